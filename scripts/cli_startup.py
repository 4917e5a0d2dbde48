"""How long the command line takes to answer: `mbsuite --version`, `--help`, `list`, an argument error and the
subcommands' help, each against a bare `python -c pass` measured in the same run (median of 7 wall-clock runs each),
printed side by side with their ratio. A benchmark, not a test: run it on a quiet machine.

    python scripts/cli_startup.py            # every command above
    python scripts/cli_startup.py --repeats 11
    python scripts/cli_startup.py --only help  # the commands whose name contains "help"

The `mbsuite` measured is the one `python -m mbsuite.cli` imports from the current directory (run the script from
another checkout to measure that one).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

#: the top-level commands, as the light parser lists them (tests/suite/test_cli_startup.py holds the two equal)
TOP_LEVEL = ("list", "run", "view", "render", "sweep", "sensitivity", "optimise", "workprecision", "perturb",
             "hardcases", "compare", "catenary", "coupler", "drive", "drives", "pantograph", "equilibrium", "modes",
             "freqresp", "rotational")

COMMANDS = {
    "mbsuite --version": ["--version"],
    "mbsuite --help": ["--help"],
    "mbsuite list": ["list"],
    "mbsuite run (argument error)": ["run", "--no-such-option"],
    # every top-level command's help, then commands of the model groups
    **{f"mbsuite {c} --help": [c, "--help"] for c in TOP_LEVEL},
    "mbsuite coupler criteria --help": ["coupler", "criteria", "--help"],
    "mbsuite drive run --help": ["drive", "run", "--help"],
    "mbsuite drive design cadjs --help": ["drive", "design", "cadjs", "--help"],
    "mbsuite pantograph fit-lumped --help": ["pantograph", "fit-lumped", "--help"],
    "mbsuite rotational coupled-clutches --help": ["rotational", "coupled-clutches", "--help"],
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
    ap.add_argument("--only", default="", help="measure only the commands whose name contains this text")
    args = ap.parse_args()
    bare = wall([sys.executable, "-c", "pass"], args.repeats)
    print(f"{'command':44s} {'wall [s]':>9s} {'python -c pass [s]':>19s} {'ratio':>7s}")
    for name, argv in COMMANDS.items():
        if args.only not in name:
            continue
        t = wall([sys.executable, "-m", "mbsuite.cli", *argv], args.repeats)
        print(f"{name:44s} {t:9.3f} {bare:19.3f} {t / bare:7.1f}", flush=True)


if __name__ == "__main__":
    main()
