"""Regenerate the shipped coupler model files (baseline CouplerParams) from mbsuite.models.coupler.modelfiles.

    .venv/bin/python scripts/coupler_write_models.py
"""

from mbsuite.models.coupler.modelfiles import write_baseline

if __name__ == "__main__":
    for path in write_baseline():
        print(f"wrote {path}")
