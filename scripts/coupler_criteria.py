"""Quality criteria c1-c5 of the single and double coupler over the full design grid, with Fig 6-10 style plots.

    .venv/bin/python scripts/coupler_criteria.py [OUT_DIR]      (default out/coupler_criteria)
"""

from __future__ import annotations

import sys
from pathlib import Path

from mbsuite.models.coupler.analysis import criteria_report


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/coupler_criteria")
    rep = criteria_report()
    print(rep.table)
    for f in rep.save(out, None):
        print(f"wrote {f}")


if __name__ == "__main__":
    main()
