"""Current-collection quality report: target curves, criteria at their boundaries, NQ, bad criteria, CLI and scene."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from mbsuite.errors import ParameterError, SceneError
from mbsuite.models.catenary.quality import QualityCriteria, assess, criteria_from, nq, validate_section


def _stats(fm=100.0, sigma=20.0, loss=0.0, events=(), uplift_mm=50.0):
    return {"Fm": fm, "sigma": sigma, "loss_pct": loss, "loss_events": list(events), "uplift_mm": uplift_mm}


def test_target_curves_are_the_published_formulas():
    """TSI Energy / EN 50367: AC Fm = 0.00047 v^2 + 90 N (lower curve + 60 N), DC 3 kV 0.00097 v^2 + 110 N,
    DC 1.5 kV 0.00228 v^2 + 90 N; NQ limits 0.2 % (AC) and 0.1 % (DC)."""
    ac = QualityCriteria()
    assert ac.target(250.0) == pytest.approx((0.00047 * 250**2 + 60, 0.00047 * 250**2 + 90), rel=1e-15)
    assert ac.target(300.0)[1] == pytest.approx(132.3, abs=1e-12)
    assert QualityCriteria.for_system("DC3kV").target(200.0)[1] == pytest.approx(0.00097 * 4e4 + 110, rel=1e-15)
    dc15 = QualityCriteria.for_system("DC1.5kV")
    assert dc15.target(160.0)[1] == pytest.approx(0.00228 * 160**2 + 90, rel=1e-15) and dc15.nq_max_pct == 0.1
    assert QualityCriteria.for_system("DC3kV", fm_b=120.0).fm_b == 120.0


def test_nq_counts_losses_from_the_stated_minimum_duration():
    ev = [{"duration": 0.002}, {"duration": 0.010}, {"duration": 0.005}]
    assert nq(ev, 2.0, 0.0) == pytest.approx(100 * 0.017 / 2.0)
    assert nq(ev, 2.0, 0.005) == pytest.approx(100 * 0.015 / 2.0)  # the 5 ms loss counts, the 2 ms one not
    with pytest.raises(ParameterError, match="window"):
        nq(ev, 0.0, 0.0)


def test_criteria_verdicts_at_their_boundaries():
    c = QualityCriteria()
    lo, hi = c.target(250.0)
    q = assess(_stats(fm=hi, sigma=0.3 * hi, uplift_mm=120.0), 250.0, c, 1.0)
    r = q["rows"]
    assert r["mean_force"]["pass"] and r["sigma"]["pass"] and r["uplift"]["pass"]  # limits are inclusive
    assert r["stat_min"]["value"] == pytest.approx(hi - 0.9 * hi) and r["stat_min"]["pass"]
    q = assess(_stats(fm=hi + 1e-9), 250.0, c, 1.0)
    assert not q["rows"]["mean_force"]["pass"] and not q["pass"]
    q = assess(_stats(fm=lo - 1e-9), 250.0, c, 1.0)
    assert not q["rows"]["mean_force"]["pass"]
    q = assess(_stats(fm=90.0, sigma=30.0), 0.0, c, 1.0)  # Fm - 3 sigma = 0 is not > 0; sigma > 0.3 Fm
    assert not q["rows"]["stat_min"]["pass"] and not q["rows"]["sigma"]["pass"]
    q = assess(_stats(fm=100.0, loss=0.3, events=[{"duration": 0.003}]), 250.0, c, 1.0)
    assert not q["rows"]["contact_loss"]["pass"] and not q["rows"]["arcing_nq"]["pass"]
    assert q["rows"]["arcing_nq"]["value"] == pytest.approx(0.3)
    q = assess(_stats(fm=100.0, events=[{"duration": 0.003}]), 250.0, c.__class__(arc_min_duration=0.005), 1.0)
    assert q["rows"]["arcing_nq"]["value"] == 0.0 and q["rows"]["arcing_nq"]["pass"]
    assert not assess(_stats(uplift_mm=120.001), 250.0, c, 1.0)["rows"]["uplift"]["pass"]


def test_bad_criteria_name_the_value():
    with pytest.raises(ParameterError, match="fm_b"):
        QualityCriteria(fm_b=-10.0)
    with pytest.raises(ParameterError, match="fm_a"):
        QualityCriteria(fm_a=-0.001)
    with pytest.raises(ParameterError, match="fm_b_lower"):
        QualityCriteria(fm_b_lower=95.0)
    with pytest.raises(ParameterError, match="system"):
        QualityCriteria.for_system("DC25kV")
    with pytest.raises(SceneError, match="valid keys"):
        validate_section({"sigma_max": 0.2})
    with pytest.raises(SceneError, match=r"sigma_ratio_max = 0.0 in \[quality\].*valid: \(0, 10\]"):
        validate_section({"sigma_ratio_max": 0.0})
    assert criteria_from({"system": "DC3kV", "nq_max_pct": 0.05}).nq_max_pct == 0.05


def test_cli_quality_report_and_scene_section(tmp_path):
    """`mbsuite catenary SCENE --quality --json`: per criterion value, limit and verdict; the scene's [quality]
    section sets the limits (here a sigma limit no passage meets)."""
    scene = tmp_path / "short.toml"
    scene.write_text('model = "catenary"\n[params]\nelement_length = 0.5\nx_end = 150.0\nwindow_start = 60.0\n'
                     'window_end = 120.0\n[input]\ntype = "passage"\nspeed = 250.0\n[solver]\nengine = "reference"\n'
                     'timestep = 2e-4\n[quality]\nsystem = "AC"\nsigma_ratio_max = 0.01\n')
    out = subprocess.run([sys.executable, "-m", "mbsuite.cli", "catenary", str(scene), "--quality", "--json",
                          "--out", str(tmp_path / "o")], capture_output=True, text=True, check=True)
    data = json.loads(out.stdout[out.stdout.index("{"):])
    q = data["runs"]["slack"]["quality"]
    assert set(q["rows"]) == {"mean_force", "sigma", "stat_min", "contact_loss", "arcing_nq", "uplift"}
    assert not q["rows"]["sigma"]["pass"] and q["rows"]["stat_min"]["pass"] and data["quality_pass"] is False
    assert (tmp_path / "o" / "quality_reference2mass_250kmh.png").is_file()
