"""`mbsuite coupler ...` commands: JSON output, files, clear errors (exit code 2)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from mbsuite.cli import main
from mbsuite.models.coupler.params import CouplerParams


def test_jacobian_json(capsys):
    assert main(["coupler", "jacobian", "--gamma", "0.2967059728390360", "--ey", "0.1", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["rank"] == 4
    assert d["cond"] == pytest.approx(math.cos(2 * 0.2967059728390360) / 0.1, rel=1e-13)  # measured 0
    assert len(d["principal_screws"]) == 2 and len(d["zero_pitch_screws"]) == 2


def test_jacobian_coplanar_warns_and_reports_infinite_cond(capsys):
    assert main(["coupler", "jacobian", "--ey", "0", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["rank"] == 3 and d["cond"] is None and "coplanar" in d["warnings"][0]


def test_fpp_pinocchio_cross_check(capsys):
    assert main(["coupler", "fpp", "--engine", "pinocchio", "--n", "25", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["max_abs_diff_pinocchio"] < 1e-13 and len(d["phi_b"]) == 25  # measured 1.1e-14


def test_criteria_quick_writes_plots(tmp_path, capsys):
    assert main(["coupler", "criteria", "--quick", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert _width(out) <= 100
    names = {p.name for p in tmp_path.iterdir()}
    assert {"fig9_criteria_single.png", "fig10_c5_double.png", "fig6_phi_difference.png", "fig7_centre_path.png",
            "fig8_link_angles.png", "criteria_single.csv", "criteria_double.csv", "summary.json"} <= names
    header = (tmp_path / "criteria_single.csv").read_text().splitlines()[0]
    assert "e_y [m]" in header and "c2 [m]" in header and "c1 [rad]" in header


def _width(out: str) -> int:
    """Widest line of a command's table (the `wrote <path>` lines name the caller's directory)."""
    return max(len(line) for line in out.splitlines() if not line.startswith("wrote "))


def _csv(path) -> tuple[list[str], np.ndarray]:
    lines = path.read_text().splitlines()
    return lines[0].split(","), np.array([[float(x) for x in r.split(",")] for r in lines[1:]])


@pytest.mark.parametrize("ey", [0.0, 0.05, 0.1])
def test_jacobian_table_fits_and_csv_holds_the_closed_form(ey, tmp_path, capsys):
    """The table fits 100 columns and prints numbers, not numpy arrays; jacobian.csv holds J with units, and at the
    aligned pose every link's axial direction cosine is e_y / l with l = sqrt(l0^2 + e_y^2), l0 = 2R sin(pi/4 -
    gamma) (Eq 1): measured to 1e-16, asserted to 1e-13."""
    g = 0.2967059728390360
    assert main(["coupler", "jacobian", "--gamma", repr(g), "--ey", repr(ey), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert _width(out) <= 100
    assert "[[" not in out and "array(" not in out and "np.float64" not in out
    head, J = _csv(tmp_path / "jacobian.csv")
    assert head == ["link", "J_v_x [-]", "J_v_y [-]", "J_v_z [-]", "J_w_x [m]", "J_w_y [m]", "J_w_z [m]"]
    l0 = 2 * math.sin(math.pi / 4 - g)
    np.testing.assert_allclose(J[:, 2], ey / math.hypot(l0, ey), rtol=0, atol=1e-13)
    _, sv = _csv(tmp_path / "jacobian_singular_values.csv")
    assert sv[0, 1] == pytest.approx(2 * math.cos(math.pi / 4 - g) * l0 / math.hypot(l0, ey), rel=1e-12)
    heads = (tmp_path / "jacobian_screws.csv").read_text().splitlines()[0]
    assert "point_y [m]" in heads and "pitch [m]" in heads
    assert (tmp_path / "summary.json").exists()


def test_fpp_writes_csv_png_summary(tmp_path, capsys):
    assert main(["coupler", "fpp", "--n", "25", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert _width(out) <= 100 and "x_b [m]" in out
    assert {"fpp_single.csv", "fpp_single.png", "summary.json"} <= {p.name for p in tmp_path.iterdir()}


def test_figures_draw_on_given_axes():
    """Plot functions return a Figure, or draw on the Axes they are given (no pyplot)."""
    from matplotlib.figure import Figure

    from mbsuite.models.coupler import criteria, plots

    p = CouplerParams()
    revs = criteria.revolutions(p, alphas=(0.035,), n=25)
    fig = Figure()
    ax = fig.subplots()
    assert plots.fig6(p, revs, ax=ax) is ax and len(ax.lines) == 2  # the curve and the zero line
    assert isinstance(plots.fig7(p, revs), Figure)
    assert isinstance(plots.fig8(p, revs), Figure)
    rows = [{"gamma": 0.3, "e_y": 0.1, "R": 1.0, "l_b": 2.0, "phi_bc": pbc, "z_c": z, "c5": c}
            for pbc, z, c in ((0.0, 0.0, 0.0), (0.0, 0.05, 3e-15), (math.pi / 2, 0.0, 0.0), (math.pi / 2, 0.05, 3e-4))]
    f10 = plots.fig10(rows)
    labels = [t.get_text() for t in f10.axes[0].get_legend().get_texts()]
    assert any("max $c_5$ = 3e-15 rad" in t for t in labels)  # phi_bc = 0 stated by its largest value
    assert f10.axes[0].get_yscale() == "linear"


@pytest.mark.parametrize("argv, msg", [
    (["coupler", "jacobian", "--gamma", "0.9"], "gamma"),
    (["coupler", "jacobian", "--ey", "-0.1"], "--ey = -0.1 is invalid"),
    (["coupler", "fpp", "--ey", "0.02", "--alpha-bx", "0.06"], "cross"),
    (["coupler", "jacobian", "--R", "0"], "R"),
])
def test_bad_input_exit_code_2(argv, msg, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("mbsuite: error:") and msg in err


def test_dynamics_command_json_and_csv(tmp_path, capsys):
    scene = tmp_path / "short.toml"
    scene.write_text('model = "coupler"\n[input]\ntype = "constant_speed"\nz_c = 0.05\nt_ramp = 0.25\n'
                     '[solver]\nduration = 0.45\nt_settle = 0.3\n')
    assert main(["coupler", "dynamics", str(scene), "--json", "--out", str(tmp_path / "o")]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["stats"]["warnings"] == {} and d["statistics"]["closure_residual_max"] < 2e-4
    header = (tmp_path / "o" / "run.csv").read_text().splitlines()[0]
    assert "torque_in [N m]" in header and "link_force_8 [N]" in header
    assert (tmp_path / "o" / "run.png").stat().st_size > 10_000


def test_dynamics_table_has_units_and_fits(tmp_path, capsys):
    scene = tmp_path / "short.toml"
    scene.write_text('model = "coupler"\n[input]\ntype = "constant_speed"\nz_c = 0.05\n'
                     '[solver]\nduration = 0.3\nt_settle = 0.25\n')
    assert main(["coupler", "dynamics", str(scene), "--engine", "reference"]) == 0
    out = capsys.readouterr().out
    assert _width(out) <= 100
    for line in out.splitlines():
        if line.strip().startswith(("torque_in_mean", "closure_residual_max_all")):
            assert line.split()[1] in ("N", "m")
