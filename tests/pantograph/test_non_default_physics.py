"""Every parameter and every effect value away from its default, each against an independent path or a closed form
(the README's parameter table names the test per parameter):

- MuJoCo (C engine plugins) against the hand-derived right-hand side at one parameter set with EVERY Table 3-I value
  changed (NON_DEFAULT), for the effect values constant/linear/nonlinear cylinder, B6/exact kinematics,
  bilateral/unilateral contact, gravity and viscous damping off;
- Coulomb friction (c1 != c2 != ch) sliding: MuJoCo's frictionloss against the event-exact sliding law, and the smooth
  law c tanh(w / omega_s) at omega_s != default against MuJoCo with that law applied as an external force;
- the orifice against the isentropic nozzle law written out here (choked, subsonic, venting, laminar band);
- the elbow damper be (0 in the thesis, so its term vanishes there): its dissipation rate -be (te' - t2')^2;
- statics at another operating height y_op and with the rigid elbow, the step, static and FORTRAN-start inputs
  (MuJoCo against the reference path), the modes' damping ratio and the fastest pole of the health figure.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from mbsuite import load_scene, run, scene_from_dict
from mbsuite.models.pantograph.equations import G_JOINTS, FrictionModes, PantographConfig, PantographODE
from mbsuite.models.pantograph.linearise import modes_from_eigs, omega_max, stiffest_pole
from mbsuite.models.pantograph.modelfiles import E_THETA_Q, q_to_theta, rigid_elbow_fit, theta_to_q
from mbsuite.models.pantograph.mujoco import MujocoPantograph
from mbsuite.models.pantograph.params import PantographParams

#: every Table 3-I value changed by 5-30 % (be, 0 in the thesis, made 300; c1 != c2 != ch; r_laminar 10x wider band)
NON_DEFAULT = dict(l1=1.80, l2=2.05, lh=0.45, m1=28.0, m2=27.0, mh=11.0, I1=10.5, I2=8.9, Ih=0.5, d1=1.0, d2=0.9,
                   dh=0.30, ks=120000.0, kh=3000.0, ke=38000.0, be=300.0, b1=50.0, b2=120.0, bh=15.0, c1=30.0,
                   c2=20.0, ch=8.0, xf=0.10, yf=0.15, le=0.09, theta_e0=-0.12, lb=0.25, alpha=1.75, Ap=0.011,
                   Ao=4e-6, V0=0.0012, Pg=650000.0, R_gas=290.0, gamma=1.35, cd=0.7, Pa=98000.0, T=305.0,
                   kc=150000.0, bc=80000.0, g=9.81, y_op=1.5, r_laminar=0.9999, omega_s=0.05)


@pytest.fixture(scope="module")
def p() -> PantographParams:
    return PantographParams(**NON_DEFAULT)


def _mj_state(mp: MujocoPantograph, th: np.ndarray, thd: np.ndarray, y_w: float, act: float | None) -> np.ndarray:
    """MuJoCo's generalised acceleration at the state, mapped to the thesis' angles (theta'' = E q'')."""
    m, d = mp.model, mp.data
    d.qpos[:] = theta_to_q(th)
    d.qvel[:] = np.linalg.solve(E_THETA_Q, thd)
    d.ctrl[mp.i_cat] = y_w
    if m.na:
        d.act[0] = act
    mujoco.mj_forward(m, d)
    return E_THETA_Q @ d.qacc


@pytest.mark.parametrize("cylinder,kinematics,contact,gravity,viscous", [
    ("linear", "B6", "bilateral", True, True),
    ("nonlinear", "exact", "unilateral", True, True),
    ("nonlinear", "B6", "bilateral", True, True),
    ("constant", "exact", "bilateral", False, False),
])
def test_mujoco_equals_hand_derived_at_non_default_parameters(p, cylinder, kinematics, contact, gravity, viscous):
    """60 random states (angles over the working range, rates ~0.3 rad/s, ram 1.2-1.8 m; nonlinear cylinder: half the
    pressures inside the laminar band 1 - r_laminar = 1e-4, half in 0.4-1.3 Ps, choked below the critical ratio
    (2 / 2.35)^(1.35 / 0.35) = 0.5369 of gamma = 1.35, written out here): MuJoCo's
    accelerations and cylinder-state rate (C plugins, MJCF written from NON_DEFAULT) against the hand-derived
    Eqs 3.10-3.26. Measured <= 3.9e-14 (accelerations) and 4.4e-16 (rate) relative; bounds 2e-13 (5x) and 5e-15
    (11x). The unilateral case meets both an open and a closed contact."""
    cfg = PantographConfig(cylinder=cylinder, elbow_kinematics=kinematics, contact=contact, gravity=gravity,
                           viscous=viscous, coulomb=False)
    ode, mp = PantographODE(p, cfg), MujocoPantograph(p, cfg)
    r_crit = (2.0 / (p.gamma + 1.0)) ** (p.gamma / (p.gamma - 1.0))
    rng = np.random.default_rng(5)
    forces, band, choked = set(), 0, 0
    for k in range(60):
        th = np.array([rng.uniform(0.1, 1.2), rng.uniform(0.1, 1.2), rng.uniform(-0.6, 0.6)])
        thd = rng.normal(0.0, 0.3, 3)
        y_w = p.y_op + rng.uniform(-0.3, 0.3)
        x, act = np.r_[th, thd], None
        if cylinder == "linear":
            act = ode.cylinder_lever(th[0])[0] + rng.uniform(-1e-3, 1e-3)
        elif cylinder == "nonlinear":
            act = p.Ps * (1.0 + rng.uniform(-1.5e-4, 1.5e-4) if k % 2 else rng.uniform(0.4, 1.3))
            band += min(act, p.Ps) / max(act, p.Ps) > p.r_laminar
            choked += act / p.Ps < r_crit
        if act is not None:
            x = np.r_[x, act]
        forces.add(float(np.sign(ode.contact_force(y_w, ode.contact_height(x)))))
        dx = ode.rhs(0.0, x, y_w)
        qdd = _mj_state(mp, th, thd, y_w, act)
        assert np.max(np.abs(qdd - dx[3:6])) <= 2e-13 * np.max(np.abs(dx[3:6])), k
        if act is not None:
            assert mp.data.act_dot[0] == pytest.approx(dx[6], rel=5e-15, abs=1e-300), k
    if contact == "unilateral":
        assert forces == {0.0, -1.0}
    if cylinder == "nonlinear":
        assert band >= 10 and choked >= 3


def test_coulomb_sliding_mujoco_equals_event_exact_law(p):
    """Coulomb friction c1 = 30, c2 = 20, ch = 8 N m (all different: a joint's friction on another's dof shows), every
    joint sliding (|w| = 0.3-1 rad/s about the equilibrium, where MuJoCo's regularised frictionloss saturates at c):
    MuJoCo's accelerations against the reference path's sliding law -G^T c sgn(w) (A.15). Measured 2.4e-12 relative
    (40 states); bound 1e-11 (4.2x). Other parameters at Table 3-I (be = 0: its large forces would reverse the
    frictionloss' regularised direction)."""
    q = PantographParams(c1=p.c1, c2=p.c2, ch=p.ch)
    cfg = PantographConfig(coulomb=True)
    ode, mp = PantographODE(q, cfg), MujocoPantograph(q, cfg, integrator="rk4", timestep=1e-3)
    x0 = ode.equilibrium()
    rng = np.random.default_rng(11)
    for _ in range(40):
        w = rng.uniform(0.3, 1.0, 3) * rng.choice([-1.0, 1.0], 3)
        thd = np.linalg.solve(G_JOINTS, w)
        th = x0[:3] + rng.uniform(-1e-3, 1e-3, 3)
        P = ode.cylinder_lever(th[0])[0]
        dx = ode.rhs(0.0, np.r_[th, thd, P], q.y_op, FrictionModes(np.zeros(3, dtype=bool), np.sign(w)))
        qdd = _mj_state(mp, th, thd, q.y_op, P)
        assert np.max(np.abs(qdd - dx[3:6])) <= 1e-11 * np.max(np.abs(dx[3:6]))


def test_smooth_coulomb_scale_omega_s(p):
    """coulomb = "smooth" at omega_s = 0.05 rad/s (default 1e-3), rates |w| = 0.2-3 omega_s (the tanh's knee):
    the hand path against MuJoCo without friction plus the torque G^T(-c tanh(w / omega_s)) written out here, applied
    as qfrc_applied. Measured <= 2.5e-11 rad/s^2 (rounding of forces ~1e3 N m); bound 1e-10 rad/s^2 (4x). (omega_s
    ignored or inverted moves the friction torque, ~5 rad/s^2 of head acceleration, by up to 100 %.)"""
    q = PantographParams(c1=p.c1, c2=p.c2, ch=p.ch, omega_s=p.omega_s)
    ode = PantographODE(q, PantographConfig(coulomb="smooth"))
    mp = MujocoPantograph(q, PantographConfig(coulomb=False))
    x0 = ode.equilibrium()
    c = np.array([q.c1, q.c2, q.ch])
    rng = np.random.default_rng(12)
    for _ in range(30):
        w = q.omega_s * rng.uniform(0.2, 3.0, 3) * rng.choice([-1.0, 1.0], 3)
        thd = np.linalg.solve(G_JOINTS, w)
        th = x0[:3] + rng.uniform(-1e-3, 1e-3, 3)
        P = ode.cylinder_lever(th[0])[0]
        dx = ode.rhs(0.0, np.r_[th, thd, P], q.y_op)
        # generalised force in theta, then onto q (theta = E q + const: Q_q = E^T Q_theta)
        mp.data.qfrc_applied[:] = E_THETA_Q.T @ (G_JOINTS.T @ (-c * np.tanh(w / q.omega_s)))
        qdd = _mj_state(mp, th, thd, q.y_op, P)
        assert np.max(np.abs(qdd - dx[3:6])) <= 1e-10
    mp.data.qfrc_applied[:] = 0.0


def _nozzle(p: PantographParams, Pu: float, Pd: float) -> float:
    """Isentropic nozzle mass flow (kg/s) from Pu to Pd, written out: subsonic
    cd Ao Pu sqrt(2 gamma / ((gamma - 1) R T) (r^(2/gamma) - r^((gamma+1)/gamma))), r = Pd / Pu."""
    g, r = p.gamma, Pd / Pu
    return p.cd * p.Ao * Pu * math.sqrt(2.0 * g / ((g - 1.0) * p.R_gas * p.T) * (r ** (2.0 / g) - r ** ((g + 1.0) / g)))


def test_orifice_is_the_isentropic_nozzle_law(p):
    """The corrected Eq 3.17 (errata 10, 12, 14) at non-default gas and orifice values (gamma 1.35, T 305 K, R 290,
    cd 0.7, Ao 4e-6 m^2, Pg 650 kPa, Pa 98 kPa, band 1e-4) against the textbook nozzle law `_nozzle`: filling below
    Ps and venting above it (Pu = P, Pd = Ps, flow out) to 1e-12 relative (measured 1.0e-13); choked below the
    critical ratio of gamma = 1.35 (0.5369, not the thesis' 0.528 of air) the flow is
    cd Ao Ps sqrt(gamma / (R T)) (2 / (gamma + 1))^((gamma + 1) / (2 (gamma - 1))) to 1e-12 (measured <= 2e-16; a
    fixed 0.528 is 1.8e-4 low); in the laminar band the flow is linear in Ps - P and continuous with the law at its
    edge (measured 2.5e-12, bound 1e-11)."""
    ode = PantographODE(p, PantographConfig(cylinder="nonlinear"))
    Ps = p.Ps
    for r in (0.6, 0.8, 0.95, 0.999):
        assert ode.orifice_mass_flow(r * Ps) == pytest.approx(_nozzle(p, Ps, r * Ps), rel=1e-12)
        assert ode.orifice_mass_flow(Ps / r) == pytest.approx(-_nozzle(p, Ps / r, Ps), rel=1e-12)
    w = 1.0 - p.r_laminar
    edge = _nozzle(p, Ps, p.r_laminar * Ps)
    for frac in (0.25, 0.5, 0.999999):
        assert ode.orifice_mass_flow(Ps * (1.0 - frac * w)) == pytest.approx(frac * edge, rel=1e-11)
        assert ode.orifice_mass_flow(Ps * (1.0 + frac * w)) == pytest.approx(-frac * edge, rel=1e-11)
    g = p.gamma
    choked = p.cd * p.Ao * Ps * math.sqrt(g / (p.R_gas * p.T)) * (2.0 / (g + 1.0)) ** ((g + 1.0) / (2.0 * (g - 1.0)))
    for frac in (0.3, 0.5, 0.536):  # below the critical ratio 0.5369 of gamma = 1.35
        assert ode.orifice_mass_flow(frac * Ps) == pytest.approx(choked, rel=1e-12)


def test_elbow_damper_dissipates_at_its_rate():
    """be = 400 N m s/rad (0 in Table 3-I and EQSIM, so the thesis never exercises the term; erratum 9 corrects its
    sign): with every other loss off (viscous, Coulomb, constant cylinder, fixed ram) the energy T + V of A.16-A.17
    falls at the damper's rate dE/dt = -be (te' - t2')^2, te' = dte/dt1 t1'. dE/dt by central differences of the
    energy along the right-hand side (step 1e-5); rates 0.14-378 W, measured |difference| <= 1.9e-6 W (rounding of
    E ~ 1e3 J), bound 1e-5 W (5.3x). (The thesis' printed sign gives a wrong rate at O(1).)"""
    q = PantographParams(be=400.0)
    ode = PantographODE(q, PantographConfig(cylinder="constant", viscous=False, coulomb=False))
    x0 = ode.equilibrium()
    rng = np.random.default_rng(3)
    for _ in range(10):
        x = x0.copy()
        x[:3] += rng.uniform(-0.01, 0.01, 3)
        x[3:6] = rng.normal(0.0, 0.2, 3)
        f = ode.rhs(0.0, x, q.y_op)
        h = 1e-5
        dE = (ode.energy(x + h * f, q.y_op) - ode.energy(x - h * f, q.y_op)) / (2 * h)
        e = ode.elbow(x[0])
        rate = -q.be * (e.dtheta_e * x[3] - x[4]) ** 2
        assert abs(dE - rate) < 1e-5 and rate < -0.1


@pytest.mark.parametrize("yf", [0.142, 0.2])
def test_unilateral_equilibrium_exists_where_the_contact_is_closed(yf):
    """Scene pantograph/unilateral at yf = 0.142 and 0.2 m (0.17 default): the bilateral equilibrium pushes the wire
    (contact force ks (y_d - y_w) = 126 N and 56 N > 0), so it is the push-only contact's equilibrium too (fsolve
    started at the geometric guess y_d = y_w, on the kink of the clipped force, stalls: the search starts from the
    closed contact's equilibrium). Found with a zero static residual (measured <= 1.0e-10 N m, bound 1e-9: the
    solvers' stopping point, 10x), equal to the bilateral one and to MuJoCo's and Pinocchio's own solutions (measured
    <= 1.0e-15 rad, about 9 ulps of the 0.5 rad angles: the roots differ in their last bits; bound 1e-14, 10x)."""
    q = PantographParams(yf=yf)
    uni = PantographODE(q, PantographConfig(contact="unilateral"))
    bil = PantographODE(q, PantographConfig(contact="bilateral"))
    xu, xb = uni.equilibrium(), bil.equilibrium()
    assert np.max(np.abs(xu[:3] - xb[:3])) < 1e-14
    assert q.ks * (uni.contact_height(xu) - q.y_op) > 50.0
    assert np.max(np.abs(uni.static_residual(xu[:3], q.y_op))) < 1e-9
    from mbsuite.models.pantograph.pinocchio import PinocchioPantograph

    for other in (MujocoPantograph, PinocchioPantograph):
        th = q_to_theta(other(q, PantographConfig(contact="unilateral")).equilibrium())
        assert np.max(np.abs(th - xu[:3])) < 1e-14, other.__name__


def test_operating_height_and_rigid_elbow_statics_in_other_paths():
    """y_op = 1.45 m (default 1.58): the equilibrium of the reference, MuJoCo and Pinocchio (the URDF of these
    parameters) paths agree to 4e-14 rad (measured 3.8e-15, the roots' last bits at 0.4 rad; 10x); the rigid elbow's
    (MuJoCo's quartic equality against the exact reduced coordinates) within 10x its fit error, and the static contact
    force is the hand statics' ks (y_d - y_op) in MuJoCo's actuator (measured 2.4e-11 N, bound 2e-10 N, 8x)."""
    from mbsuite.models.pantograph.reports import equilibrium_all_paths

    sc = load_scene("pantograph").replace(params={"y_op": 1.45})
    paths = equilibrium_all_paths(sc)
    for name in ("mujoco", "pinocchio"):
        assert np.max(np.abs(paths[name] - paths["reference"])) <= 4e-14, name
    q = sc.build_params()
    assert abs(paths["reference"][0] - PantographODE().equilibrium()[0]) > 0.02  # a different configuration
    ode = PantographODE(q)
    x0 = ode.equilibrium()
    mp = MujocoPantograph(q)
    mp.set_static(mp.equilibrium(), q.y_op)
    assert q.ks * (ode.contact_height(x0) - q.y_op) == pytest.approx(-mp.data.actuator_force[mp.i_cat], abs=2e-10)
    cfg = PantographConfig(elbow="rigid")
    rigid = PantographODE(q, cfg)
    th_ref = rigid.theta(rigid.equilibrium()[:2])
    _, fit = rigid_elbow_fit(q)
    assert np.max(np.abs(q_to_theta(MujocoPantograph(q, cfg).equilibrium()) - th_ref)) < 10 * fit


def _inputs_scene(inp: dict):
    lab = load_scene("pantograph").to_dict()
    return scene_from_dict({**lab, "input": inp, "effects": {**lab["effects"], "coulomb": False},
                            "outputs": {"signals": ["F1", "HD", "y_d", "y_w", "contact_force", "theta1", "thetah"]},
                            "solver": {**lab["solver"], "duration": 0.5, "t_settle": 0.0}})


@pytest.mark.parametrize("inp", [
    {"type": "step", "height": -3e-3, "t_step": 0.05},
    {"type": "step", "height": 2e-3, "t_step": 0.2, "initial": "fortran"},
    {"type": "sine", "initial": "fortran", "frequency": 3.0, "amplitude": 2.5e-3},
    {"type": "static", "initial": "fortran"},
], ids=["step", "step-fortran", "sine-fortran", "static-fortran"])
def test_step_and_fortran_start_mujoco_equals_reference(inp):
    """A step of the ram (-3 mm at 0.05 s, 2 mm at 0.2 s; defaults 1 mm, 0.1 s) and the thesis' FORTRAN start
    (erratum 18: theta_1 = theta_2 = asin((y_op + A) / 2 l1) with A the amplitude or step height, theta_h = 0, not an
    equilibrium) for each input type, Coulomb off, 0.5 s: the ram is the scene's (closed form), and MuJoCo (RK4 1 ms)
    follows the reference path (LSODA rtol 1e-8) to 1e-4 of each signal's excursion (measured: step 1.7e-5, FORTRAN
    starts <= 2.0e-5; 5x). The ram equals the closed form exactly (measured 0; bound 1e-15, a few ulps of 1.58 m)
    except at the sample on the step instant itself, left out of every comparison: there y_w jumps, and which side a
    sample at exactly t_step reports hangs on how the engine and the recorder round t. (The steps stay on the 1 ms
    grid: MuJoCo holds the ram over each step, so a step between grid points is applied up to half a step early
    or late: 3 % of the excursion measured at t_step = 0.0505 s.)"""
    sc = _inputs_scene(inp)
    a, b = run(sc), run(sc.replace(solver={"engine": "reference"}))
    assert np.array_equal(a.t, b.t)
    y_op = sc.build_params().y_op
    A = inp.get("amplitude", inp.get("height", 0.0))
    keep = np.ones(a.t.size, bool)
    if inp["type"] == "step":
        keep = np.abs(a.t - inp["t_step"]) > 1e-4  # the sample on the step instant (1 ms samples)
        assert np.count_nonzero(~keep) == 1
        ram = y_op + np.where(a.t >= inp["t_step"], inp["height"], 0.0)
    elif inp["type"] == "sine":
        ram = y_op + A * (1.0 - np.cos(2.0 * math.pi * inp["frequency"] * a.t))
    else:
        ram = np.full(a.t.size, y_op)
    if inp.get("initial") == "fortran":
        t1 = math.asin((y_op + A) / (2.0 * sc.build_params().l1))
        assert b["theta1"][0] == pytest.approx(t1, abs=1e-15) and b["thetah"][0] == 0.0
    else:
        before = (a.t < inp["t_step"]) & keep
        # at rest until the step: measured 3.2e-10 N (of 88.7 N), bound 2e-9 N (6x)
        assert np.max(np.abs(b["contact_force"][before] - b["contact_force"][0])) < 2e-9
    assert np.max(np.abs(a["y_w"] - ram)[keep]) < 1e-15 and np.max(np.abs(b["y_w"] - ram)[keep]) < 1e-15
    for s in ("F1", "HD", "y_d", "contact_force"):
        assert np.max(np.abs(a[s] - b[s])[keep]) < 1e-4 * np.ptp(b[s]), s


def test_static_input_rests_at_the_independent_equilibrium():
    """A static ram (type "static"): both paths stay at the static equilibrium. Each run starts from its own path's
    statics (MuJoCo's, the reference's), so the force is compared with a third solution: Pinocchio's equilibrium of
    the URDF (its own CRBA gravity, frame Jacobians and fsolve) and the contact height from Pinocchio's forward
    kinematics, ks (y_d - y_op) = 88.73 N. Measured: MuJoCo 2.8e-10 N, reference 9.0e-9 N throughout; bound 5e-8 N
    (5.6x)."""
    from mbsuite.models.pantograph.pinocchio import PinocchioPantograph

    sc = _inputs_scene({"type": "static"})
    pp = PinocchioPantograph(sc.build_params())
    f0 = pp.p.ks * (pp.contact_height(pp.equilibrium()) - pp.p.y_op)
    assert f0 == pytest.approx(88.73, abs=0.005)
    for res in (run(sc), run(sc.replace(solver={"engine": "reference"}))):
        assert np.max(np.abs(res["contact_force"] - f0)) < 5e-8, res.engine


def test_modes_damping_ratio_and_frequency_closed_form():
    """Modes from eigenvalues of a block-diagonal A with known f_n = 3 and 11 Hz, zeta = 0.3 and 0.05 and a real pole
    at -7 1/s: f_n = |lambda| / 2 pi, zeta = -Re(lambda) / |lambda| (not / Im), tau = 1/7 s, to 1e-12."""
    blocks = []
    for f, z in ((3.0, 0.3), (11.0, 0.05)):
        wn = 2 * math.pi * f
        blocks.append(np.array([[0.0, 1.0], [-wn * wn, -2 * z * wn]]))
    A = np.zeros((5, 5))
    A[:2, :2], A[2:4, 2:4], A[4, 4] = blocks[0], blocks[1], -7.0
    modes = modes_from_eigs(np.linalg.eigvals(A))
    osc = [m for m in modes if m["kind"] == "oscillatory"]
    first = [m for m in modes if m["kind"] == "first-order"]
    assert [m["f_n"] for m in osc] == pytest.approx([3.0, 11.0], rel=1e-12)
    assert [m["zeta"] for m in osc] == pytest.approx([0.3, 0.05], rel=1e-12)
    assert osc[0]["f_d"] == pytest.approx(3.0 * math.sqrt(1 - 0.09), rel=1e-12)
    assert len(first) == 1 and first[0]["tau"] == pytest.approx(1.0 / 7.0, rel=1e-12)


def test_health_fastest_pole_is_the_nonlinear_cylinders():
    """The stability_margin figure's omega_max for the nonlinear cylinder is its real pole (README: 163 1/s, above
    the 121.9 rad/s head mode), from MuJoCo's own linearisation: mjd_transitionFD (implicit, h = 1e-4 s; MuJoCo
    integrates activations by explicit Euler, so the pole is (mu - 1) / h). Measured 4.9e-4 relative; bound 2e-3
    (4x); the head mode alone is 25 % below."""
    p = PantographParams()
    y = p.y_op + 1.85e-3
    cfg = PantographConfig(cylinder="nonlinear")
    mp = MujocoPantograph(p, cfg, integrator="implicit", timestep=1e-4)
    m, d = mp.model, mp.data
    m.dof_frictionloss[:] = 0.0
    mp.set_static(mp.equilibrium(y), y)
    A = np.zeros((7, 7))
    mujoco.mjd_transitionFD(m, d, 1e-7, True, A, None, None, None)
    mu = np.linalg.eigvals(A)
    real = mu[np.abs(mu.imag) < 1e-12].real
    pole = float(np.max(np.abs((real - 1.0) / m.opt.timestep)))
    assert omega_max(p, cfg, y) == pytest.approx(pole, rel=2e-3)
    assert stiffest_pole(p, cfg, y) == omega_max(p, cfg, y)


def test_reference_step_with_coulomb_breaks_at_the_jump():
    """A step of the ram with Coulomb friction on (lab effects, 1 mm at 0.1 s): the reference path ends a smooth
    segment at the jump and re-decides the friction modes there. The holding torques jump past c, so every stuck
    joint slips at t_step itself; the run is then one solution whatever the method and tolerance: LSODA rtol 1e-8
    against DOP853 rtol 1e-11 (a different method at a thousand times the tolerance) within 1e-3 N of contact force
    (measured 4.0e-5 N). Integrated across the jump, LSODA's event finder failed on the kink (a ValueError out of
    scipy at 2 s) or missed stick events (0.07 N off DOP853 in the largest force)."""
    lab = load_scene("pantograph").to_dict()
    sc = scene_from_dict({**lab, "input": {"type": "step", "height": 1e-3, "t_step": 0.1},
                          "solver": {**lab["solver"], "engine": "reference", "duration": 2.0, "t_settle": 1.0}})
    a = run(sc)
    b = run(sc.replace(solver={"method": "DOP853", "rtol": 1e-11, "atol": 1e-13}))
    slips = {e["joint"] for e in a.events if e["kind"] == "slip" and e["t"] == 0.1}
    assert slips == {"base", "knuckle", "head"}
    assert np.array_equal(a.t, b.t) and np.count_nonzero(a.t == 0.1) == 1
    assert np.max(np.abs(a["contact_force"] - b["contact_force"])) < 1e-3
