"""Sensitivity studies (`mbsuite.analysis.sensitivity`, `mbsuite sensitivity`): Sobol indices of the Ishigami function
against their closed form and Morris effects of a linear function against theirs, both through the sweep machinery
that runs a scene's points; a small catenary study end to end, its evaluations equal to the public run at the same
point; the study's inputs refused with a message naming them."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import mbsuite
from mbsuite.analysis import sensitivity
from mbsuite.analysis.designspace import Factor, point_scene, sections_for
from mbsuite.cli import main
from mbsuite.errors import MbsuiteError

# the EN 50318 line shortened to 4 spans, 1 m elements: a passage in a fraction of a second
SHORT = {"n_spans": 4, "x_end": 200.0, "window_start": 60.0, "window_end": 180.0, "element_length": 1.0}
SHORT_SETS = [a for k, v in SHORT.items() for a in ("--set", f"params.{k}={v:g}")]


def test_ishigami_closed_form_is_the_published_one():
    """The closed-form indices (variance decomposition) equal the values tabulated for a = 7, b = 0.1 (Saltelli et
    al., Global Sensitivity Analysis: The Primer, 2008): S1 = 0.3139, 0.4424, 0; ST = 0.5576, 0.4424, 0.2437."""
    ref = sensitivity.ishigami_indices(7.0, 0.1)
    assert ref["S1"] == pytest.approx([0.3139, 0.4424, 0.0], abs=5e-5)
    assert ref["ST"] == pytest.approx([0.5576, 0.4424, 0.2437], abs=5e-5)


def test_sobol_indices_of_ishigami_through_the_sweep_machinery():
    """SALib's Sobol indices of the Ishigami function, every point run by `run_sweep` (serially: 5120 points of
    microseconds each), match the closed form. Tolerance 0.05: with n = 1024 the largest error over seeds 0-4 is
    0.022 (seed 2), 0.0041 at the seed used here (measured with this code): the bound is 2.3x the worst seed and 12x
    this one."""
    opts = mbsuite.analysis.sweep.SweepOptions(max_points=6000)
    res = sensitivity.run(sensitivity.ishigami, sensitivity.ISHIGAMI_FACTORS, method="sobol", n=1024, seed=1,
                          workers=1, options=opts, progress=False)
    ref = sensitivity.ishigami_indices()
    ind = res.indices["f"]
    assert len(res.evaluations) == 1024 * (3 + 2)
    for name in ("S1", "ST"):
        assert np.abs(np.subtract(ind[name], ref[name])).max() < 0.05, (name, ind[name], ref[name])
    # the ranking by total index: x1 (0.558), x2 (0.442), x3 (0.244)
    assert [r["factor"] for r in res.ranking("f")] == ["x.x1", "x.x2", "x.x3"]


def linear(point):
    """y = 2 a - 3 b + 0 c: elementary effects constant, in closed form."""
    return {"y": 2.0 * point["x.a"] - 3.0 * point["x.b"] + 0.0 * point["x.c"]}


def test_morris_of_a_linear_function_equals_its_elementary_effects():
    """For y = sum a_i x_i every elementary effect over a step of the normalised range is a_i (hi - lo): mu* =
    |a_i| (hi - lo), mu = a_i (hi - lo), sigma = 0 (SALib's effects are the output's change over the whole range)."""
    facs = [Factor("x", "a", 0.0, 5.0), Factor("x", "b", -1.0, 1.0), Factor("x", "c", 2.0, 3.0)]
    res = sensitivity.run(linear, facs, method="morris", n=6, seed=3, workers=1, progress=False)
    ind = res.indices["y"]
    assert ind["mu_star"] == pytest.approx([10.0, 6.0, 0.0], abs=1e-9)
    assert ind["mu"] == pytest.approx([10.0, -6.0, 0.0], abs=1e-9)
    assert ind["sigma"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-9)
    assert len(res.evaluations) == 6 * (3 + 1)


def test_a_study_resumes_from_its_store(tmp_path):
    """With a store, a second run of the same study computes nothing (every point is read back) and gives the same
    indices."""
    facs = [Factor("x", "a", 0.0, 5.0), Factor("x", "b", -1.0, 1.0), Factor("x", "c", 2.0, 3.0)]
    opts = mbsuite.analysis.sweep.SweepOptions(store=tmp_path / "study.jsonl")
    res = sensitivity.run(linear, facs, method="morris", n=4, seed=3, workers=1, options=opts, progress=False)
    size = (tmp_path / "study.jsonl").stat().st_size
    again = sensitivity.run(linear, facs, method="morris", n=4, seed=3, workers=1, options=opts, progress=False)
    assert (tmp_path / "study.jsonl").stat().st_size == size  # nothing appended
    assert again.indices == res.indices


def test_nested_keys_reach_a_models_own_section():
    """`pantograph.params.Pg` sets the Eppinger pantograph's parameter in the catenary scene's [pantograph] section,
    keeping the section's other values."""
    scene = mbsuite.load_scene("catenary/en50318_eppinger")
    d = scene.to_dict()
    secs = sections_for(d, {"pantograph.params.Pg": 7.0e5, "params.m1": 8.0})
    assert secs["pantograph"]["params"] == {**d["pantograph"]["params"], "Pg": 7.0e5}
    sc = point_scene(scene, {"pantograph.params.Pg": 7.0e5})
    assert sc.to_dict()["pantograph"]["params"]["Pg"] == 7.0e5
    assert sc.to_dict()["pantograph"]["effects"] == d["pantograph"]["effects"]


def test_catenary_morris_end_to_end_on_a_short_line(tmp_path):
    """`mbsuite sensitivity` on the 2-mass pantograph under a short line: the ranked table, the CSV, the figure and
    summary.json with the inputs, the seed and every evaluation; an evaluation equals `mbsuite.run` of the scene at
    the same point (the headline outputs of the public run)."""
    out = tmp_path / "sens"
    rc = main(["sensitivity", "catenary/en50318", *SHORT_SETS, "--vary", "params.F0=100:140", "--vary",
               "params.c2=50:120", "--method", "morris", "--n", "2", "--seed", "4", "--workers", "2",
               "--outputs", "Fm,sigma", "--out", str(out)])
    assert rc == 0
    summary = json.loads((out / "summary.json").read_text())
    data = summary["results"]
    assert data["seed"] == 4 and data["method"] == "morris" and data["n"] == 2
    assert [f["name"] for f in data["factors"]] == ["params.F0", "params.c2"]
    ev = data["evaluations"]
    assert len(ev) == 2 * (2 + 1)
    assert data["ranking"]["Fm"][0]["factor"] == "params.F0"  # the static uplift force moves the mean force most
    scene = mbsuite.load_scene("catenary/en50318").replace(params=SHORT)
    direct = mbsuite.run(point_scene(scene, ev[0]["point"])).statistics
    assert ev[0]["outputs"]["Fm"] == direct["Fm"] and ev[0]["outputs"]["sigma"] == direct["sigma"]
    for name in ("sensitivity.csv", "evaluations.csv", "sensitivity.png"):
        assert (out / name).stat().st_size > 0
    head = (out / "evaluations.csv").read_text().splitlines()[0]
    assert head.startswith("params.F0 [N],params.c2 [N s/m],") and "Fm [N]" in head


@pytest.mark.parametrize(("vary", "words"), [
    ("params.m1=5", "LO:HI"),
    ("params.m1=10:5", "lower bound 10 must lie below"),
    ("params.m1=a:5", "'a' is not a number"),
    ("nosuch.m1=1:2", "SECTION in"),
    ("params.m1=-1:5", "m1"),
])
def test_bad_ranges_are_refused_naming_them(vary, words, capsys):
    rc = main(["sensitivity", "catenary/en50318", "--vary", vary])
    err = capsys.readouterr().err
    assert rc == 2 and words in err and err.count("\n") == 1, err


def test_bad_settings_are_refused():
    with pytest.raises(MbsuiteError, match="power of two"):
        sensitivity.run(linear, [Factor("x", "a", 0, 1)], method="sobol", n=6)
    with pytest.raises(MbsuiteError, match="unknown; valid: morris, sobol"):
        sensitivity.run(linear, [Factor("x", "a", 0, 1)], method="fast")
    with pytest.raises(MbsuiteError, match="not among the evaluated outputs"):
        sensitivity.run(linear, [Factor("x", "a", 0, 1), Factor("x", "b", 0, 1), Factor("x", "c", 0, 1)],
                        outputs=["z"], n=2, workers=1, progress=False)
    with pytest.raises(MbsuiteError, match="not among the evaluated outputs"):
        sensitivity.run(mbsuite.load_scene("catenary/en50318"), ["params.m1=5:8"], outputs=["sigmaa"])
    with pytest.raises(MbsuiteError, match=r"lo = nan in the range of params.m1 is invalid"):
        Factor("params", "m1", math.nan, 1.0)
