"""Pantographs that can run under the FE catenary: a small protocol and the EN 50318 2-mass reference pantograph.

The coupled integrator (`sim.py`) advances the catenary with the trapezoidal rule, so over one step the contact force
varies linearly from f_n to f_{n+1}. A pantograph only has to answer:

- `static(y_wire, k_wire)`: put yourself in static equilibrium pressing on a wire at height `y_wire` (m, relative to the
  undisturbed CW level) through a spring `k_wire` (the contact spring in series with the wire's static compliance);
  return the static contact force (N).
- `trial(t, dt, f0, f1)`: the contact-point height at t + dt (m, same datum) if the contact force pressing the head
  down (f >= 0 pushes the wire up) varied linearly from f0 to f1 over the step. The state is not changed; `commit()`
  accepts the last trial.
- `head()`, `signals()`: current contact-point height and named outputs.

`affine = True` tells the coupler that trial() is exactly affine in f1; such a pantograph may also offer
`affine_map(dt, f0) -> (P, g)` with head height P - g f1. A nonlinear pantograph is coupled by a secant iteration on
f1. Optional: `engine` (the name of the pantograph's engine path, for reports; default "reference"),
`engine_warnings() -> {name: count}` (warnings of its engine, reported with the run), `energy()` (J, for the energy
diagnostics), `aerodynamic(head, frame)`: the constant aerodynamic uplift (N, upward) on its head and on its frame
(`aerodynamics.py`), given before `static` (whose state then includes it) and acting in every trial, the one-port's
included; every pantograph the catenary knows has it (the model README, "Aerodynamic uplift", says where each applies
the two forces).

`native(dt) -> NativePort` (optional) gives the pantograph as a one-port in C (`engines/native/mbsuite.h`), which
the catenary's compiled loop steps without Python: `.port` the filled `mbs_port`, `.load()` / `.pull()` the committed
state into the port and back into the Python object, `.signals(rows)` the recorded output rows as `signals()`'s
names, `.failure(code)` the words for a failed trial. Its answers are those of `trial / commit` to rounding (a test
holds each against the Python twin). Every pantograph the catenary knows has one; without it a passage steps from
Python (`train._Secant`), which is also the test oracle of the compiled loop.

This protocol (`Pantograph`) and the factory that makes one (`UnderWire`: `ModelSpec.under_wire` of a registry model)
are the only contract. The scene's `pantograph` effect names a `PantographKind`: its engine paths, the `[pantograph]`
section it takes and its `UnderWire` factory. `reference2mass` is the catenary's own (`TwoMassPantograph`, its
parameters m1 ... F0 the catenary's); every other name is a pantograph model of the registry (`PANTOGRAPH_MODELS`),
found by `mbsuite.registry.get_model(name).under_wire` with the `[pantograph]` section of the scene (its own `effects`
and `params`, validated against that model's spec). `lumped` and `transfer` are the catenary's linear pantographs
(`components/linear_pantograph.py`: an n-stage lumped one and a state-space model of a receptance), their parameters
in the `[pantograph]` section's `params`; like the 2-mass one they are exactly affine per step and run in the compiled
loop as the linear one-port (the 2-stage lumped one is a `TwoMassPantograph` with its own numbers). The catenary
imports no pantograph model.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import partial
from typing import Any, Protocol, runtime_checkable

import numpy as np

from ...components import linear_pantograph as linear
from ...errors import SceneError
from ...limits import Limit, limit_of
from ...registry import ModelSpec, get_model

#: the catenary's own pantograph, the EN 50318 2-mass reference (parameters m1 ... F0 among the catenary's)
TWO_MASS = "reference2mass"
#: the `pantograph` effect's values that name a registry model (value -> model name)
PANTOGRAPH_MODELS = {"eppinger": "pantograph"}
#: the catenary's linear pantographs, their parameters in the `[pantograph]` section (`components/linear_pantograph.py`)
LINEAR = (linear.LUMPED, linear.TRANSFER)
#: every value of the `pantograph` effect
PANTOGRAPHS = (TWO_MASS, *PANTOGRAPH_MODELS, *LINEAR)
#: the values of the `pantograph` effect that read the scene's `[pantograph]` section
SECTION_PANTOGRAPHS = (*PANTOGRAPH_MODELS, *LINEAR)
#: keys of the scene's `[pantograph]` section
SECTION_KEYS = ("effects", "params")


@runtime_checkable
class Pantograph(Protocol):
    """What the catenary needs of a pantograph under the wire: heights from the undisturbed CW level (m),
    forces in N; over one step the contact force varies linearly f0 -> f1 (the trapezoidal rule's force history)."""
    name: str
    affine: bool

    def static(self, y_wire: float, k_wire: float) -> float:
        """Set the static state pressing on a wire at height y_wire through a spring k_wire; return the force."""

    def trial(self, t: float, dt: float, f0: float, f1: float) -> float:
        """Contact-point height at t + dt under the force history f0 -> f1; the committed state is unchanged."""

    def commit(self) -> None:
        """Accept the last trial as the new state."""

    def head(self) -> float:
        """Contact-point height (m) of the committed state."""

    def signals(self) -> dict[str, float]:
        """The committed state's output signals (SI units)."""


class UnderWire(Protocol):
    """The factory of a pantograph under the wire (`ModelSpec.under_wire` of a registry model): `params` and
    `effects` are the model's own (from the scene's `[pantograph]` section), `engine` one of its paths, `timestep` the
    catenary's step (s)."""

    def __call__(self, params: Mapping[str, Any], effects: Mapping[str, Any], engine: str,
                 timestep: float) -> Pantograph: ...


class TwoMassPantograph:
    """EN 50318 reference pantograph: head m1 on k1, c1 to the frame; frame m2 on k2, c2 to a fixed base; the static
    uplift F0 acts on the frame; k2 is referenced to the undisturbed CW level (catenary.md). The constant aerodynamic
    uplifts Fa_h on the head and Fa_f on the frame (`aerodynamic`; 0 until given) act on their masses:

        m1 x1'' = -k1 (x1 - x2) - c1 (x1' - x2') - f + Fa_h
        m2 x2'' =  k1 (x1 - x2) + c1 (x1' - x2') - k2 x2 - c2 x2' + F0 + Fa_f

    Integrated with the trapezoidal rule (the catenary's scheme), hence exactly affine in the contact force."""

    affine = True

    def __init__(self, m1: float, k1: float, c1: float, m2: float, k2: float, c2: float, F0: float,
                 name: str = "reference2mass"):
        self.name = name
        self.Mm = np.diag([m1, m2])
        self.Km = np.array([[k1, -k1], [-k1, k1 + k2]])
        self.Cm = np.array([[c1, -c1], [-c1, c1 + c2]])
        self.F0 = F0
        self.aero = (0.0, 0.0)  # the aerodynamic uplift (N, upward) on the head and on the frame
        self.x = np.zeros(2)
        self.v = np.zeros(2)
        self._dt = None
        self._pending = None

    def aerodynamic(self, head: float, frame: float) -> None:
        """The constant aerodynamic uplift (N, upward) on the head mass and on the frame mass (before `static`)."""
        self.aero = (float(head), float(frame))

    def _prepare(self, dt: float) -> None:
        h = dt / 2
        self._dt = dt
        Si = np.linalg.inv(self.Mm + h * self.Cm + h * h * self.Km)
        self._S = ((float(Si[0, 0]), float(Si[0, 1])), (float(Si[1, 0]), float(Si[1, 1])))
        self._m = (float(self.Mm[0, 0]), float(self.Mm[1, 1]))
        self._k = (float(self.Km[0, 0]), float(self.Km[0, 1]), float(self.Km[1, 1]))

    def _rhs(self, h: float, f0: float, f1: float) -> tuple[float, float]:
        (m1, m2), (k11, k12, k22) = self._m, self._k
        x1, x2 = float(self.x[0]), float(self.x[1])
        v1, v2 = float(self.v[0]), float(self.v[1])
        fa_h, fa_f = self.aero
        return (m1 * v1 - h * (k11 * x1 + k12 * x2) - h * (f0 + f1) / 2 + h * fa_h,
                m2 * v2 - h * (k12 * x1 + k22 * x2) + h * (self.F0 + fa_f))

    def static(self, y_wire: float, k_wire: float) -> float:
        """Static state against a wire at y_wire through k_wire: K x = [-f + Fa_h, F0 + Fa_f], f = k_wire (x1 -
        y_wire)."""
        fa_h, fa_f = self.aero
        A = self.Km + np.array([[k_wire, 0.0], [0.0, 0.0]])
        self.x = np.linalg.solve(A, np.array([k_wire * y_wire + fa_h, self.F0 + fa_f]))
        self.v = np.zeros(2)
        return float(k_wire * (self.x[0] - y_wire))

    def affine_map(self, dt: float, f0: float) -> tuple[float, float]:
        """(P, g): head height at t + dt is P - g f1 (exact, the scheme is linear)."""
        if dt != self._dt:
            self._prepare(dt)
        h = dt / 2
        r1, r2 = self._rhs(h, f0, 0.0)
        S = self._S
        return float(self.x[0]) + 2 * h * (S[0][0] * r1 + S[0][1] * r2), h * h * S[0][0]

    def trial(self, t: float, dt: float, f0: float, f1: float) -> float:
        """Head height at t + dt by the trapezoidal rule under f0 -> f1 (pending until `commit`)."""
        if dt != self._dt:
            self._prepare(dt)
        h = dt / 2
        r1, r2 = self._rhs(h, f0, f1)
        S = self._S
        vb1 = S[0][0] * r1 + S[0][1] * r2
        vb2 = S[1][0] * r1 + S[1][1] * r2
        x_new = np.array([self.x[0] + 2 * h * vb1, self.x[1] + 2 * h * vb2])
        self._pending = (x_new, np.array([2 * vb1 - self.v[0], 2 * vb2 - self.v[1]]))
        return float(x_new[0])

    def commit(self) -> None:
        """Accept the last trial."""
        self.x, self.v = self._pending

    def head(self) -> float:
        """Head displacement x1 (m) of the committed state."""
        return float(self.x[0])

    def signals(self) -> dict[str, float]:
        """Head and frame displacements (m) of the committed state."""
        return {"head_displacement": float(self.x[0]), "frame_displacement": float(self.x[1])}

    def native(self, dt: float):
        """This pantograph as the compiled loop's one-port at time step `dt` (`native_core.TwoMassPort`)."""
        from .native_core import TwoMassPort

        return TwoMassPort(self, dt)

    def pack(self, out: np.ndarray, dt: float) -> None:
        """The state and step constants into the native core's one-port (x1 x2 v1 v2, S^-1 row-major, m1 m2,
        k11 k12 k22, the frame's constant uplift F0 + Fa_f, the head's Fa_h): `native/catenary.c` advances this
        pantograph by the same rule."""
        if dt != self._dt:
            self._prepare(dt)
        (m1, m2), (k11, k12, k22), S = self._m, self._k, self._S
        fa_h, fa_f = self.aero
        out[:15] = (self.x[0], self.x[1], self.v[0], self.v[1], S[0][0], S[0][1], S[1][0], S[1][1], m1, m2, k11,
                    k12, k22, self.F0 + fa_f, fa_h)

    def unpack(self, src: np.ndarray) -> None:
        """The state back from the native core (`pack`)."""
        self.x = np.array([src[0], src[1]], dtype=float)
        self.v = np.array([src[2], src[3]], dtype=float)

    def energy(self) -> float:
        """Kinetic + spring energy (J) minus the potential of F0 and of the aerodynamic uplift."""
        fa_h, fa_f = self.aero
        return float(0.5 * self.v @ self.Mm @ self.v + 0.5 * self.x @ self.Km @ self.x - (self.F0 + fa_f) * self.x[1]
                     - fa_h * self.x[0])


# --- the kinds of pantograph -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PantographKind:
    """A value of the scene's `pantograph` effect: the engine paths its pantograph has, its factory, and the registry
    model whose declaration validates the `[pantograph]` section (None: the catenary's own); `check` validates the
    section of a catenary pantograph that takes one (the linear ones)."""

    name: str
    engines: tuple[str, ...]
    make: UnderWire
    spec: ModelSpec | None = None
    check: Callable[[Any], dict[str, dict[str, Any]]] | None = None

    def section(self, value: Any) -> dict[str, dict[str, Any]]:
        """The `[pantograph]` section validated for this pantograph (SceneError naming the bad key or value)."""
        if self.check is not None:
            return self.check(value)
        if self.spec is None:
            value = value or {}
            if value.get("effects") or value.get("params"):
                raise SceneError(f"the {self.name} pantograph takes its parameters from [params] (m1, k1, c1, m2, "
                                 "k2, c2, F0) and has no effects: remove the [pantograph] section")
            return {"effects": {}, "params": {}}
        return _check_section(value, self.name, self.spec)


def _two_mass(p, params: Mapping[str, Any], effects: Mapping[str, Any], engine: str,
              timestep: float) -> TwoMassPantograph:
    """`UnderWire` of the 2-mass pantograph: its parameters are the catenary's `p` (m1 ... F0)."""
    return TwoMassPantograph(p.m1, p.k1, p.c1, p.m2, p.k2, p.c2, p.F0)


def _linear_section(name: str, value: Any) -> dict[str, dict[str, Any]]:
    """The `[pantograph]` section of the linear pantograph `name`, validated (its parameters built once)."""
    p = linear.params_of(name, value if value else None)
    return {"effects": {}, "params": p.section()}  # as checked: numpy users' numbers as the numbers they hold


def _linear(name: str, params: Mapping[str, Any], effects: Mapping[str, Any], engine: str,
            timestep: float) -> linear.LinearPantograph | TwoMassPantograph:
    """`UnderWire` of a linear pantograph: its parameters from the `[pantograph]` section's `params`. A 2-stage
    lumped pantograph is the 2-mass pantograph's model and scheme with other numbers: it is made one
    (`TwoMassPantograph`, stepped in the compiled loop)."""
    p = linear.params_of(name, {"params": params})
    if isinstance(p, linear.LumpedParams) and p.stages == 2:
        return TwoMassPantograph(p.m[0], p.k[0], p.c[0], p.m[1], p.k[1], p.c[1], p.F0, name=name)
    return linear.make(name, {"params": params})


def kind(name: str, p) -> PantographKind:
    """The kind of pantograph the `pantograph` effect's value `name` names, under a catenary of parameters `p`."""
    if name == TWO_MASS:
        return PantographKind(TWO_MASS, ("reference",), partial(_two_mass, p))
    if name in LINEAR:
        return PantographKind(name, ("reference",), partial(_linear, name), check=partial(_linear_section, name))
    if name not in PANTOGRAPH_MODELS:
        raise SceneError(f"unknown pantograph {name!r}; valid: {list(PANTOGRAPHS)}")
    spec = _model_spec(name)
    return PantographKind(name, spec.engines, spec.under_wire, spec)


def _model_spec(name: str) -> ModelSpec:
    spec = get_model(PANTOGRAPH_MODELS[name])
    if spec.under_wire is None:
        raise SceneError(f"model {spec.name!r} (pantograph {name!r}) does not declare how it runs under the wire "
                         "(ModelSpec.under_wire)")
    return spec


def _check_section(value: Any, name: str, spec: ModelSpec) -> dict[str, dict[str, Any]]:
    """The `[pantograph]` section validated against the spec of the registry model `spec` (pantograph `name`)."""
    if not isinstance(value, Mapping):
        raise SceneError(f"[pantograph] must be a table with keys {list(SECTION_KEYS)}, got {value!r}")
    bad = sorted(set(value) - set(SECTION_KEYS))
    if bad:
        raise SceneError(f"unknown key(s) {bad} in [pantograph]; valid keys: {list(SECTION_KEYS)}")
    effects, params = value.get("effects") or {}, value.get("params") or {}
    for what, v in (("effects", effects), ("params", params)):
        if not isinstance(v, Mapping):
            raise SceneError(f"[pantograph] {what} must be a table, got {v!r}")
    bad = sorted(set(effects) - set(spec.effects))
    if bad:
        raise SceneError(f"unknown effect(s) {bad} of the {name!r} pantograph (model '{spec.name}') in [pantograph]; "
                         f"valid effects: {sorted(spec.effects)}")
    for effect, v in effects.items():
        spec.effects[effect].check(effect, v)
    valid = spec.param_names()
    bad = sorted(set(params) - set(valid))
    if bad:
        raise SceneError(f"unknown parameter(s) {bad} of the {name!r} pantograph (model '{spec.name}') in "
                         f"[pantograph]; valid parameters: {valid}")
    # each value against its field's declared Limit (numpy scalars taken as the numbers they hold), as checked
    params = {k: (limit_of(spec.params_cls, k) or Limit()).check(k, v, SceneError, f" in [pantograph] params (the "
                                                                    f"{name!r} pantograph)") for k, v in params.items()}
    spec.params_cls(**params)  # the model's parameter dataclass validates across them
    return {"effects": dict(effects), "params": params}


def validate_section(value: Any) -> dict[str, dict[str, Any]]:
    """Validator of the scene's `[pantograph]` section (`ModelSpec.sections`): `effects` and `params` of a registry
    pantograph, checked against that model's spec (unknown keys are errors listing the valid ones). The section does
    not see the scene's `pantograph` effect: it must be valid for one of the registry pantographs, and `build` checks
    it again against the one the scene names. A section whose `params` hold the keys of a linear pantograph
    (`m, k, c, F0` or `A, B, C, F0`) is validated as that one's."""
    params = value.get("params") if isinstance(value, Mapping) else None
    if isinstance(params, Mapping):
        for name in LINEAR:
            if set(params) & (set(linear.KINDS[name][0]) - {"F0"}):
                return _linear_section(name, value)
    first = None
    for name in PANTOGRAPH_MODELS:
        try:
            return _check_section(value, name, _model_spec(name))
        except SceneError as exc:
            first = first or exc
    raise first if first is not None else SceneError("no registry pantograph takes a [pantograph] section")


validate_section.schemas = {"pantograph_lumped": linear.LUMPED_SECTION,
                            "pantograph_transfer": linear.TRANSFER_SECTION}


def build(name: str, p, engine: str = "reference", dt: float = 1e-4, section: Mapping[str, Any] | None = None,
          contact: str | None = None) -> Pantograph:
    """The pantograph named by the scene's `pantograph` effect, on its engine path `engine`, for a catenary with
    parameters `p` and time step `dt`. `section`: the scene's `[pantograph]` section (registry pantographs only);
    `contact`: the catenary's contact law, which a `contact` effect in the section must not contradict (the head-wire
    contact is the catenary's)."""
    k = kind(name, p)
    if engine not in k.engines:
        paths = " and ".join(k.engines)
        raise SceneError(f"the {name} pantograph has only the {paths} path{'s' if len(k.engines) > 1 else ''}, not "
                         f"{engine!r}: use solver.engine = {k.engines[0]!r} (the catenary itself is always the FE "
                         "code)")
    sec = k.section(dict(section or {}))
    effects = dict(sec["effects"])
    if contact is not None and k.spec is not None and "contact" in k.spec.effects:
        if effects.get("contact", contact) != contact:
            raise SceneError(f"[pantograph] effects.contact = {effects['contact']!r} contradicts the catenary's "
                             f"contact = {contact!r}: the head-wire contact is the catenary's effect")
        effects["contact"] = contact
    return k.make(sec["params"], effects, engine, dt)


def build_train(pantographs: list, p, engine: str, dt: float, section: Mapping[str, Any] | None = None,
                contact: str | None = None) -> list[Pantograph]:
    """The pantographs of a passage, leading first: names (`build`) or objects of the protocol (taken as they are).
    A named pantograph runs on `engine`; on a train that also carries one with that path, a pantograph without it
    (the 2-mass one) runs on its only path. The `[pantograph]` section is the sectioned pantograph's (the Eppinger
    or a linear one; at most one such kind per train); the 2-mass ones of a mixed train take theirs from [params]."""
    carried = any(engine in kind(n, p).engines for n in pantographs if isinstance(n, str))
    takers = sorted({n for n in pantographs if isinstance(n, str) and n in SECTION_PANTOGRAPHS})
    if len(takers) > 1 and section:
        raise SceneError(f"the [pantograph] section describes one kind of pantograph, but the train carries "
                         f"{takers}: run trains of one kind of sectioned pantograph")
    out = []
    for item in pantographs:
        if not isinstance(item, str):
            out.append(item)
            continue
        engines = kind(item, p).engines
        # the section is the sectioned pantograph's; a train without one hands it to every member (which refuse it)
        sec = section if item in SECTION_PANTOGRAPHS or not takers else None
        out.append(build(item, p, engine if engine in engines or not carried else engines[0], dt, sec, contact))
    return out
