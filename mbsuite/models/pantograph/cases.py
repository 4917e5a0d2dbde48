"""The pantograph's suite declarations: its hard cases, its work-precision study and the random admissible inputs of
the random-input test (collected by `mbsuite.hardcases`, `mbsuite.analysis.workprecision` and the suite's tests
through `SPEC.cases`). Bounds are stated with the numbers measured when they were set."""

from __future__ import annotations

import math
import warnings

import numpy as np

from ... import load_scene, run
from ...analysis.harmonic import fundamental
from ...analysis.workprecision import Setting, Study
from ...errors import SceneError, SolverError
from ...hardcases import Checker, HardCase
from ...scenes import Scene
from ...trust.health import AccuracyError, InaccurateResultWarning


def _pantograph_stick_slip(ck: Checker) -> None:
    """Lab scene at 2 Hz, 4 s (8 cycles): the event-exact reference and MuJoCo's frictionloss. Measured: 32 stick
    events, 12361 RHS calls, 98 segments; |F1| MuJoCo/reference - 1 = 4.2e-4, |HD| 2.0e-3 (t >= 2 s)."""
    sc = load_scene("pantograph").replace(input={"frequency": 2.0}, solver={"duration": 4.0, "t_settle": 2.0})
    ref = run(sc.replace(solver={"engine": "reference", "sample_dt": 1e-3}))
    mj = run(sc)
    sticks = sum(1 for e in ref.events if e["kind"] == "stick")
    ck.finite("reference and MuJoCo outputs", *ref.signals.values(), *mj.signals.values())
    ck.ge("stick events in 8 cycles (the head joint alone sticks twice per cycle)", sticks, 16)
    ck.le("reference RHS calls (no stall at the sign change; 3x the 12361 measured)", ref.stats["nfev"], 40_000)
    ck.le("reference smooth segments (4x the 98 measured)", ref.stats["segments"], 400)
    ck.true("MuJoCo warnings", mj.stats["warnings"] == {}, mj.stats["warnings"])
    for s, bound in (("F1", 3e-3), ("HD", 1e-2)):  # 7x / 5x the measured 4.2e-4 / 2.0e-3
        a, b = fundamental(mj.t, mj[s], 2.0, 2.0), fundamental(ref.t, ref[s], 2.0, 2.0)
        ck.le(f"|{s}| MuJoCo frictionloss vs event-exact reference, relative", abs(abs(a) / abs(b) - 1), bound)


def _pantograph_orifice_dp0(ck: Checker) -> None:
    """Nonlinear cylinder started at P = Ps (dp = 0), 2 s at 4.25 Hz, both engines. Measured: 6833 RHS calls; MuJoCo
    vs reference |F1| -5.2e-4, |HD| -1.1e-4, pressure swing -5.4e-4, phases <= 0.11 deg; pressure 807.7-814.9 kPa
    (Ps = 811.2 kPa), mean - Ps = +98 Pa = 0.027 of the swing amplitude."""
    from .params import PantographParams

    p = PantographParams()
    sc = load_scene("pantograph/nonlinear_cylinder").replace(
        outputs=["F1", "HD", "cylinder_state"], solver={"duration": 2.0, "t_settle": 1.0})
    ref = run(sc.replace(solver={"engine": "reference"}))
    mj = run(sc)
    ck.finite("reference and MuJoCo outputs", *ref.signals.values(), *mj.signals.values())
    ck.le("reference RHS calls starting at P = Ps (dp = 0; 3x the 6833 measured)", ref.stats["nfev"], 20_000)
    ck.true("MuJoCo warnings", mj.stats["warnings"] == {}, mj.stats["warnings"])
    f = float(sc.input["frequency"])
    for s in ("F1", "HD", "cylinder_state"):
        a, b = fundamental(mj.t, mj[s], f, 1.0), fundamental(ref.t, ref[s], f, 1.0)
        ck.le(f"|{s}| MuJoCo plugin vs reference, relative (5x the measured <= 5.4e-4)", abs(abs(a) / abs(b) - 1),
              3e-3)
        ck.le(f"{s} phase MuJoCo vs reference (deg; 5x the measured 0.11)", abs(math.degrees(np.angle(a / b))), 0.5)
    P = ref["cylinder_state"][ref.t >= 1.0]
    swing = abs(fundamental(ref.t, ref["cylinder_state"], f, 1.0))
    # the orifice passes no net mass over a period: the pressure oscillates about Ps (to second order in the swing);
    # an orifice that pumps one way (erratum 12: the flow not negated above Ps) drifts the mean by many swings
    ck.le("|mean P - Ps| / pressure swing amplitude (4x the measured 0.027)", abs(float(np.mean(P)) - p.Ps) / swing,
          0.1)
    ck.le("max |P - Ps| / pressure swing amplitude (a sine about Ps: 1 + 0.1)", float(np.max(np.abs(P - p.Ps))) / swing,
          1.1)


def _pantograph_orifice_choked(ck: Checker) -> None:
    from .equations import PantographODE

    ode = PantographODE(cylinder="nonlinear")
    p = ode.p
    flows = np.array([ode.orifice_mass_flow(r * p.Ps) for r in np.linspace(0.05, 1.5, 2901)])
    ck.finite("orifice flow over 0.05-1.5 Ps", flows)
    ck.true("inflow below Ps, outflow above (erratum 12), zero at Ps",
            ode.orifice_mass_flow(0.9 * p.Ps) > 0 > ode.orifice_mass_flow(1.1 * p.Ps)
            and ode.orifice_mass_flow(p.Ps) == 0.0)
    choked = [ode.orifice_mass_flow(r * p.Ps) for r in (0.1, 0.2, 0.3, 0.5)]
    ck.le("choked plateau: flow independent of Pd/Pu below the critical ratio (relative spread)",
          np.ptp(choked) / choked[0], 1e-12)
    r = (2 / (p.gamma + 1)) ** (p.gamma / (p.gamma - 1))  # critical ratio, 0.52828 (the thesis' 0.528)
    # corrected Eq 3.17 at the critical ratio, in closed form (sqrt(T), erratum 10)
    expect = p.cd * p.Ao * math.sqrt(2 * p.gamma / (p.R_gas * (p.gamma - 1))) * p.Ps / math.sqrt(p.T) \
        * r ** (1 / p.gamma) * math.sqrt(1 - r ** ((p.gamma - 1) / p.gamma))
    ck.le("choked flow vs corrected Eq 3.17 at the critical ratio, relative", abs(choked[0] / expect - 1), 1e-12)
    # the subsonic branch, from just above the critical ratio to the band, against the isentropic nozzle law written
    # out (a clamp placed above the critical ratio shows at 1.001 r). Measured 4.0e-15 (largest at 0.95 Ps: the
    # cancellation in x^(2/g) - x^((g+1)/g)); bound 4e-14 (10x)
    g = p.gamma
    sub = [abs(ode.orifice_mass_flow(x * p.Ps) / (p.cd * p.Ao * p.Ps * math.sqrt(
        2 * g / ((g - 1) * p.R_gas * p.T) * (x ** (2 / g) - x ** ((g + 1) / g)))) - 1)
        for x in (1.001 * r, 0.6, 0.8, 0.95)]
    ck.le("subsonic flow vs the isentropic nozzle law at 1.001 r_crit, 0.6, 0.8, 0.95 Ps, relative", max(sub), 4e-14)
    edge = p.r_laminar * p.Ps
    ck.le("continuity at the laminar band edge (relative jump)",
          abs(ode.orifice_mass_flow(edge * (1 - 1e-12)) / ode.orifice_mass_flow(edge * (1 + 1e-12)) - 1), 1e-6)
    slope = np.diff(flows) / np.diff(np.linspace(0.05, 1.5, 2901) * p.Ps)
    ck.finite("finite slope d(mdot)/dP everywhere (Lipschitz RHS near dp = 0)", slope)


def _loss_mask(t: np.ndarray, events: list[dict]) -> np.ndarray:
    """Samples strictly inside a contact-loss interval (an interval open at the end of the run lasts to its end)."""
    inside = np.zeros(t.size, bool)
    for e in events:
        if e["kind"] == "contact_loss":
            end = math.inf if e["duration"] is None else e["t_start"] + e["duration"]
            inside |= (t > e["t_start"]) & (t < end)
    return inside


def _pantograph_unilateral(ck: Checker) -> None:
    """Push-only contact, 2.5 mm at 4.25 Hz, 4 s, both engines (1 ms samples). Measured (t >= 2 s): 25 losses in
    each path; paired starts within 1.3 ms, durations within 1.0 ms; total loss time -0.43 %."""
    from .params import PantographParams

    ks = PantographParams().ks
    sc = load_scene("pantograph/unilateral").replace(outputs=["y_d", "y_w", "contact_force"],
                                                     solver={"duration": 4.0, "t_settle": 2.0})
    mj = run(sc)
    ref = run(sc.replace(solver={"engine": "reference", "sample_dt": 1e-3}))
    lm = [e for e in mj.events if e["kind"] == "contact_loss" and e["t_start"] >= 2.0 and e["duration"]]
    lr = [e for e in ref.events if e["kind"] == "contact_loss" and e["t_start"] >= 2.0 and e["duration"]]
    ck.finite("outputs", *mj.signals.values(), *ref.signals.values())
    ck.ge("contact losses detected (reference, 2-4 s; measured 25)", len(lr), 20)
    ck.le("|losses MuJoCo - reference|", abs(len(lm) - len(lr)), 1)
    ds = dd = 0.0
    for b in lr[1:-1]:  # pair each reference loss with the MuJoCo loss that starts nearest
        a = min(lm, key=lambda e: abs(e["t_start"] - b["t_start"]))
        ds, dd = max(ds, abs(a["t_start"] - b["t_start"])), max(dd, abs(a["duration"] - b["duration"]))
    ck.le("paired loss starts MuJoCo vs reference (s; 2.5 samples)", ds, 2.5e-3)
    ck.le("paired loss durations MuJoCo vs reference (s; 2.5 samples)", dd, 2.5e-3)
    tot_m, tot_r = sum(e["duration"] for e in lm), sum(e["duration"] for e in lr)
    ck.le("total loss time MuJoCo vs reference, relative (4.7x the measured 0.43 %)",
          abs(tot_m / tot_r - 1) if tot_r else math.inf, 0.02)
    # the output is clipped at zero, so test the unclipped spring force ks (y_d - y_w) of the reference's states:
    # negative inside every event-located loss (the head below the wire) and non-negative outside (the reference
    # locates the events exactly: measured min +0.20 N outside, max -0.012 N inside)
    fs = ks * (ref["y_d"] - ref["y_w"])
    inside = _loss_mask(ref.t, ref.events)
    ck.le("unclipped spring force inside the reference's losses (N; measured max -0.012)", float(np.max(fs[inside])),
          0.0)
    ck.ge("unclipped spring force outside the reference's losses (N)", float(np.min(fs[~inside])), 0.0)
    ck.le("unclipped spring force reaches below -100 N (real losses, not grazing)", float(np.min(fs)), -100.0)
    ck.true("contact-force output = max(unclipped, 0) (both paths)",
            all(np.array_equal(np.maximum(r["contact_force"], 0.0), r["contact_force"])
                and np.allclose(r["contact_force"], np.maximum(ks * (r["y_d"] - r["y_w"]), 0.0), rtol=0, atol=1e-9)
                for r in (mj, ref)))


def _pantograph_big_step(ck: Checker) -> None:
    sc = load_scene("pantograph").replace(solver={"timestep": 0.02, "duration": 2.0, "t_settle": 1.0})
    for integ in ("euler", "implicitfast", "rk4", "discrete"):
        ck.raises(f"{integ} at h = 0.02 s: AccuracyError (stability_margin) before stepping",
                  lambda i=integ: run(sc.replace(solver={"integrator": i})), AccuracyError, "stability_margin")
    loose = sc.replace(solver={"allow_inaccurate": True})
    for integ in ("euler", "implicitfast"):
        ck.raises(f"{integ} at h = 0.02 s, inaccuracy allowed: SolverError telling to reduce the step",
                  lambda i=integ: run(loose.replace(solver={"integrator": i})), SolverError, "reduce solver.timestep")
    res = run(loose.replace(solver={"integrator": "rk4"}))
    ck.finite("RK4 at h = 0.02 s, inaccuracy allowed", *res.signals.values())
    ck.true("RK4 at h = 0.02 s, inaccuracy allowed: the result carries the warning",
            any("stability_margin" in w for w in res.warnings), res.warnings)


def _pantograph_energy_100s(ck: Checker) -> None:
    from .equations import PantographConfig, PantographODE
    from .modelfiles import E_THETA_Q, q_to_theta, theta_to_q
    from .mujoco import MujocoPantograph

    cfg = PantographConfig(cylinder="constant", viscous=False, coulomb=False)
    ode = PantographODE(config=cfg)
    x0 = ode.equilibrium()
    x0[3:6] = [0.05, -0.03, 0.1]
    y_w = 1.58
    E0 = ode.energy(x0, y_w)
    mp = MujocoPantograph(config=cfg, integrator="rk4", timestep=1e-3)
    mp.set_static(theta_to_q(x0[:3]), y_w)
    mp.data.qvel[:] = np.linalg.solve(E_THETA_Q, x0[3:6])
    tr = mp.stepper(every=1000).run(100_000)
    d = mp.data
    drift = [ode.energy(np.r_[q_to_theta(q), E_THETA_Q @ v], y_w) - E0
             for q, v in zip(tr["qpos"][1:], tr["qvel"][1:], strict=True)]
    drift = np.abs(np.array(drift))
    ck.finite("state after 100 s", d.qpos, d.qvel)
    ck.le("energy drift over 100 s, MuJoCo RK4 1 ms, no damping (J)", drift.max(), 1e-3)
    # RK4 is not symplectic: its energy error grows linearly (measured 1.6e-4 J at 100 s, ratio 9.4 = linear from 0);
    # faster growth (quadratic: ratio ~100, exponential) would be an instability
    ck.le("drift last 10 s / first 10 s (linear growth gives ~10; faster growth fails)",
          drift[-10:].max() / (drift[:10].max() + 1e-9), 15.0)


class PantographStudy(Study):
    """The pantograph's work-precision study: MuJoCo integrators x timesteps and scipy methods x tolerances against
    a Radau rtol 1e-12 reference."""
    SIGNALS = ("F1", "F2", "HD", "y_d")
    MJ_INTEGRATORS = ("euler", "implicitfast", "implicit", "rk4", "discrete")
    MJ_STEPS = (2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4, 5e-5)
    SCIPY = {"DOP853": (1e-4, 1e-6, 1e-8, 1e-10), "RK45": (1e-4, 1e-6, 1e-8), "Radau": (1e-4, 1e-6, 1e-8, 1e-10),
             "LSODA": (1e-4, 1e-6, 1e-8, 1e-10), "BDF": (1e-4, 1e-6, 1e-8)}
    state_doc = "max_t |F1, F2, HD, y_d - ref| / A (A = input amplitude), t >= t_settle, 1 ms grid"
    physics_doc = ("max(rel. amplitude error F1, HD; phase error F1, HD in rad at the forcing frequency; rel. error of "
                   "contact-force mean and std)")

    def __init__(self, scene: Scene, quick: bool = False, frequency: float | None = None, duration: float = 3.0):
        super().__init__(scene, quick)
        inp = dict(scene.input)
        if inp.get("type", "sine") != "sine":
            raise SceneError("the pantograph work-precision study needs a sine input")
        self.f = float(frequency or inp.get("frequency", 4.25))
        T = 1.0 if quick else duration
        self.ts = T / 2
        # allow_inaccurate: the study measures the error of every setting, also of those the health figures refuse
        self.base = scene.replace(effects={"coulomb": False}, input={"frequency": self.f},
                                  outputs=[*self.SIGNALS, "y_w", "contact_force"],
                                  solver={"duration": T, "t_settle": self.ts, "sample_dt": 1e-3,
                                          "max_step": 1.0 / (16 * self.f), "allow_inaccurate": True})
        self.A = float(self.base.input.get("amplitude", 1.85e-3))

    def _run(self, **solver):
        sc = self.base.replace(solver=solver)

        def go():
            with warnings.catch_warnings():  # the refused settings' warnings stay in the result, not on the console
                warnings.simplefilter("ignore", InaccurateResultWarning)
                return run(sc)

        return go

    def settings(self) -> list[Setting]:
        """The settings measured: MuJoCo integrator x timestep and scipy method x rtol."""
        out = []
        integ = ("implicitfast", "rk4") if self.quick else self.MJ_INTEGRATORS
        steps = (1e-3, 5e-4) if self.quick else self.MJ_STEPS
        for i in integ:
            for h in steps:
                out.append(Setting("mujoco", i, h, self._run(engine="mujoco", integrator=i, timestep=h)))
        meth = {"DOP853": (1e-4, 1e-6)} if self.quick else self.SCIPY
        for mth, rtols in meth.items():
            for r in rtols:
                out.append(Setting("reference", mth, r, self._run(engine="reference", method=mth, rtol=r,
                                                                   atol=r * 1e-2)))
        return out

    def reference(self):
        """The reference result (Radau rtol 1e-12) and its check against DOP853 rtol 1e-12."""
        ref = run(self.base.replace(solver={"engine": "reference", "method": "Radau", "rtol": 1e-12, "atol": 1e-14}))
        chk = run(self.base.replace(solver={"engine": "reference", "method": "DOP853", "rtol": 1e-12, "atol": 1e-14}))
        err, det = self.physics_error(chk, ref)
        return ref, {"reference": "scipy Radau rtol 1e-12, atol 1e-14",
                     "check": "scipy DOP853 rtol 1e-12", "check_state_error": self.state_error(chk, ref),
                     "check_physics_error": err}

    def state_error(self, res, ref) -> float:
        """Largest deviation of F1, F2, HD, y_d from the reference after settling, over the amplitude A."""
        m = ref.t >= self.ts
        grid = ref.t[m]
        return max(float(np.max(np.abs(np.interp(grid, res.t, res[s]) - ref[s][m]))) / self.A for s in self.SIGNALS)

    def physics_error(self, res, ref):
        """Largest relative error of the physics metrics (fundamental of F1, HD; contact-force mean and std) and
        each."""
        det = {}
        for s in ("F1", "HD"):
            a, b = fundamental(res.t, res[s], self.f, self.ts), fundamental(ref.t, ref[s], self.f, self.ts)
            det[f"{s}_amp_rel"] = abs(abs(a) / abs(b) - 1.0)
            det[f"{s}_phase_rad"] = abs(float(np.angle(a / b)))
        fr, fc = ref["contact_force"][ref.t >= self.ts], res["contact_force"][res.t >= self.ts]
        sd = float(np.std(fr)) or 1.0
        det["Fc_mean_rel"] = abs(float(np.mean(fc)) - float(np.mean(fr))) / abs(float(np.mean(fr)))
        det["Fc_std_rel"] = abs(float(np.std(fc)) - sd) / sd
        return max(det.values()), det

HARD_CASES: tuple[HardCase, ...] = (
    HardCase("pantograph_stick_slip_2hz", "pantograph",
             "Coulomb stick/slip every half cycle: sign() chatter stalls adaptive solvers",
             "pantograph/lab at 2 Hz, 4 s, both engines",
             "no NaN; >= 16 stick events; reference RHS calls <= 4e4, segments <= 400; no MuJoCo warning; "
             "|F1| MuJoCo vs exact within 0.3 %, |HD| within 1 %", _pantograph_stick_slip),
    HardCase("pantograph_orifice_dp0", "pantograph",
             "orifice law at dp -> 0: unbounded slope of the turbulent law at P = Ps",
             "pantograph/nonlinear_cylinder from P = Ps, 2 s, both engines",
             "no NaN; reference RHS calls <= 2e4; no MuJoCo warning; MuJoCo vs reference F1, HD, P within 0.3 % "
             "and 0.5 deg; P oscillates about Ps (mean within 0.1 swing)", _pantograph_orifice_dp0),
    HardCase("pantograph_orifice_choked", "pantograph",
             "choked flow below the critical Pd/Pu = 0.528 and the laminar band: branch switches of the orifice law",
             "PantographODE(cylinder='nonlinear').orifice_mass_flow over 0.05-1.5 Ps",
             "finite flow and slope; flow sign; choked plateau flat to 1e-12 and equal to corrected Eq 3.17; "
             "subsonic flow equal to the nozzle law to 4e-14; continuous at the band edge",
             _pantograph_orifice_choked),
    HardCase("pantograph_unilateral_contact", "pantograph",
             "push-only contact: non-smooth force, repeated contact loss and impact",
             "pantograph/unilateral (2.5 mm at 4.25 Hz), 4 s, both engines",
             "losses detected (>= 20), counts agree within 1, paired starts/durations within 2.5 ms, total loss "
             "time within 2 %; unclipped spring force <= 0 inside losses, >= 0 outside",
             _pantograph_unilateral),
    HardCase("pantograph_over_large_timestep", "pantograph",
             "explicit/semi-implicit integration far above the stable step",
             "pantograph/lab at h = 0.02 s with euler, implicitfast, rk4, discrete",
             "all: AccuracyError (stability_margin) before stepping; inaccuracy allowed: euler/implicitfast "
             "SolverError 'reduce solver.timestep' (not garbage), rk4 finite with the warning in the result",
             _pantograph_big_step),
    HardCase("pantograph_energy_drift_100s", "pantograph",
             "long-time energy drift of a conservative 3-DOF system with engine plugins",
             "pantograph, constant cylinder, no damping/friction, RK4 1 ms, 100 s",
             "energy drift <= 1e-3 J; growth no faster than linear", _pantograph_energy_100s),
)


def workprecision_study(scene: Scene, quick: bool = False) -> Study:
    """The `workprecision_study` hook: the pantograph study of this scene."""
    return PantographStudy(scene, quick=quick)


def random_input(scene: Scene, rng: np.random.Generator) -> dict:
    """Admissible random changes of a pantograph scene's input: a sine ram of 0.5-1 x the scene's amplitude at 1-12
    Hz."""
    inp = dict(scene.input)
    if inp.get("type") == "sine":
        inp.update(amplitude=float(inp.get("amplitude", 1.85e-3)) * rng.uniform(0.5, 1.0),
                   frequency=rng.uniform(1.0, 12.0))
    return {"input": inp}
