"""Build the documentation site (mkdocs-material + mkdocstrings, strict: any warning is an error).

The pages are the repository's own documents, gathered into `docs/` at build time so that each exists once: the top
README becomes the home page, each model's README its model page; `docs/gallery.md` shows every figure the suite writes
beside the command that makes it (the figures are made here, by those very commands, unless `--no-figures`).

    python scripts/build_docs.py               # -> out/site/
    python scripts/build_docs.py --no-figures  # reuse the figures of an earlier build
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
MODELS = ("pantograph", "coupler", "drives", "catenary", "iftomm")

# (title, command, figure files written into --out, what the figure shows)
GALLERY: list[tuple[str, str, list[str], str]] = [
    ("Pantograph frequency response", "mbsuite freqresp pantograph --methods linear,mujoco",
     ["freqresp.png"], "Response amplitude and phase of F1, F2, HD and y_d per unit ram amplitude, from the "
     "linearisation about the mean ram height and from MuJoCo time simulations, with the thesis' resonances."),
    ("Pantograph time history", "mbsuite run pantograph", ["run.png"],
     "The lab scene's signals over time, one panel per group of signals of one unit and comparable scale."),
    ("EN 50318 passage", "mbsuite catenary catenary/en50318 --speed 250 --quality",
     ["force_uplift_reference2mass_250kmh.png", "quality_reference2mass_250kmh.png"],
     "Contact force, contact-wire height and uplift along the section; the current-collection quality criteria."),
    ("Coupler criteria", "mbsuite coupler criteria --quick",
     ["fig6_phi_difference.png", "fig9_criteria_single.png", "fig10_c5_double.png"],
     "Kinematic errors and criteria c1-c5 of the single and double couplers over a revolution."),
    ("Drives efficiency", "mbsuite drive efficiency drives/step_up_efficiency --loads 0.2,0.4,0.6 --duration 3",
     ["efficiency.png"], "Efficiency and loss breakdown of the step-up drive against load speed."),
    ("Work-precision", "mbsuite workprecision rotational/coupled_clutches --quick --repeats 1", ["workprecision.png"],
     "Error against wall time for every engine and setting; each point labelled with its step or tolerance."),
    ("Two pantographs on one train", "mbsuite catenary catenary/en50318_two_pantographs --speed 300 --quality",
     ["train_force_300kmh.png", "quality_train_300kmh.png"],
     "Both pantographs' contact forces along the section 200 m apart at 300 km/h; their quality criteria."),
    ("A parameter study of an analysis", "mbsuite modes pantograph --vary params.mh=10:16:2", ["study.png"],
     "The pantograph's natural frequencies against its head mass (`--vary` on modes, freqresp, equilibrium, "
     "catenary and the coupler and drive commands)."),
    ("A sweep of time runs", "mbsuite sweep pantograph --vary input.frequency=2,4,6", ["sweep.png"],
     "Each output signal's range over the swept values."),
    ("Coupler dynamics", "mbsuite coupler dynamics coupler/double_lateral", ["run.png"],
     "Input torque, coupler-angle error, closure residual and link forces of the double coupler on MuJoCo."),
    ("Coupler revolution", "mbsuite coupler fpp", ["fpp_single.png"],
     "The single coupler's pose over a revolution of its input (the forward position problem by continuation)."),
    ("Drive run", "mbsuite drive run drives/step_up_pwm", ["run.png"],
     "Speeds, spring twist, energies and clutch/brake commands of the PWM-switched step-up drive."),
    ("Coupled clutches against the Modelica reference", "mbsuite rotational coupled-clutches", ["coupled_clutches.png"],
     "The Modelica Standard Library's CoupledClutches example on both paths against its reference result."),
    ("Drive design tables", "mbsuite drive design tables", ["design_tables.png"],
     "The thesis' Chapter 5 design tables recomputed."),
    ("A stitched line", "mbsuite catenary catenary/en50318_stitched --speed 300 --quality",
     ["force_uplift_reference2mass_300kmh.png", "quality_reference2mass_300kmh.png"],
     "The 2-mass pantograph under the stitched EN 50318 line at 300 km/h: force, wire height and uplift; quality."),
    ("A line of your own", "mbsuite catenary catenary/example_line", ["force_uplift_reference2mass_250kmh.png"],
     "A tension section from a line file: varying spans, stitch wires, masses, presag and a height profile."),
    ("Sensitivity of the Eppinger pantograph under the wire",
     "mbsuite sensitivity catenary/en50318_eppinger --set solver.engine=mujoco --vary pantograph.params.mh=10:17 "
     "--vary pantograph.params.kh=1500:3000 --vary pantograph.params.bh=5:20 --vary pantograph.params.b2=100:220 "
     "--vary pantograph.params.Pg=6.8e5:7.6e5 --method morris --n 4 --seed 1", ["sensitivity.png"],
     "Morris elementary effects (mu*, with 95 % intervals) of five pantograph parameters on the EN 50318 statistics."),
    ("The best Eppinger pantograph for the line",
     "mbsuite optimise catenary/en50318_eppinger --set solver.engine=mujoco --vary pantograph.params.kh=1500:3000 "
     "--vary pantograph.params.b2=100:220 --vary pantograph.params.bh=5:20 --start pantograph.params.kh=2250 "
     "--start pantograph.params.b2=157.5 --start pantograph.params.bh=10.8 --objective sigma --band AC --speed 250 "
     "--maxiter 1 --popsize 2 --seed 1", ["optimise.png"],
     "Differential evolution for the lowest sigma with Fm inside the EN 50367 band: every design evaluated."),
    ("Sigma against the mean force",
     "mbsuite optimise catenary/en50318 --vary params.c2=50:130 --vary params.F0=100:140 --objective sigma "
     "--against Fm --pareto 95,105,115 --band AC --speed 250 --maxiter 3 --popsize 4 --seed 2", ["pareto.png"],
     "The epsilon-constraint front of sigma against Fm at 250 km/h."),
    ("Lumped pantographs fitted to the multibody one", "mbsuite pantograph fit-lumped --stages 3", ["lumped_fit.png"],
     "The Eppinger pantograph's driving-point receptance against its 3-stage lumped and transfer-function fits."),
    ("Two runs compared", "mbsuite compare out/docs-figures/gallery_2 out/docs-figures/gallery_15",
     ["compare_signals.png"], "The 2-mass pantograph at 250 km/h under the EN 50318 line (A: the passage above) and "
     "under the line of your own (B): the statistics side by side with their differences (table, compare.csv), the "
     "signals overlaid along the line; it reads the summary.json files the two gallery commands above wrote."),
]


def _gather() -> None:
    """Copy the repository's documents into docs/ (generated pages; git-ignored), rewriting their links."""
    text = (ROOT / "README.md").read_text()
    for m in MODELS:
        text = text.replace(f"](mbsuite/models/{m}/README.md)", f"](models/{m}.md)")
    text = re.sub(r"\]\(docs/([A-Za-z_]+\.md)\)", r"](\1)", text)  # docs/accuracy.md, docs/stability.md, ...
    (DOCS / "index.md").write_text(text)
    (DOCS / "models").mkdir(exist_ok=True)
    for m in MODELS:
        page = (ROOT / "mbsuite" / "models" / m / "README.md").read_text()
        page = re.sub(r"\]\(\.\./\.\./\.\./docs/([A-Za-z_]+\.md)\)", r"](../\1)", page)
        page = re.sub(r"\]\((\.\./)+([^)]+)\)", r"] (`\2`)", page)  # other repository paths: shown as paths
        (DOCS / "models" / f"{m}.md").write_text(page)


def _figures(out: Path) -> None:
    """Run every gallery command with --out and copy its figures into docs/gallery/."""
    dest = DOCS / "gallery"
    dest.mkdir(exist_ok=True)
    env = {**os.environ, "MPLBACKEND": "Agg"}
    for i, (_title, cmd, files, _what) in enumerate(GALLERY):
        d = out / f"gallery_{i}"
        argv = [sys.executable, "-m", "mbsuite.cli", *shlex.split(cmd)[1:], "--out", str(d)]
        subprocess.run(argv, check=True, env=env, stdout=subprocess.DEVNULL)
        for f in files:
            hits = sorted(d.rglob(f))
            if not hits:
                raise SystemExit(f"gallery: {cmd!r} wrote no {f} into {d}")
            shutil.copy2(hits[0], dest / _name(i, f))


def _name(i: int, f: str) -> str:
    """A gallery figure's file: its command's index and the name the command gave it (several write `run.png`)."""
    return f"{i:02d}_{f}"


def _gallery_page() -> None:
    lines = ["# Gallery", "", "Every figure below is written by the command above it (`--out DIR`); the same "
             "directory also holds the CSV files (SI units in the header) and `summary.json`.", ""]
    for i, (title, cmd, files, what) in enumerate(GALLERY):
        lines += [f"## {title}", "", f"```\n{cmd} --out DIR\n```", "", what, ""]
        lines += [f"![{title}](gallery/{_name(i, f)})" for f in files] + [""]
    (DOCS / "gallery.md").write_text("\n".join(lines))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-figures", action="store_true", help="do not remake the gallery's figures")
    args = ap.parse_args(argv)
    _gather()
    _gallery_page()
    if not args.no_figures:
        _figures(ROOT / "out" / "docs-figures")
    missing = [_name(i, f) for i, (_, _, files, _) in enumerate(GALLERY) for f in files
               if not (DOCS / "gallery" / _name(i, f)).is_file()]
    if missing:
        print(f"gallery figures missing: {missing}; run without --no-figures", file=sys.stderr)
        return 2
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(ROOT / "mkdocs.yml")],
                          cwd=ROOT, env=env).returncode


if __name__ == "__main__":
    sys.exit(main())
