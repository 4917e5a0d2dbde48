"""Admissibility rule, c5 extremum, resolved input defaults, declared limits, model files checked at load, health
figures and the size guard of the coupler."""

from __future__ import annotations

import json
import math
import re
import shutil

import numpy as np
import pytest
from scipy.optimize import brentq, root

import mbsuite
from mbsuite.cli import main
from mbsuite.errors import GeometryError, ModelFileError
from mbsuite.limits import undeclared
from mbsuite.models.coupler import analysis, criteria
from mbsuite.models.coupler.double import solve_double_wrapped_batch
from mbsuite.models.coupler.params import CouplerParams
from mbsuite.models.coupler.reference import revolution_guess
from mbsuite.models.coupler.single import solve_single


# ------------------------------------------------------------------------------------------- admissibility boundary
def _independent_pose(p: CouplerParams, alpha: float, u0: np.ndarray) -> tuple[np.ndarray, float]:
    """Eq (4) written out again and solved by scipy (Levenberg-Marquardt): the pose at phi_a = 0, alpha_bx = alpha
    and the smallest link axial component along both shaft axes (over the link length)."""
    g, R = p.gamma, p.R
    P = R * np.array([[-math.sin(g), 0, math.cos(g)], [math.sin(g), 0, math.cos(g)],
                      [math.sin(g), 0, -math.cos(g)], [-math.sin(g), 0, -math.cos(g)]])
    c, s = math.cos(alpha), math.sin(alpha)
    Rx = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])

    def links(u):
        cp, sp = math.cos(u[0]), math.sin(u[0])
        Rb = Rx @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
        return (P @ Rb.T + [u[1], p.e_y + u[2], u[3]])[[1, 2, 3, 0]] - P, Rb

    def fun(u):
        return (links(u)[0] ** 2).sum(1) - p.link_length**2

    sol = root(fun, u0, method="hybr", options={"xtol": 1e-14})
    if np.max(np.abs(fun(sol.x))) >= 1e-12:
        sol = root(fun, sol.x, method="lm", options={"xtol": 1e-15, "ftol": 1e-15})
    lv, Rb = links(sol.x)
    assert np.max(np.abs((lv**2).sum(1) - p.link_length**2)) < 1e-12  # converged, also past the boundary
    return sol.x, min(lv[:, 1].min(), (lv @ Rb[:, 1]).min()) / p.link_length


@pytest.mark.parametrize("e_y", [0.05, 0.1])
def test_admissibility_boundary(e_y):
    p = CouplerParams(e_y=e_y)
    u = np.array([-math.pi / 2, 0.0, 0.0, 0.0])
    for a in np.linspace(0.0, 0.8 * e_y, 9):  # continuation of the independent solution towards the boundary
        u, _ = _independent_pose(p, a, u)
    state = {"u": u}

    def axial(a: float) -> float:
        return _independent_pose(p, a, state["u"])[1]

    a_star = brentq(axial, 0.8 * e_y, e_y, xtol=1e-15)
    assert _independent_pose(p, 1.05 * a_star, state["u"])[1] < 0  # a (refused) solution beyond
    assert 0.85 * e_y < a_star < e_y  # roughly e_y > R alpha (0.914 and 0.902 x e_y measured)
    inside = solve_single(p, 0.0, a_star * (1 - 1e-4))
    np.testing.assert_allclose(inside.u, _independent_pose(p, a_star * (1 - 1e-4), u)[0], atol=1e-9)
    with pytest.raises(GeometryError) as exc:
        solve_single(p, 0.0, a_star * (1 + 1e-4))
    msg = str(exc.value)
    assert f"alpha_bx = {a_star * (1 + 1e-4):.6g} rad" in msg and f"e_y = {e_y:g} m" in msg
    assert "interpenetrate" in msg and "axial component" in msg


# -------------------------------------------------------------------------------------------------------- c5
@pytest.mark.parametrize("l_b", [2.0, 4.0])
def test_c5_extremum_converged_against_brute_force(l_b):
    p = CouplerParams(l_b=l_b, phi_bc=math.pi / 2)
    c = criteria.double_c5(p, 0.1, n=61)
    # brute force: 4096 samples over [0, 2 pi) (no closing sample) by the batched FPP, a different solver path
    N = 4096
    phi = np.arange(N) * 2 * math.pi / N
    inp = {"alpha_cx": 0.0, "alpha_cz": 0.0, "x_c": 0.0, "z_c": 0.1}
    U = solve_double_wrapped_batch(p, phi, np.array([0, 0, 0, 0.1]), revolution_guess(p, inp, phi))
    d = phi - U[:, 0]
    mean = d.mean()  # rectangle rule on the open periodic grid
    dev = np.abs(d - mean)
    i = int(np.argmax(dev))
    y0, y1, y2 = dev[i - 1], dev[i], dev[(i + 1) % N]
    sampling = abs(y0 - 2 * y1 + y2) / 8  # |g''| (dphi / 2)^2 / 2: how far a sampled maximum can miss the peak
    # refined >= every sample, within the grid's sampling error of the brute maximum (measured 9.4e-7, 6.4e-8 rel)
    assert c["c5"] >= y1 - 1e-15 and c["c5"] - y1 <= sampling
    assert abs(c["c5"] - y1) <= 1e-6 * y1
    # and the brute maximum refined by the parabola through its 3 best samples (measured 9e-12, 2e-12 relative)
    x = 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)
    assert c["c5"] == pytest.approx(y1 - 0.25 * (y0 - y2) * x, rel=1e-9)
    assert c["mean"] == pytest.approx(mean, abs=1e-13)  # trapezoid-free periodic mean
    assert (c["c5"] - c["c5_sampled"]) / c["c5"] > 5e-3  # 61 samples alone under-read by 0.53-0.55 %
    assert criteria.double_c5(p, 0.1, n=31)["c5"] == pytest.approx(c["c5"], rel=1e-9)  # independent of the grid


def test_periodic_mean_counts_the_closing_sample_once():
    x = np.linspace(0, 2 * math.pi, 7)
    assert criteria.periodic_mean(1.0 + np.cos(x)) == pytest.approx(1.0, abs=1e-15)  # closed-grid mean: 1.142857


def test_regression_criteria_table_double_c5(capsys):
    """The double-coupler table names its geometry; its c5 is the README's converged value (regression: validated
    against a 4096-sample brute force in test_c5_extremum_converged_against_brute_force)."""
    rep = analysis.criteria_report(gammas=(0.297,), eys=(0.1,), alphas=(0.07,), zcs=(0.1,), lbs=(2.0,),
                                   phibcs=(math.pi / 2,), n=121)
    assert "gamma = 0.29671 rad (17 deg), e_y = 0.1 m, R = 1 m" in rep.table
    assert rep.data["double"][0]["gamma"] == pytest.approx(math.radians(17))
    assert rep.data["double"][0]["c5"] == pytest.approx(1.37364e-3, rel=5e-6)


# ------------------------------------------------------------------------------------- declared limits, inputs
def test_every_parameter_declares_its_range():
    assert undeclared(CouplerParams) == []
    with pytest.raises(mbsuite.ParameterError, match=r"coupler parameter m_link = -1.0 is invalid; valid: \[1e-06, "):
        CouplerParams(m_link=-1.0)


def test_omitted_inputs_are_resolved_and_shown(tmp_path, capsys):
    scene = tmp_path / "omits.toml"
    scene.write_text('model = "coupler"\n[input]\ntype = "constant_speed"\nomega = 12.566370614359172\n'
                     '[solver]\nduration = 0.3\nt_settle = 0.25\n')
    sc = mbsuite.load_scene(scene)
    assert sc.input == {"type": "constant_speed", "omega": 4 * math.pi, "load_torque": 1000.0, "alpha_cx": 0.0,
                        "alpha_cz": 0.0, "x_c": 0.0, "z_c": 0.0, "t_ramp": 0.25}
    out = tmp_path / "o"
    assert main(["coupler", "dynamics", str(scene), "--json", "--out", str(out)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["input"]["z_c"] == 0.0 and d["scene"]["input"]["load_torque"] == 1000.0
    assert json.loads((out / "summary.json").read_text())["scene"]["input"]["z_c"] == 0.0
    assert main(["coupler", "dynamics", str(scene)]) == 0
    assert re.search(r"input \(resolved, defaults included\): .*z_c = 0\b", capsys.readouterr().out, re.S)


def test_fpp_size_guard(capsys):
    assert main(["coupler", "fpp", "--n", "1e8"]) == 2
    assert "--n = 100000000 is invalid; valid: integer in [3, 100000]" in capsys.readouterr().err
    assert main(["coupler", "fpp", "--n", "9", "--max-n", "8"]) == 2
    assert main(["coupler", "fpp", "--n", "9", "--max-n", "9", "--json"]) == 0


# ---------------------------------------------------------------------------------------- model files at load
def _copy_models(tmp_path, monkeypatch, edit=None, text=None):
    from mbsuite.paths import models_root

    root = models_root()
    for sub in ("mjcf", "models_urdf"):
        shutil.copytree(root / sub, tmp_path / sub)
    f = tmp_path / "mjcf" / "coupler_double.xml"
    if edit:
        src = f.read_text()
        assert edit[0] in src
        f.write_text(src.replace(edit[0], edit[1], 1))
    if text is not None:
        f.write_text(text)
    monkeypatch.setenv("MBSUITE_MODELS_DIR", str(tmp_path))
    return f


def _link_length_edit() -> tuple[str, str]:
    l = f"{CouplerParams().link_length:.15g}"
    return (f'<connect name="link3" body1="link3" body2="shaft_b" anchor="0 0 {l}"/>',
            '<connect name="link3" body1="link3" body2="shaft_b" anchor="0 0 1.0"/>')


def test_changed_link_length_refused_on_mujoco_and_pinocchio(tmp_path, monkeypatch):
    f = _copy_models(tmp_path, monkeypatch, edit=_link_length_edit())
    sc = mbsuite.load_scene("coupler/double_lateral").replace(solver={"duration": 0.01, "t_settle": 0.0})
    with pytest.raises(ModelFileError) as exc:
        mbsuite.run(sc)
    msg = str(exc.value)
    l = CouplerParams().link_length
    assert str(f) in msg and "'link3'" in msg and f"residual {1.0 - l:.4g} m" in msg and "(MuJoCo)" in msg
    from mbsuite.models.coupler.pinocchio import PinMjcfCoupler

    with pytest.raises(ModelFileError, match=rf"link3.*\(Pinocchio\): residual {1.0 - l:.4g} m"):
        PinMjcfCoupler("double", f)


def test_urdf_closure_refused_by_pinocchio(tmp_path, monkeypatch):
    _copy_models(tmp_path, monkeypatch)
    u = tmp_path / "models_urdf" / "coupler_single.urdf"
    src = u.read_text()
    old = re.search(r'(<mbsuite_closure name="link2"[^>]*length=")([^"]+)"', src)
    u.write_text(src.replace(old.group(0), old.group(1) + '1.2"'))
    from mbsuite.models.coupler.pinocchio import PinCoupler

    with pytest.raises(ModelFileError, match=rf"{re.escape(str(u))}: loop closure 'link2'.*Pinocchio.*residual"):
        PinCoupler.build("single")


def test_malformed_mjcf_is_a_model_file_error(tmp_path, monkeypatch, capsys):
    f = _copy_models(tmp_path, monkeypatch, text="this is not XML <<<")
    with pytest.raises(ModelFileError, match=re.escape(str(f))):
        mbsuite.run(mbsuite.load_scene("coupler/double_lateral").replace(solver={"duration": 0.01, "t_settle": 0.0}))
    assert main(["coupler", "dynamics", "coupler/double_lateral"]) == 2
    err = capsys.readouterr().err
    assert str(f) in err and "Traceback" not in err and "internal error" not in err


def test_missing_name_and_bad_inertia_refused(tmp_path, monkeypatch):
    from mbsuite.models.coupler.filechecks import load_checked_mjcf

    f = _copy_models(tmp_path, monkeypatch, edit=('<site name="BC_S3"', '<site name="BC_S9"'))
    with pytest.raises(ModelFileError, match="site 'BC_S3'"):
        load_checked_mjcf("double", f)
    f.write_text(f.read_text().replace('<site name="BC_S9"', '<site name="BC_S3"').replace(
        'mass="80" diaginertia="40 20 40"', 'mass="80" diaginertia="40 20 100"'))
    with pytest.raises(ModelFileError, match="shaft_b"):  # MuJoCo's compiler or our check, naming the body
        load_checked_mjcf("double", f)


# ------------------------------------------------------------------------------------------------------ health
def _closure_gaps_by_mj_step(sc) -> tuple[np.ndarray, np.ndarray]:
    """The scene's MuJoCo model stepped by `mujoco.mj_step` under the same start-up ramp, not by the native core; at
    every sample the largest distance between a link's far end (site `link<k>_end`) and the driven joint point it is
    closed on (site `BA_S<k+1>` / `BC_S<k+1>` of shaft b), from the site positions, not from the equality rows."""
    import mujoco

    from mbsuite.models.coupler.mujoco import build, ramp_input
    from mbsuite.models.coupler.scenario import scene_inputs

    inp, sv = scene_inputs(sc), sc.solver
    m, d, _ = build(sc.build_params(), dict(sc.effects), inp, sv.timestep, sv.integrator)
    n, every = int(round(sv.duration / sv.timestep)), int(round(sv.sample_dt / sv.timestep))
    ctrl = ramp_input(inp, n, sv.timestep)
    site = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"link{k + 1}_end") for k in range(8)]
    driven = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"{'BA' if k < 4 else 'BC'}_S{(k + 1) % 4 + 1}")
              for k in range(8)]

    def gap() -> float:
        mujoco.mj_kinematics(m, d)
        return float(np.max(np.linalg.norm(d.site_xpos[site] - d.site_xpos[driven], axis=1)))

    t, gaps = [0.0], [gap()]
    for i in range(n):
        d.ctrl[:2] = ctrl[i]
        mujoco.mj_step(m, d)
        if (i + 1) % every == 0:
            t.append((i + 1) * sv.timestep)
            gaps.append(gap())
    return np.array(t), np.array(gaps)


def test_health_figures_on_both_engines():
    sc = mbsuite.load_scene("coupler/double_phibc90").replace(solver={"duration": 0.6})
    mj = mbsuite.run(sc)
    (fig,) = mj.health
    l = sc.build_params().link_length
    assert fig.name == "closure_residual" and fig.bound == pytest.approx(5e-3 * l)
    # the figure is the largest closure gap over the whole run, start-up ramp included: against the gap computed from
    # the site positions of the same model stepped by mj_step (measured: equal to the last bit; bound 1e-9 relative)
    t, gaps = _closure_gaps_by_mj_step(sc)
    assert fig.value == pytest.approx(gaps.max(), rel=1e-9)
    settled = gaps[t >= max(sc.solver.t_settle, sc.input["t_ramp"])].max()
    assert mj.statistics["closure_residual_max"] == pytest.approx(settled, rel=1e-9)
    # the peak lies in the 0.25 s ramp (measured at 0.13 s: 9.45e-4 m, 34x the settled 2.77e-5 m; asserted 10x)
    assert t[gaps.argmax()] < sc.input["t_ramp"] and gaps.max() > 10 * settled
    rf = mbsuite.run(sc, engine="reference")
    assert rf.health[0].value < 2e-13  # rigid FPP, |r| <= 1e-13 R^2: measured 3.4e-14 m; bound 6x
    from mbsuite.models.coupler.scenario import closure_figure
    from mbsuite.trust.health import judge

    with pytest.raises(mbsuite.AccuracyError, match="closure_residual = 0.005666 m exceeds its bound 0.004721 m"):
        judge([closure_figure(6e-3 * l, sc.build_params())])
