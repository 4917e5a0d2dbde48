"""The catenary's suite declarations: its hard cases (one pantograph near the wave speed; two pantographs: the
trailing one near the warning limit, contact loss on both, slack droppers under both, a steady-arm start) and the
random admissible inputs of the random-input test (collected by `mbsuite.hardcases` and the suite's tests through
`SPEC.cases`), and the work-precision study (`workprecision_study`, `CatenaryStudy`: element length x time step
against the EN 50318 statistics' errors and CPU, `docs/accuracy.md`)."""

from __future__ import annotations

import hashlib
import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ...analysis.workprecision import Setting, Study
from ...errors import ParameterError
from ...hardcases import Checker, HardCase
from ...scenes import Scene
from .pantographs import PANTOGRAPH_MODELS


def _catenary_critical_speed(ck: Checker) -> None:
    import math

    from .config import CriticalSpeedWarning, speed_regime
    from .params import CatenaryParams

    p = CatenaryParams()
    c = p.cw_wave_speed
    # closed form: c = sqrt(T / rho) = sqrt(20000 / 1.35) m/s = 438.2 km/h (measured equal to rounding)
    ck.le("CW wave speed against sqrt(T/rho) (relative)", abs(c / math.sqrt(20000.0 / 1.35) - 1.0), 1e-15)

    def regime(v: float) -> tuple[dict, list[str]]:
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            info = speed_regime(p, v)
        return info, [str(x.message) for x in w if issubclass(x.category, CriticalSpeedWarning)]

    info, w = regime(0.5 * c)
    ck.true("50 % of c: no warning, subcritical", not w and info["regime"] == "subcritical", info["regime"])
    info, w = regime(300 / 3.6)
    ck.true("300 km/h (68 % of c, below the EN 50119 70 % limit): no warning, subcritical",
            not w and info["regime"] == "subcritical", info["regime"])
    info, w = regime(320 / 3.6)
    ck.true("320 km/h (73 % of c): CriticalSpeedWarning naming EN 50119, regime 'above EN 50119 limit'",
            len(w) == 1 and "EN 50119" in w[0] and info["regime"] == "above EN 50119 limit", info["regime"])
    info, w = regime(0.95 * c)
    ck.true("95 % of c: CriticalSpeedWarning 'Near-critical', regime near-critical",
            len(w) == 1 and "Near-critical" in w[0] and info["regime"] == "near-critical", info["regime"])
    ck.raises("speed at the wave speed sqrt(T/rho)", lambda: speed_regime(p, c), ParameterError, "wave speed")
    ck.raises("450 km/h, above the wave speed", lambda: speed_regime(p, 450 / 3.6), ParameterError, "wave speed")


#: a shortened two-pantograph line (6 spans): the leading pantograph ends at 180 + 120 = 300 m <= 360 m
def _p6(**kw):
    from .params import CatenaryParams

    return CatenaryParams(element_length=0.5, n_spans=6, x_end=180.0, window_start=90.0, window_end=150.0, **kw)


def _contact_law(ck: Checker, run, label: str) -> None:
    """f = k_c max(head - wire, 0) at every step of every pantograph's record (end-of-step states)."""
    kc = run.params.k_contact
    for k, r in enumerate(run.results):
        err = float(np.max(np.abs(r.force - kc * np.maximum(r.head - r.wire, 0.0))))
        ck.le(f"{label}: pantograph {k + 1} contact law at every step (N, relative to its peak force)",
              err / max(float(np.max(r.force)), 1.0), 1e-13)  # measured <= 1.13e-14 (rounding): 9x


def _trailing_near_warning_speed(ck: Checker) -> None:
    from .config import CriticalSpeedWarning
    from .train import simulate_train

    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        run = simulate_train(_p6(), 310.0, 2e-4, ["reference2mass", "reference2mass"], [120.0])
    ck.true("310 km/h (70.7 % of c): CriticalSpeedWarning", any(issubclass(x.category, CriticalSpeedWarning)
                                                               for x in w))
    for k, r in enumerate(run.results):
        ck.finite(f"pantograph {k + 1} record", r.force, r.head, r.wire, r.uplift)
    _contact_law(ck, run, "310 km/h")
    lead, trail = run.stats
    ck.ge("the trailing pantograph, in the leading one's wave, varies more: sigma_trail / sigma_lead",
          trail["sigma"] / lead["sigma"], 1.2)
    ck.ge("the trailing pantograph loses contact (%)", trail["loss_pct"], 0.1)
    ck.le("largest wire and head excursion (m; small-displacement model)",
          max(float(np.max(np.abs(r.wire))) + float(np.max(np.abs(r.head))) for r in run.results), 0.3)
    ck.measured.update({"sigma_lead": lead["sigma"], "sigma_trail": trail["sigma"], "loss_trail": trail["loss_pct"]})


def _loss_on_both(ck: Checker) -> None:
    from .stats import in_window
    from .train import simulate_train

    p = _p6(F0=40.0)
    run = simulate_train(p, 300.0, 2e-4, ["reference2mass", "reference2mass"], [120.0])
    for k, s in enumerate(run.stats):
        ck.ge(f"pantograph {k + 1}: contact-loss events in the window", len(s["loss_events"]), 1)
        # the window by its own rule (`in_window`: both edges fall on samples here, x = 90.0 and 150.0 exactly, and a
        # last-bit change would move an edge sample out of a strict window only)
        w = in_window(run.results[k].x, p)
        ck.true(f"pantograph {k + 1}: loss percentage = share of window samples with force <= 0",
                abs(s["loss_pct"] - 100 * np.mean(run.results[k].force[w] <= 0)) < 1e-12, s["loss_pct"])
        ck.finite(f"pantograph {k + 1} record", run.results[k].force, run.results[k].head)
    _contact_law(ck, run, "F0 = 40 N, 300 km/h")


def _slack_under_both(ck: Checker) -> None:
    from .fe import assemble
    from .train import simulate_train

    p = _p6(F0=70.0)
    run = simulate_train(p, 300.0, 2e-4, ["reference2mass", "reference2mass"], [120.0], record_droppers=True)
    dx = assemble(p).x[assemble(p).droppers]
    for k in range(2):
        near = np.abs(run.x[:, k][:, None] - dx[None, :]) <= 10.0
        ck.ge(f"slack dropper-steps within 10 m of pantograph {k + 1}", int((run.dropper_slack & near).sum()), 100)
    # exact law: a slack dropper's elastic tension is <= 0, a taut one's >= 0, to rounding of a ~100 N tension
    # (measured: the closest slack dropper at -0.010 N, the closest taut one at +0.0016 N, i.e. no violation at all)
    tol = 1e-10
    de, ds = run.dropper_elastic[1:], run.dropper_slack[1:]
    ck.le("slack droppers carry no elastic tension: max (T0 + k delta) of a slack dropper (N)",
          float(np.max(de[ds])), tol)
    ck.ge("taut droppers are in tension: min (T0 + k delta) of a taut dropper (N)", float(np.min(de[~ds])), -tol)
    _contact_law(ck, run, "F0 = 70 N")


def _trailing_starts_on_a_steady_arm(ck: Checker) -> None:
    from .analysis import simulate
    from .train import simulate_train

    p = _p6()
    run = simulate_train(p, 250.0, 2e-4, ["reference2mass", "reference2mass"], [120.0])
    single = simulate(p, 250.0, 2e-4)
    r = run.results[1]
    n_entry = int(round(120.0 / (250 / 3.6) / 2e-4))
    ck.true("at its entry step the trailing pantograph is at the pinned support x = 0 and the leading one on the "
            "steady arm at 120 m (to 1e-9 m: the entry position is V n dt in either association)",
            abs(r.x[0]) < 1e-9 and abs(run.x[n_entry, 1]) < 1e-9 and abs(run.x[n_entry, 0] - 120.0) < 1e-9,
            (float(run.x[n_entry, 1]), float(run.x[n_entry, 0])))
    ck.le("its start state is the single pantograph's: |static force - single's| (N)",
          abs(run.static_forces[1] - single.static_force), 1e-9)
    ck.finite("both records", run.results[0].force, r.force, r.uplift)
    # each steady arm's uplift is charged to the pantograph within 30 m of it only
    sx = r.support_x
    for k, rr in enumerate(run.results):
        j = int(np.argmin(np.abs(sx - 120.0)))
        near = np.abs(rr.x - 120.0) <= 30.0
        ck.le(f"pantograph {k + 1}: uplift at 120 m is its own (mm, recomputed minus reported)",
              abs(1000 * float(np.max(rr.uplift[near, j])) - run.stats[k]["uplift_at_supports_mm"]["120"]), 1e-9)
    _contact_law(ck, run, "spacing 120 m")


HARD_CASES: tuple[HardCase, ...] = (
    HardCase("catenary_critical_speed", "catenary",
             "train speed approaching the contact wire's wave speed: no steady solution",
             "catenary speed regime at 50 %, 68 %, 73 %, 95 %, 100 %, 103 % of sqrt(T/rho)",
             "c = sqrt(T/rho) to rounding; nothing at 50 % and at 300 km/h; CriticalSpeedWarning naming EN 50119 "
             "at 320 km/h and 'Near-critical' at 95 %; ParameterError at c and at 450 km/h", _catenary_critical_speed),
    HardCase("catenary_trailing_near_wave_speed_limit", "catenary",
             "the trailing pantograph rides the leading one's wave just above 70 % of the wave speed",
             "two 2-mass pantographs 120 m apart at 310 km/h (6 spans, window 90-150 m)",
             "CriticalSpeedWarning; finite records; contact law exact every step; trailing sigma >= 1.2 x leading's "
             "and contact loss; excursions < 0.3 m", _trailing_near_warning_speed),
    HardCase("catenary_contact_loss_on_both", "catenary",
             "both pantographs leave and regain the wire (unilateral contact, active set every step)",
             "two 2-mass pantographs 120 m apart, F0 = 40 N, 300 km/h",
             ">= 1 loss event for each; loss % equals the share of samples with f <= 0; contact law exact",
             _loss_on_both),
    HardCase("catenary_slack_droppers_under_both", "catenary",
             "droppers go slack under both pantographs at once: one local problem with both contacts and the "
             "slack set", "two 2-mass pantographs 120 m apart, F0 = 70 N, 300 km/h, dropper diagnostics",
             "slack droppers near each pantograph; slack <=> elastic tension <= 0 at every step (1e-10 N); "
             "contact law exact (1e-13 relative)", _slack_under_both),
    HardCase("catenary_trailing_starts_on_steady_arm", "catenary",
             "a spacing of two spans: the trailing pantograph enters at the support while the leading one is on a "
             "steady arm, both pass steady arms together all the way",
             "two 2-mass pantographs 120 m apart, 250 km/h",
             "entry at x = 0 with the single pantograph's static force (1e-9 N); each steady arm's uplift charged "
             "to the pantograph within 30 m only; finite; contact law exact", _trailing_starts_on_a_steady_arm),
)


def random_input(scene: Scene, rng: np.random.Generator) -> dict:
    """A random train speed of 150-300 km/h over a 1 s stretch of line from the scene's start (statistics window:
    20-90 % of the stretch, also as the one window of a scene that sets `windows`). The pantograph keeps its engine
    path where it has a MuJoCo one; the 2-mass reference pantograph runs on the reference path (the catenary is FE
    code, only registry pantographs have other paths)."""
    v = rng.uniform(150.0, 300.0)
    length = v / 3.6 * 1.0  # 1 s of travel
    x0 = float(scene.build_params().x_start)
    out = {"input": {**scene.input, "speed": v},
           "params": {"x_end": x0 + length, "window_start": x0 + 0.2 * length, "window_end": x0 + 0.9 * length},
           "solver": {"duration": 1.0}}
    if (scene.params or {}).get("windows"):  # a scene's own windows (an overlap's) become the stretch's one
        out["params"]["windows"] = [[x0 + 0.2 * length, x0 + 0.9 * length]]
    if scene.effects["pantograph"] not in PANTOGRAPH_MODELS:
        out["solver"]["engine"] = "reference"
    return out


# ================================================================================================ work-precision
#: the FE method options the study compares: the point-load correction of the wires (`fe.PointCorrection`, the
#: default) and the plain Hermite wires
METHODS = {"corrected": True, "plain": False}


def passage_stats(scene: Scene, element_length: float, dt: float, speeds: tuple[float, ...],
                  correction: bool = True) -> dict[str, list]:
    """The statistics (`accuracy.STATS`) of every pantograph of the scene's passage (its `[train]`, on its path) at
    each speed with this element length, time step and FE method (`correction`: the wires' point-load correction):
    {"250": [{stat: value} per pantograph], ...}. The size guards grow with the resolution (the study asks for it);
    a run past the wave-resolution bound is kept."""
    from .accuracy import STATS
    from .analysis import scene_config
    from .config import CriticalSpeedWarning
    from .fe import assemble
    from .train import run_passage

    p = scene.build_params()
    sc = scene.replace(params={"element_length": element_length, "max_element_steps": max(
        p.max_element_steps, 1e13)}, solver={"timestep": dt, "max_steps": 1e9, "allow_inaccurate": True})
    out = {}
    for v in speeds:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CriticalSpeedWarning)
            cfg = scene_config(sc, sc.solver.engine, speed_kmh=v)
            run = run_passage(cfg, fe=assemble(cfg.params, point_correction=correction))
        out[f"{v:g}"] = [{k: float(st[k]) for k in STATS} for st in run.stats]
    return out


def _source_digest() -> str:
    """A digest of the catenary's code (every .py and .c file of the model): a cached reference is only reused by the
    code that computed it."""
    h = hashlib.sha256()
    root = Path(__file__).parent
    for f in sorted([*root.glob("*.py"), *root.glob("native/*.c"), *root.glob("native/*.h")]):
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


class CatenaryStudy(Study):
    """Work-precision study of a catenary scene: FE method (the wires' point-load correction, or the plain Hermite
    wires) x element length x time step, every pantograph of the scene's passage at both EN 50318 speeds (one
    setting's time is both passages'), against a reference of the plain Hermite wires at 0.0625 m / 5e-5 s whose own
    accuracy is shown by two checks, 0.125 m / 5e-5 s (the mesh) and 0.0625 m / 1e-4 s (the step). Errors are those
    of the eight statistics (`accuracy.py`)."""

    ELEMENTS = (1.0, 0.5, 0.25, 0.125)
    STEPS = (4e-4, 2e-4, 1e-4, 5e-5)
    SPEEDS = (250.0, 300.0)
    REFERENCE = ("plain", 0.0625, 5e-5)
    CHECKS = (("plain", 0.125, 5e-5), ("plain", 0.0625, 1e-4))
    #: where references are cached (None: computed every time); keyed by the scene, resolution, speeds and the code
    reference_cache: Path | None = None
    state_doc = ("max |statistic - ref| over the six force statistics (Fm, sigma, Fm +/- 3 sigma, actual max and "
                 "min of the 20 Hz filtered force), every pantograph and both speeds (N)")
    physics_doc = ("max |statistic - ref| / declared tolerance over the eight statistics (1 N on the forces, 0.5 mm "
                   "on the uplift, 0.05 % + 10 % of the loss on the contact loss), every pantograph and both speeds "
                   "(1 = the tolerance)")

    def __init__(self, scene: Scene, quick: bool = False):
        super().__init__(scene, quick)
        if quick:  # one speed, the corrected method at two coarse settings against the shipped resolution
            self.methods, self.elements, self.steps = ("corrected",), (2.0, 1.0), (8e-4, 4e-4)
            self.speeds = (float(scene.input["speed"]),)
            self.ref_res, self.checks = ("corrected", 0.5, 2e-4), (("corrected", 1.0, 4e-4),)
        else:
            self.methods, self.elements, self.steps = tuple(METHODS), self.ELEMENTS, self.STEPS
            self.speeds, self.ref_res, self.checks = self.SPEEDS, self.REFERENCE, self.CHECKS

    def _stats(self, method: str, h: float, dt: float) -> dict[str, list]:
        return passage_stats(self.scene, h, dt, self.speeds, METHODS[method])

    def settings(self) -> list[Setting]:
        """FE method x element length x time step, trapezoidal rule."""
        return [Setting("fe", f"trapezoidal, {m} Hermite", f"h {h:g} m, dt {dt:g} s",
                        lambda m=m, h=h, dt=dt: self._stats(m, h, dt))
                for m in self.methods for h in self.elements for dt in self.steps]

    def _cached(self, method: str, h: float, dt: float) -> dict[str, list]:
        if self.reference_cache is None:
            return self._stats(method, h, dt)
        key = hashlib.sha256(json.dumps([self.scene.to_dict(), method, h, dt, self.speeds, _source_digest()],
                                        sort_keys=True, default=str).encode()).hexdigest()[:20]
        f = Path(self.reference_cache) / f"catenary_reference_{key}.json"
        if f.exists():
            return json.loads(f.read_text())
        out = self._stats(method, h, dt)
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text(json.dumps(out))
        return out

    def reference(self):
        """The reference statistics and their checks (the class docstring)."""
        ref = self._cached(*self.ref_res)
        checks = []
        for m, h, dt in self.checks:
            chk = self._cached(m, h, dt)
            err, det = self.physics_error(chk, ref)
            checks.append({"check": f"{m} Hermite {h:g} m, {dt:g} s", "state_error": self.state_error(chk, ref),
                           "physics_error": err, "details": det})
        m, h, dt = self.ref_res
        return ref, {"reference": f"{m} Hermite wires, element length {h:g} m, dt {dt:g} s (speeds "
                                  f"{', '.join(f'{v:g}' for v in self.speeds)} km/h)",
                     "check": "; ".join(c["check"] for c in checks),
                     "check_state_error": max(c["state_error"] for c in checks),
                     "check_physics_error": max(c["physics_error"] for c in checks), "checks": checks,
                     "reference_values": ref}

    @staticmethod
    def _errors(res: dict[str, list], ref: dict[str, list]) -> dict[str, float]:
        """Per speed and pantograph: the largest force-statistic error (N), the uplift error (mm), the loss error
        (%)."""
        from .accuracy import STATS, UNITS

        out: dict[str, float] = {}
        for v, pans in ref.items():
            for k, (a, b) in enumerate(zip(res[v], pans, strict=True)):
                tag = f"{v}kmh_p{k + 1}"
                out[f"{tag}_force_N"] = max(abs(a[s] - b[s]) for s in STATS if UNITS[s] == "N")
                out[f"{tag}_uplift_mm"] = abs(a["uplift_mm"] - b["uplift_mm"])
                out[f"{tag}_loss_pct"] = abs(a["loss_pct"] - b["loss_pct"])
        return out

    def state_error(self, res: Any, ref: Any) -> float:
        """The class's `state_doc`."""
        return max(e for k, e in self._errors(res, ref).items() if k.endswith("_force_N"))

    def physics_error(self, res: Any, ref: Any) -> tuple[float, dict]:
        """The class's `physics_doc`, and the errors per speed and pantograph."""
        from .accuracy import LOSS_RTOL, TOL

        det = self._errors(res, ref)
        worst = 0.0
        for v, pans in ref.items():
            for k, b in enumerate(pans):
                tag = f"{v}kmh_p{k + 1}"
                worst = max(worst, det[f"{tag}_force_N"] / TOL["Fm"], det[f"{tag}_uplift_mm"] / TOL["uplift_mm"],
                            det[f"{tag}_loss_pct"] / (TOL["loss_pct"] + LOSS_RTOL * abs(b["loss_pct"])))
        return worst, det


def workprecision_study(scene: Scene, quick: bool = False) -> Study:
    """The `workprecision_study` hook: the catenary study of this scene."""
    return CatenaryStudy(scene, quick=quick)
