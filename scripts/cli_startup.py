"""How long the command line takes to answer: `mbsuite --version`, `--help`, `list`, an argument error and the
subcommands' help, each against a bare `python -c pass` measured in the same run (median of 7 wall-clock runs each),
printed side by side with their ratio. A benchmark, not a test: run it on a quiet machine.

    python scripts/cli_startup.py            # every command above
    python scripts/cli_startup.py --repeats 11
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

COMMANDS = {
    "mbsuite --version": ["--version"],
    "mbsuite --help": ["--help"],
    "mbsuite list": ["list"],
    "mbsuite run (argument error)": ["run", "--no-such-option"],
    "mbsuite catenary --help": ["catenary", "--help"],
    "mbsuite pantograph --help": ["pantograph", "--help"],
    "mbsuite modes --help": ["modes", "--help"],
    "mbsuite coupler criteria --help": ["coupler", "criteria", "--help"],
    "mbsuite drive run --help": ["drive", "run", "--help"],
    "mbsuite rotational --help": ["rotational", "--help"],
    "mbsuite optimise --help": ["optimise", "--help"],
}


def wall(argv: list[str], repeats: int) -> float:
    """Median wall time of `argv` over `repeats` runs (output discarded)."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7, help="runs per command; the median is reported (default 7)")
    args = ap.parse_args()
    bare = wall([sys.executable, "-c", "pass"], args.repeats)
    print(f"{'command':32s} {'wall [s]':>9s} {'python -c pass [s]':>19s} {'ratio':>7s}")
    for name, argv in COMMANDS.items():
        t = wall([sys.executable, "-m", "mbsuite.cli", *argv], args.repeats)
        print(f"{name:32s} {t:9.3f} {bare:19.3f} {t / bare:7.1f}")


if __name__ == "__main__":
    main()
