"""The Eppinger pantograph's hand-derived ODE as a C one-port (`native/ode_port.c`, the `mbs_port` protocol of
`mbsuite.engines.native.oneport`): the C twin of `EppingerReference`'s step (`under_wire.py`; Eppinger 1984, "An
experimental and analytical study of pantograph dynamics"), so that a compiled host (the FE catenary's loop) steps it
without Python.

A trial is one classical RK4 step of `PantographODE.rhs_with_force` (`equations.py`, followed statement by statement)
with the contact force varying linearly f0 -> f1 over the step; it answers the contact height less y_op. The two agree
to rounding (the 3x3 solve is Gaussian elimination in C, LAPACK in numpy): `tests/pantograph/test_ode_port.py`.
`OdePort(ref)` copies the parameters, effects, aerodynamic uplift (`PantographODE.aero`) and committed state of an
`EppingerReference`; outputs per recorded row: head_displacement, theta_1, theta_2, theta_h
(`EppingerReference.signals`).
"""

from __future__ import annotations

import ctypes
from typing import Any

import numpy as np

from ...engines import native
from ...engines.native.oneport import Port
from ...errors import SceneError

#: an `under_wire.EppingerReference` (its params, cfg, ode and state x; not imported: it imports this module)
Reference = Any


_P = ctypes.c_void_p
_I = ctypes.c_int
_D = ctypes.c_double
ABI = 2
#: largest state (MBS_PANTO_ODE_NX): 3 angles, 3 rates, the cylinder state
NX = 7
#: outputs per row, in order (the keys of `EppingerReference.signals`)
OUTPUTS = ("head_displacement", "theta_1", "theta_2", "theta_h")
#: `PantographParams` fields copied into the struct (same names)
PARAMS = ("l1", "l2", "lh", "m1", "m2", "mh", "I1", "I2", "Ih", "d1", "d2", "dh", "kh", "ke", "be",
          "xf", "yf", "le", "theta_e0", "lb", "alpha", "Ap", "V0", "Pg", "Pa", "Ps", "R_gas", "T", "gamma", "kc",
          "bc", "r_laminar", "omega_s", "y_op")
CYLINDERS = ("constant", "linear", "nonlinear")
#: the elbow's second-derivative step (the default of `Elbow.second_derivative`)
H_SECOND = 1e-5


class _State(ctypes.Structure):
    """`mbs_panto_ode` (`native/ode_port.c`)."""

    _fields_ = [
        ("nq", _I), ("n", _I), ("has_P", _I), ("cylinder", _I), ("exact", _I), ("smooth", _I),
        *((name, _D) for name in PARAMS),
        ("g", _D), ("b", _D * 3), ("c", _D * 3),
        ("K12", _D), ("K13", _D), ("K23", _D), ("r_crit", _D), ("gas", _D), ("phi1_0", _D), ("lfb0", _D), ("h2", _D),
        ("aero_head", _D), ("aero_frame", _D),
        ("m_lam", _D), ("dp_lam", _D),
        ("x", _D * NX), ("pending", _D * NX), ("has_pending", _I),
        ("fail_code", _I), ("fail_stage", _I), ("fail_index", _I),
        ("fail_value", _D), ("fail_aux", _D), ("fail_theta1", _D), ("fail_t", _D),
        ("k", _D * NX * 4), ("xs", _D * NX), ("xn", _D * NX),
    ]


#: `native/ode_port.c` as Python binds it (ABI and the `mbs_panto_ode` layout checked)
DECLARATION = native.Declaration(
    "models/pantograph/native/ode_port.c", "mbs_panto_ode_abi", ABI,
    functions=(
        native.CFunction("mbs_panto_ode_port", None, (_P, _P)),
        native.CFunction("mbs_panto_ode_rhs", _I, (_P, _P, _D, _P)),
        native.CFunction("mbs_panto_ode_call_trial", _I, (_P, _D, _D, _D, _D, _P)),
        native.CFunction("mbs_panto_ode_call_commit", None, (_P,)),
        native.CFunction("mbs_panto_ode_call_outputs", None, (_P, _P)),
    ),
    structs=(native.CStruct(_State, "mbs_panto_ode_size"),),
)

#: failure codes of `ode_port.c` (PO_FAIL_*)
FAIL_INPUT, FAIL_STATE, FAIL_RATE, FAIL_NEW, FAIL_ELBOW, FAIL_VOLUME, FAIL_PRESSURE, FAIL_SINGULAR = range(1, 9)
_INPUTS = ("t", "dt", "f0", "f1")


def library() -> native.Binding:
    """The one-port's entry points on the native library (loaded once; ABI and struct layout checked)."""
    return native.bind(DECLARATION)


class OdePort:
    """The C one-port of `ref` (an `EppingerReference`): its parameters, effects and committed state `ref.x` copied
    into the C state. `port` is the filled `oneport.Port` (its `self` points into this object, kept alive by it)."""

    def __init__(self, ref: Reference):
        ode = ref.ode
        p = ode.p
        cfg = ode.cfg
        if cfg.coulomb not in (False, "smooth"):
            raise SceneError("the pantograph's C one-port integrates Coulomb friction as the smooth law or not at "
                             f"all; coulomb = {cfg.coulomb!r} (event-exact stick/slip) has no fixed-step form")
        if cfg.cylinder not in CYLINDERS:
            raise SceneError(f"the pantograph's C one-port has no cylinder {cfg.cylinder!r}; valid: {list(CYLINDERS)}")
        self.lib = library()
        self.nq, self.n = ode.nq, ode.n
        s = self._s = _State()
        s.nq, s.n, s.has_P = ode.nq, ode.n, int(ode.has_P)
        s.cylinder = CYLINDERS.index(cfg.cylinder)
        s.exact = int(ode.elbow.exact)
        s.smooth = int(cfg.coulomb == "smooth")
        for name in PARAMS:
            setattr(s, name, float(getattr(p, name)))
        s.y_op = float(ref.y_op)
        s.g = float(ode.g)
        s.b[:] = [float(v) for v in ode.b]
        s.c[:] = [float(v) for v in ode.c]
        s.K12, s.K13, s.K23 = float(ode.K12), float(ode.K13), float(ode.K23)
        s.r_crit, s.gas = float(ode.r_crit), float(ode.gas)
        s.phi1_0, s.lfb0 = float(ode.elbow.phi1_0), float(ode.elbow.lfb0)
        s.h2 = H_SECOND
        s.aero_head, s.aero_frame = ode.aero
        self.port = Port()
        self.lib.mbs_panto_ode_port(ctypes.byref(self.port), ctypes.byref(s))
        self.push(ref)

    def push(self, ref: Reference) -> None:
        """Take `ref.x` as the committed state (e.g. after `ref.static`)."""
        x = np.asarray(ref.x, dtype=float)
        if x.shape != (self.n,):
            raise ValueError(f"state of shape {x.shape}, the one-port's is ({self.n},)")
        self._s.x[: self.n] = x.tolist()
        self._s.has_pending = 0

    def state(self) -> np.ndarray:
        """The committed state x (a copy)."""
        return np.array(self._s.x[: self.n])

    def pull(self, ref: Reference) -> None:
        """Write the committed state back into `ref.x`."""
        ref.x = self.state()

    def signals(self, rows: np.ndarray) -> dict[str, np.ndarray]:
        """The signals of recorded output rows (shape (n, 4)), keyed like `Reference.signals`."""
        rows = np.asarray(rows, dtype=float).reshape(-1, len(OUTPUTS))
        return {name: rows[:, i].copy() for i, name in enumerate(OUTPUTS)}

    # ------------------------------------------------------------------------------------------- through the port
    def trial(self, t: float, dt: float, f0: float, f1: float) -> tuple[int, float]:
        """(code, y) of one trial through the port's function pointer (tests; a host calls the pointer itself)."""
        y = ctypes.c_double(np.nan)
        code = self.lib.mbs_panto_ode_call_trial(ctypes.byref(self.port), t, dt, f0, f1, ctypes.byref(y))
        return int(code), y.value

    def commit(self) -> None:
        """Accept the last trial through the port's function pointer."""
        self.lib.mbs_panto_ode_call_commit(ctypes.byref(self.port))

    def outputs(self) -> np.ndarray:
        """The committed state's outputs through the port's function pointer (a row of `OUTPUTS`)."""
        out = np.empty(len(OUTPUTS))
        self.lib.mbs_panto_ode_call_outputs(ctypes.byref(self.port), out.ctypes.data)
        return out

    def pending(self) -> np.ndarray | None:
        """The last successful trial's state (None after a failed trial or before any)."""
        return np.array(self._s.pending[: self.n]) if self._s.has_pending else None

    def rhs(self, x: np.ndarray, f_up: float) -> tuple[int, np.ndarray]:
        """(code, x') of `PantographODE.rhs_with_force` in C (tests)."""
        xa = np.ascontiguousarray(x, dtype=float)
        dx = np.full(self.n, np.nan)
        code = self.lib.mbs_panto_ode_rhs(ctypes.byref(self._s), xa.ctypes.data, float(f_up), dx.ctypes.data)
        return int(code), dx

    # ------------------------------------------------------------------------------------------- failures
    def failure(self, code: int) -> str:
        """A message naming what made a trial fail with `code` (read from the C state's failure record)."""
        s = self._s
        stage = {1: "RK4 stage 1", 2: "RK4 stage 2", 3: "RK4 stage 3", 4: "RK4 stage 4",
                 5: "the step's new state"}.get(s.fail_stage, "")
        where = f" ({stage} of the step from t = {s.fail_t:.6g} s)" if stage else f" (step from t = {s.fail_t:.6g} s)"
        head = "Eppinger pantograph (C one-port): "
        if code == FAIL_INPUT:
            name = _INPUTS[s.fail_index] if 0 <= s.fail_index < 4 else "?"
            what = "force" if name in ("f0", "f1") else "time" if name == "t" else "time step"
            return f"{head}non-finite {what} {name} = {s.fail_value!r} given to a trial"
        if code == FAIL_STATE:
            return f"{head}non-finite committed state x[{s.fail_index}] = {s.fail_value!r}"
        if code == FAIL_RATE:
            return (f"{head}non-finite state rate x'[{s.fail_index}] = {s.fail_value!r} at theta_1 = "
                    f"{s.fail_theta1:.6g} rad{where}: the step diverged (reduce the time step)")
        if code == FAIL_NEW:
            what = "contact height" if s.fail_index < 0 else f"state x[{s.fail_index}]"
            return f"{head}non-finite new {what} = {s.fail_value!r}{where}: the step diverged (reduce the time step)"
        if code == FAIL_ELBOW:
            return (f"{head}elbow chain geometry has no tangent line at theta_1 = {s.fail_theta1:.6g} rad "
                    f"(B^2-4AC = {s.fail_value:.3g}, A = {s.fail_aux:.3g}): the chain base point lies inside the "
                    f"pinion circle or the chain is vertical{where}")
        if code == FAIL_VOLUME:
            return (f"{head}nonlinear cylinder volume became non-positive (V = {s.fail_value:.3g} m^3) at theta_1 = "
                    f"{s.fail_theta1:.4g}{where}")
        if code == FAIL_PRESSURE:
            return f"{head}nonlinear cylinder: non-positive absolute pressure P = {s.fail_value:.6g} Pa{where}"
        if code == FAIL_SINGULAR:
            return (f"{head}singular mass matrix (zero pivot in column {s.fail_index}) at theta_1 = "
                    f"{s.fail_theta1:.6g} rad{where}")
        return f"{head}unknown failure code {code}"
