"""The IFToMM gates' suite declarations: hard cases, the four-bar's work-precision study (closed-form reference) and
the random admissible inputs of the random-input test (collected through `SPEC.cases`)."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ... import load_scene, run
from ...analysis.workprecision import Setting, Study, _rel
from ...engines import core
from ...errors import MbsuiteError
from ...hardcases import Checker, HardCase
from ...scenes import Scene
from .mujoco import channels, closure_jacobian_rank, closure_of, initial_velocity, mujoco_model


def _iftomm_fourbar(ck: Checker) -> None:
    from scipy.integrate import solve_ivp


    sc = load_scene("iftomm/fourbar")
    mj = run(sc)
    ref = run(sc.replace(solver={"engine": "reference", "rtol": 1e-10, "atol": 1e-12}))
    # independent closed form on the parallelogram branch: M = (1/3 + 1/3 + 1) m L^2, V = 2 m g L sin(psi)
    g = 9.81
    an = solve_ivp(lambda t, x: [x[1], -1.2 * g * math.cos(x[0])], (0, ref.t[-1]), [math.pi / 2, 6.0],
                   method="DOP853", rtol=1e-12, atol=1e-12, t_eval=ref.t)
    ck.finite("MuJoCo and Pinocchio outputs", *mj.signals.values(), *ref.signals.values())
    turns = (mj["input_angle"][-1] - mj["input_angle"][0]) / (2 * math.pi)
    turns_an = (an.y[0][-1] - an.y[0][0]) / (2 * math.pi)
    ck.ge("crank turns in 10 s (2 singular positions per turn)", turns, 10)
    # measured 0.020 turn of 11.9 (MuJoCo's soft closures lose 0.36 J and the crank falls behind); bound 5x
    ck.le("MuJoCo crank turns in 10 s vs the closed form", abs(turns - turns_an), 0.1)
    # measured 7.5e-9 rad (DOP853 rtol 1e-10); bound 6.7x
    ck.le("Pinocchio (branch-reduced) vs closed form, crank angle (rad)",
          np.max(np.abs(ref["input_angle"] + math.pi / 2 - an.y[0])), 5e-8)
    ck.le("MuJoCo stays on the parallelogram branch: max |coupler angle| (rad)", mj.statistics["branch_angle_max"],
          0.01)
    ck.le("MuJoCo closure residual (m)", mj.statistics["closure_residual_max"], 2e-4)
    # measured 0.36 J of 30 J kinetic energy: the soft closure (solref 4 ms, damping ratio 1) dissipates
    ck.le("MuJoCo energy drift over 10 s (J)", mj.statistics["energy_drift_max"], 0.5)
    ck.le("Pinocchio energy drift (J)", ref.statistics["energy_drift_max"], 3e-7)  # measured 4.8e-8 J; bound 6x
    # against the closed form (= Pinocchio to 7.5e-9 rad): measured 7.39e-3 rad over the first 2 s; bound 4x
    ck.le("MuJoCo vs closed form, crank angle over the first 2 s (rad)",
          np.max(np.abs(mj["input_angle"] + math.pi / 2 - an.y[0])[mj.t <= 2.0]), 0.03)
    ck.true("MuJoCo warnings", mj.stats["warnings"] == {}, mj.stats["warnings"])


def _iftomm_bricard(ck: Checker) -> None:

    sc = load_scene("iftomm/bricard")
    mj = run(sc)
    ref = run(sc.replace(solver={"engine": "reference"}))
    m = mujoco_model("bricard", 1e-3, "rk4", 0.004, 9.81)
    rank0, s0 = closure_jacobian_rank(m, np.zeros(m.nq))
    ck.true("closure Jacobian: 6 rows, rank 4 on 5 joints -> 1 DOF (Gruebler: 0), detected by SVD",
            rank0 == 4 and m.nv - rank0 == 1, (rank0, np.round(s0, 6).tolist()))
    ck.finite("MuJoCo and Pinocchio outputs", *mj.signals.values(), *ref.signals.values())
    ck.ge("it moves: range of joint 1 (rad)", np.ptp(ref["input_angle"]), 0.5)
    ck.le("Pinocchio closure residual (m)", ref.statistics["closure_residual_max"], 1e-6)
    ck.le("Pinocchio energy drift (J)", ref.statistics["energy_drift_max"], 5e-4)  # measured 1.03e-4 J; bound 5x
    ck.le("MuJoCo closure residual with redundant rows (m)", mj.statistics["closure_residual_max"], 5e-4)
    ck.le("MuJoCo energy drift over 10 s (J)", mj.statistics["energy_drift_max"], 0.1)
    ck.le("MuJoCo vs Pinocchio joint 1 over 10 s (rad)", np.max(np.abs(mj["input_angle"] - ref["input_angle"])), 0.15)
    # measured 3.8e-7 rad (the penalty formulation's closure error, 3.2e-7 m); bound 5x
    ck.le("symmetric motion q1 + q3 = 0 (Pinocchio, rad)", ref.statistics["branch_angle_max"], 2e-6)
    ck.true("MuJoCo warnings", mj.stats["warnings"] == {}, mj.stats["warnings"])


def _iftomm_drift_100s(ck: Checker) -> None:
    for mech, rate in (("fourbar", 6.0), ("bricard", 0.0)):
        m = mujoco_model(mech, 1e-3, "rk4", 0.004, 9.81)
        d = mujoco.MjData(m)
        d.qvel[:] = initial_velocity(m, rate)
        mujoco.mj_forward(m, d)
        E0 = float(d.energy.sum())
        tr = core.Stepper(m, d, channels(m), every=100, what=f"IFToMM {mech} 100 s").run(100_000)
        res, en = closure_of(tr, m)[1:], tr["energy"].sum(axis=1)[1:] - E0
        qs = tr["q"][1:]
        ck.finite(f"{mech}: 100 s state", d.qpos, d.qvel)
        ck.le(f"{mech}: closure residual over 100 s (m)", res.max(), 5e-4)
        ck.le(f"{mech}: closure residual last 10 s / first 10 s (no drift)", res[-100:].max() / res[:100].max(), 2.0)
        ck.true(f"{mech}: energy only dissipated (soft closure damping), never gained beyond 1e-6 J",
                bool(en.max() <= 1e-6), float(en.max()))
        if mech == "fourbar":
            ck.le("fourbar: branch kept for 100 s, max |coupler angle| (rad)", float(np.max(np.abs(
                qs[:, 0] + qs[:, 1]))), 0.02)


class FourbarStudy(Study):
    """Work-precision study of the four-bar: MuJoCo integrators x timesteps and Pinocchio (scipy methods x
    rtol) against the closed form on the parallelogram branch, psi'' = -(6/5) g cos psi."""
    MJ_INTEGRATORS = ("euler", "implicitfast", "rk4")
    MJ_STEPS = (2e-3, 1e-3, 5e-4, 2.5e-4)
    PIN = {"DOP853": (1e-4, 1e-6, 1e-8, 1e-10), "LSODA": (1e-4, 1e-6, 1e-8), "Radau": (1e-4, 1e-6, 1e-8)}
    state_doc = "max_t |crank angle - ref| / 1 rad, 10 s through 24 singular positions"
    physics_doc = ("max(rel. error of the crank's turns in 10 s, max closure residual / L, |energy drift| / E_kin(0), "
                   "max |coupler angle| (branch))")

    def __init__(self, scene: Scene, quick: bool = False):
        super().__init__(scene, quick)
        if scene.effects["mechanism"] != "fourbar":
            raise MbsuiteError("the IFToMM work-precision study covers the four-bar (closed-form reference); the "
                               "Bricard has none (its hard case compares MuJoCo with Pinocchio)")
        T = 2.0 if quick else 10.0
        # the study measures errors: results past a health bound are kept (with their warning), not refused
        self.base = scene.replace(solver={"duration": T, "sample_dt": 1e-2, "allow_inaccurate": True})
        self.rate = float(scene.input["rate"])
        self.g = float(scene.build_params().gravity)

    def settings(self) -> list[Setting]:
        """The settings of the study: MuJoCo integrators x timesteps, Pinocchio methods x tolerances."""
        out = []
        for i in (("rk4",) if self.quick else self.MJ_INTEGRATORS):
            for h in ((1e-3,) if self.quick else self.MJ_STEPS):
                sc = self.base.replace(solver={"engine": "mujoco", "integrator": i, "timestep": h})
                out.append(Setting("mujoco", i, h, lambda sc=sc: run(sc)))
        for mth, rtols in ({"DOP853": (1e-6,)} if self.quick else self.PIN).items():
            for r in rtols:
                sc = self.base.replace(solver={"engine": "reference", "method": mth, "rtol": r, "atol": r * 1e-2})
                out.append(Setting("pinocchio", mth, r, lambda sc=sc: run(sc)))
        return out

    def reference(self):
        """The closed-form reference on the parallelogram branch (DOP853, rtol 1e-13)."""
        from scipy.integrate import solve_ivp

        t = np.arange(0.0, self.base.solver.duration + 5e-3, 1e-2)
        g = self.g
        sol = solve_ivp(lambda _, x: [x[1], -1.2 * g * math.cos(x[0])], (0.0, t[-1]), [math.pi / 2, self.rate],
                        method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
        self.e_kin0 = 0.5 * (5.0 / 3.0) * self.rate**2
        return {"t": sol.t, "angle": sol.y[0] - math.pi / 2}, {
            "reference": "closed form on the parallelogram branch, psi'' = -(6/5) g cos(psi), DOP853 rtol 1e-13"}

    def state_error(self, res, ref) -> float:
        """max_t |crank angle - reference| [rad]."""
        return float(np.max(np.abs(np.interp(ref["t"], res.t, res["input_angle"]) - ref["angle"])))

    def physics_error(self, res, ref):
        """Physics error of one setting and its parts (the class's `physics_doc`)."""
        turns = (res["input_angle"][-1] - res["input_angle"][0]) / (2 * math.pi)
        turns_ref = (ref["angle"][-1] - ref["angle"][0]) / (2 * math.pi)
        det = {"turns_rel": _rel(turns, turns_ref), "closure_residual": res.statistics["closure_residual_max"],
               "energy_drift_rel": res.statistics["energy_drift_max"] / self.e_kin0,
               "branch_rad": res.statistics["branch_angle_max"]}
        return max(det.values()), det

HARD_CASES: tuple[HardCase, ...] = (
    HardCase("iftomm_fourbar_singular", "iftomm",
             "A02: all bars collinear twice per turn; the closure Jacobian loses rank and the parallelogram may "
             "switch to the anti-parallelogram branch",
             "iftomm/fourbar, 10 s, MuJoCo and Pinocchio",
             ">= 10 turns, within 0.1 turn of the closed form; stays on branch (|coupler angle| <= 0.01 rad); "
             "closure <= 2e-4 m; energy drift <= 0.5 J (MuJoCo) / 3e-7 J (Pinocchio); Pinocchio = closed form to 5e-8 "
             "rad; MuJoCo = closed form to 0.03 rad over the first 2 s", _iftomm_fourbar),
    HardCase("iftomm_bricard_overconstrained", "iftomm",
             "A04: over-constrained loop (Gruebler 0 DOF, real 1 DOF): redundant closure rows",
             "iftomm/bricard, 10 s, MuJoCo and Pinocchio",
             "rank 4 of 6 rows detected; closure <= 5e-4 m (MuJoCo) / 1e-6 m (Pinocchio); energy drift <= 0.1 / "
             "5e-4 J; paths agree within 0.15 rad; symmetric motion q1 + q3 <= 2e-6 rad", _iftomm_bricard),
    HardCase("iftomm_drift_100s", "iftomm",
             "100 s of soft closures through singular positions and redundant rows",
             "iftomm fourbar and bricard, MuJoCo RK4 1 ms, 100 s",
             "closure <= 5e-4 m without growth; energy never gained; four-bar stays on its branch",
             _iftomm_drift_100s, slow=True),
)


def workprecision_study(scene: Scene, quick: bool = False) -> Study:
    """The IFToMM work-precision study (the four-bar; the Bricard has no closed form)."""
    return FourbarStudy(scene, quick=quick)


def random_input(scene: Scene, rng: np.random.Generator) -> dict:
    """A random initial rate of the input joint: +-8 rad/s on the four-bar, +-1 rad/s on the Bricard."""
    rate = rng.uniform(-8.0, 8.0) if scene.effects["mechanism"] == "fourbar" else rng.uniform(-1.0, 1.0)
    return {"input": {**scene.input, "rate": rate}}
