"""Coupled integrator: independent ODE reference, exact per-step contact and dropper laws (no lag), hard cases.
The speed regimes (warning and refusal near the wave speed) are the registry case `catenary_critical_speed`."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mbsuite.errors import ParameterError
from mbsuite.models.catenary.analysis import ContactLostWarning, simulate
from mbsuite.models.catenary.config import CriticalSpeedWarning
from mbsuite.models.catenary.fe import assemble, hermite
from mbsuite.models.catenary.line import Irregularity, PointMass
from mbsuite.models.catenary.lines import stitched
from mbsuite.models.catenary.pantographs import TwoMassPantograph
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.passage import irregularity_at
from mbsuite.models.catenary.sim import CoupledSimulation


def _panto(p):
    return TwoMassPantograph(p.m1, p.k1, p.c1, p.m2, p.k2, p.c2, p.F0)


#: every pantograph, contact, dropper and damping value away from the specification's
NON_DEFAULT = dict(m1=9.0, k1=6000.0, c1=25.0, m2=12.0, k2=80.0, c2=60.0, F0=100.0, k_contact=8.0e4, k_dropper=5.0e4,
                   zeta=0.01, f_damp1=1.5, f_damp2=25.0)


@pytest.mark.parametrize("over", [{}, NON_DEFAULT], ids=["spec", "non-default"])
def test_trapezoidal_coupling_converges_to_independent_ode_solution(over):
    """Linear droppers + attached (bilateral) contact make the coupled system a linear time-varying ODE: integrate it
    with DOP853 (rtol 1e-10), the contact force evaluated continuously with the Hermite interpolation and the contact
    spring in series with the wire's point-load defect there (`fe.contact_defect`), and compare; with the
    specification's values and with every pantograph, contact, dropper and damping value changed."""
    p = CatenaryParams(n_spans=1, element_length=1.0, x_end=30.0, window_start=10.0, window_end=20.0, **over)
    fe = assemble(p)
    n, V = fe.n, 250 / 3.6
    M = fe.M.toarray()
    K = (fe.K0 + fe.Kd).toarray()
    a, b = p.rayleigh()
    C = a * M + b * fe.K0.toarray()
    Mi = np.linalg.inv(M)

    cw_dof, cw_w0 = fe.cw_dof, fe.cw_w0

    def geo(t):
        e, xi, h = fe.element_at(V * t)
        d = cw_dof[e:e + 2].ravel()
        Nl = np.where(d >= 0, hermite(xi, h), 0.0)
        return Nl, np.where(d >= 0, d, 0), float(Nl @ cw_w0[e:e + 2].ravel()), fe.contact_defect(e, xi)

    def force(t, y):
        Nl, d, w0, cb = geo(t)
        return (y[2 * n] - (w0 + Nl @ y[:n][d])) / (1 / p.k_contact + cb), Nl, d

    def rhs(t, y):
        u, v = y[:n], y[n:2 * n]
        x1, x2, v1, v2 = y[2 * n:]
        f, Nl, d = force(t, y)
        F = np.zeros(n)
        np.add.at(F, d, Nl * f)
        a1 = (-p.k1 * (x1 - x2) - p.c1 * (v1 - v2) - f) / p.m1
        a2 = (p.k1 * (x1 - x2) + p.c1 * (v1 - v2) - p.k2 * x2 - p.c2 * v2 + p.F0) / p.m2
        return np.concatenate([v, Mi @ (F - K @ u - C @ v), [v1, v2, a1, a2]])

    pan = _panto(p)
    pan.static(0.0, p.k_contact)
    T = 30.0 / V
    t_eval = 0.004 * np.arange(int(T / 0.004) + 1)  # on both time grids
    sol = solve_ivp(rhs, (0, T), np.concatenate([np.zeros(2 * n), pan.x, [0, 0]]), method="DOP853", rtol=1e-10,
                    atol=1e-12, t_eval=t_eval)
    f_ref = np.array([force(t, y)[0] for t, y in zip(sol.t, sol.y.T, strict=True)])
    errs = []
    for dt in (2e-4, 1e-4):
        res = CoupledSimulation(fe, _panto(p), V, dt, "linear", "bilateral").run(0.0, 30.0)
        idx = np.rint(t_eval / dt).astype(int)
        assert np.allclose(res.t[idx], t_eval, atol=1e-12)
        errs.append(np.max(np.abs(res.force[idx] - f_ref)))
    # measured 0.101 N (2e-4 s) and 0.0249 N (1e-4 s) on a 177 N peak (non-default: 0.091 and 0.0229 N on 157 N);
    # bound 2x above the finer one
    assert errs[1] < 0.05
    # second order: the error falls by 2^2 = 4 per halving (measured 4.04, 3.99); a first-order slip (ratio 2) or an
    # error floor (ratio ~1) fails
    assert 3.5 < errs[0] / errs[1] < 4.5


def test_contact_and_dropper_laws_hold_exactly_at_every_step():
    """No one-step lag: f_{n+1} = k_c max(head - wire, 0) with both heights from the end-of-step state, and each dropper
    is slack exactly when its elastic tension T0 + k delta (end-of-step state) is not positive."""
    p = CatenaryParams(n_spans=2, element_length=0.5, x_end=100.0, window_start=40.0, window_end=80.0)
    fe = assemble(p)
    res = CoupledSimulation(fe, _panto(p), 300 / 3.6, 1e-4, "slack").run(0.0, 100.0, record_droppers=True)
    gap = res.head - res.wire
    expect = p.k_contact * np.maximum(gap, 0.0)
    assert np.max(np.abs(res.force - expect)) < 1e-8 * np.max(res.force)
    assert res.dropper_slack.any(), "the passage must slacken droppers for this test to mean anything"
    tol = 1e-8 * p.k_dropper
    assert np.all(res.dropper_elastic[res.dropper_slack] <= tol)
    assert np.all(res.dropper_elastic[~res.dropper_slack] >= -tol)


def test_near_critical_speed_high_speed_contact_loss_without_blow_up():
    """420 km/h (96 % of the wave speed) with a light uplift: warned, contact lost and regained many times, all
    finite, the wire and pantograph stay within physical bounds."""
    p = CatenaryParams(n_spans=3, element_length=0.5, x_end=170.0, window_start=60.0, window_end=120.0, F0=60.0)
    fe = assemble(p)
    with pytest.warns(CriticalSpeedWarning):
        run = simulate(p, 420.0, 1e-4, fe=fe)
    r = run.result
    assert np.all(np.isfinite(r.force)) and np.all(np.isfinite(r.uplift))
    ev = run.stats["loss_events"]
    assert len(ev) >= 3 and run.stats["loss_pct"] > 0
    # no blow-up: measured |wire|, |head| <= 0.075 m and a peak force of 158 N; bounds 4x and 3.8x above
    assert np.max(np.abs(r.wire)) < 0.3 and np.max(np.abs(r.head)) < 0.3
    assert np.max(r.force) < 10 * p.F0


@pytest.mark.parametrize("F0", [0.0, -50.0])
def test_pantograph_leaving_the_wire_is_reported_not_nan(F0):
    """Zero (or negative) static uplift: the head drops off the wire; the run reports it, statistics stay finite."""
    p = CatenaryParams(n_spans=2, element_length=0.5, x_end=100.0, window_start=40.0, window_end=80.0, F0=F0)
    with pytest.warns(ContactLostWarning, match="off the wire"):
        run = simulate(p, 250.0, 2e-4)
    s = run.stats
    assert s["contact_lost_entirely"] and s["loss_pct"] == 100.0
    for k in ("Fm", "sigma", "stat_max", "stat_min", "max", "min", "uplift_mm"):
        assert math.isfinite(s[k])
    assert abs(s["Fm"]) < 1e-6 and s["sigma"] < 1e-6
    assert len(s["loss_events"]) == 1 and s["loss_counts"]["power_loss_gt_20ms"] == 1


def test_bad_speed_and_timestep():
    p = CatenaryParams(n_spans=1, x_end=50.0, window_start=10.0, window_end=40.0)
    for bad in (0.0, -10.0, float("nan")):
        with pytest.raises(ParameterError, match="speed"):
            simulate(p, bad, 1e-4)
    with pytest.raises(ParameterError, match="solver.timestep"):
        simulate(p, 200.0, -1e-4)


@pytest.mark.parametrize("law", ["slack", "linear"])
def test_energy_balance_closes_through_contact_loss_and_recontact(law):
    """Undamped, weightless catenary and pantograph at 400 km/h with a light uplift: the total energy (catenary with
    the exact dropper law + pantograph + contact spring) changes only by the work the imposed horizontal motion feeds
    in through the sloping wire, -int f V dw/dx dt, across contact losses and re-contacts (no energy blow-up)."""
    p = CatenaryParams(n_spans=3, element_length=0.5, x_end=170.0, window_start=60.0, window_end=120.0, F0=60.0,
                       zeta=0.0, c1=0.0, c2=0.0, g=0.0)
    fe = assemble(p)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CriticalSpeedWarning)
        r = CoupledSimulation(fe, _panto(p), 400 / 3.6, 1e-4, law).run(0.0, 170.0, record_energy=True, record_every=5)
    E = r.energy
    total = E["catenary"] + E["pantograph"] + E["contact"]
    work = np.concatenate([[0.0], np.cumsum(0.5 * (E["drive_power"][1:] + E["drive_power"][:-1]) * np.diff(r.t))])
    scale = np.max(np.abs(total - total[0]))
    assert scale > 10.0  # J: the passage does put energy into the wire
    # measured 4.1e-4 (slack) and 1.34e-3 (linear: 11 losses and re-contacts) of the energy exchanged at dt 1e-4 s;
    # bounds 6x and 3.7x above (a dropped loss or drive-work term of 0.3 % fails)
    bound = {"slack": 2.5e-3, "linear": 5e-3}[law]
    assert np.max(np.abs(total - total[0] - work)) < bound * scale
    if law == "linear":
        assert np.sum(np.diff((r.force <= 0).astype(int)) == 1) >= 5  # contact lost and regained repeatedly


def test_energy_balance_closes_on_a_stitched_line_with_masses_and_an_irregularity():
    """The balance above on a line with every new element: a stitch wire (6-DOF nodes, clamps to the messenger, its
    tension relieving the messenger's), point masses, dropper masses and clamp masses, droppers of both laws and a
    contact-wire irregularity, at 300 km/h (below the stitch wire's wave speed). The imposed motion's power is
    -f V d(w + r)/dx: measured 1.9e-3 of the energy exchanged through 12 contact losses (bound 5e-3, 2.7x); without
    the irregularity's slope dr/dx the balance is off by 0.24 of it."""
    p = CatenaryParams(n_spans=3, element_length=0.5, x_end=170.0, window_start=60.0, window_end=120.0, F0=60.0,
                       zeta=0.0, c1=0.0, c2=0.0, g=0.0)
    line = stitched(p)
    drop = tuple(dataclasses.replace(d, law="linear", mass=0.2, clamp_lower=0.1) if i % 3 == 1 else d
                 for i, d in enumerate(line.droppers))
    xs = np.arange(0.0, 140.0 + 1e-9, 0.5)
    irr = Irregularity(x0=5.0, dx=0.5, r=0.004 * np.sin(2 * np.pi * xs / 7.3) * np.exp(-(((xs - 70) / 50) ** 2)))
    masses = (PointMass(60.0, "contact", 0.8), PointMass(30.0, "messenger", 0.5))
    p = dataclasses.replace(p, line=dataclasses.replace(line, droppers=drop, irregularity=irr, masses=masses))
    fe = assemble(p)
    V = 300 / 3.6
    r = CoupledSimulation(fe, _panto(p), V, 1e-4, "slack").run(0.0, 75.0, record_energy=True, record_every=5)
    E = r.energy
    total = E["catenary"] + E["pantograph"] + E["contact"]

    def work(power):
        return np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(r.t))])

    scale = np.max(np.abs(total - total[0]))
    assert scale > 5.0 and np.sum(np.diff((r.force <= 0).astype(int)) == 1) >= 5
    assert np.max(np.abs(total - total[0] - work(E["drive_power"]))) < 5e-3 * scale
    # the irregularity's share of the power, from the profile's own slope (line.Irregularity.slope)
    p_irr = -r.force * V * irr.slope(r.x)
    assert np.max(np.abs(total - total[0] - work(E["drive_power"] - p_irr))) > 0.1 * scale


def test_irregularity_is_the_profile_interpolated_linearly_and_zero_outside():
    """`passage.irregularity_at` (the operations the compiled core repeats) against the profile's own numpy
    interpolation (`line.Irregularity`, np.interp) on and between the grid points and outside: equal to the rounding of
    the positions (measured 5.5e-17 m of 4e-3 m; bound 5e-16 m); slopes equal to rounding, 0 outside."""
    r = np.random.default_rng(3).uniform(-0.004, 0.004, 41)
    irr = Irregularity(x0=12.3, dx=0.7, r=r)
    xs = np.concatenate([np.linspace(0.0, 50.0, 2001), 12.3 + 0.7 * np.arange(41), [12.3 - 1e-9, 12.3 + 28.0 + 1e-9]])
    got = np.array([irregularity_at(irr, x) for x in xs])
    assert np.max(np.abs(got[:, 0] - irr(xs))) < 5e-16
    inside = (xs >= 12.3) & (xs < 12.3 + 28.0)
    assert np.max(np.abs(got[inside, 1] - irr.slope(xs[inside]))) < 1e-12 * np.max(np.abs(got[:, 1]))
    assert np.all(got[~inside & (xs != 12.3 + 28.0)] == 0.0) and irregularity_at(None, 20.0) == (0.0, 0.0)


def test_passage_is_a_step_object_and_run_its_driver():
    """`start` gives the coupled static state; `step()` advances it by dt; `run` records exactly what stepping by hand
    gives. The first record is the static state (uplift at the supports included)."""
    p = CatenaryParams(n_spans=2, element_length=0.5, x_start=30.0, x_end=50.0, window_start=35.0, window_end=45.0)
    fe = assemble(p)
    sim = CoupledSimulation(fe, _panto(p), 250 / 3.6, 2e-4, "slack")
    ps = sim.start(30.0, 50.0)
    assert (ps.n, ps.t, ps.x, ps.status) == (0, 0.0, 30.0, "running") and ps.force == ps.static_force > 0
    forces, heads = [ps.force], [ps.head]
    while ps.status == "running":
        ps.step()
        forces.append(ps.force)
        heads.append(ps.head)
    assert ps.n == ps.nsteps == 1440 and ps.x == 50.0 and ps.t == pytest.approx(1440 * 2e-4)
    with pytest.raises(RuntimeError, match="finished"):
        ps.step()
    res = CoupledSimulation(fe, _panto(p), 250 / 3.6, 2e-4, "slack").run(30.0, 50.0, native=False)  # the twin
    assert np.array_equal(res.force, forces) and np.array_equal(res.head, heads)
    start = sim.start(30.0, 50.0)
    sup = fe.support_cw
    assert res.uplift[0, 1] == start.u[sup[1]] > 0  # the static contact force lifts the support at 60 m
