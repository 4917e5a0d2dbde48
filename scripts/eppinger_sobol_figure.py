"""The Eppinger pantograph's Sobol study (docs/design-studies.md) as one figure and its tables: reads the
`summary.json` of each operating point's `mbsuite sensitivity ... --method sobol --out DIR` run and draws, per output,
the total and first-order indices of every factor with their 95 % bootstrap half-widths, one bar group per operating
point; prints the tables in Markdown.

    .venv/bin/python scripts/eppinger_sobol_figure.py out/studies/eppinger_sobol_{en50318,stitched}_{250,300}_n32 \\
        --out docs/figures/eppinger_sobol.png
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

#: what each output is called in the figure and the tables
LABELS = {"sigma": "σ", "stat_min": "Fm − 3σ", "min": "actual min", "loss_pct": "contact loss"}
#: factor name -> short label
SHORT = {"mh": "mh head mass", "kh": "kh head spring", "bh": "bh head damping", "b2": "b2 knuckle damping",
         "ke": "ke elbow stiffness", "be": "be elbow damping", "Pg": "Pg supply pressure"}


def load(d: Path) -> dict:
    """The study's results, with its operating point (line and speed) from its command."""
    s = json.loads((d / "summary.json").read_text())
    r = s["results"]
    sc = s["scene"]
    line = "stitched" if (sc.get("line") or {}).get("kind") == "stitched" else "EN 50318"
    r["label"] = f"{line}, {sc['input']['speed']:g} km/h"
    return r


def table(studies: list[dict], output: str) -> str:
    """Markdown table of ST and S1 (± half-width) of every factor at every operating point for `output`."""
    names = [f["name"].split(".")[-1] for f in studies[0]["factors"]]
    head = "| factor | " + " | ".join(f"{s['label']}: ST / S1" for s in studies) + " |"
    rows = [head, "|---" * (len(studies) + 1) + "|"]
    for i, n in enumerate(names):
        cells = []
        for s in studies:
            ix = s["indices"][output]
            cells.append(f"{ix['ST'][i]:.2f} ± {ix['ST_conf'][i]:.2f} / {ix['S1'][i]:.2f} ± {ix['S1_conf'][i]:.2f}")
        rows.append(f"| {SHORT.get(n, n)} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def figure(studies: list[dict], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    outputs = list(studies[0]["outputs"])
    names = [f["name"].split(".")[-1] for f in studies[0]["factors"]]
    fig, axes = plt.subplots(len(outputs), 1, figsize=(10, 2.6 * len(outputs)), sharex=True)
    x = np.arange(len(names))
    w = 0.8 / len(studies)
    for ax, o in zip(np.atleast_1d(axes), outputs, strict=True):
        for j, s in enumerate(studies):
            ix = s["indices"][o]
            pos = x - 0.4 + (j + 0.5) * w
            ax.bar(pos, ix["ST"], w, yerr=ix["ST_conf"], capsize=2, label=f"ST, {s['label']}", alpha=0.75)
            ax.errorbar(pos, ix["S1"], yerr=ix["S1_conf"], fmt="k.", ms=3, lw=0.6, capsize=1.5)
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_ylabel(f"index of {LABELS.get(o, o)}", fontsize=8)
        ax.set_ylim(-0.3, 1.3)
    axes[0].legend(fontsize=7, ncol=2, loc="upper center")
    axes[-1].set_xticks(x, [SHORT.get(n, n) for n in names], rotation=20, fontsize=8)
    n = studies[0]["n"]
    fig.suptitle(f"Eppinger pantograph, Sobol indices (bars: total ST, dots: first order S1; 95 % bootstrap "
                 f"half-widths; n = {n}, {studies[0]['evaluations_count']} passages per operating point)", fontsize=9)
    fig.tight_layout(rect=(0.01, 0.0, 1.0, 0.97))
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dirs", nargs="+", type=Path)
    ap.add_argument("--out", type=Path, default=Path("docs/figures/eppinger_sobol.png"))
    a = ap.parse_args()
    studies = [load(d) for d in a.dirs]
    figure(studies, a.out)
    for o in studies[0]["outputs"]:
        print(f"\n{LABELS.get(o, o)} ({studies[0]['units'].get(o, '')})\n")
        print(table(studies, o))
    print(f"\nwrote {a.out}")


if __name__ == "__main__":
    main()
