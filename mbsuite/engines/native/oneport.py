"""One-ports in C (`mbsuite.h`, `oneport.c`): the ctypes mirror of `mbs_port`, the protocol by which a compiled host
loop (a model's) steps a body that it couples through one force, and the MuJoCo one-port (`MujocoPort`), a
MuJoCo model driven by one force actuator.

A Python object that a compiled host can step offers `port(dt) -> Port` (a filled `mbs_port`, kept alive by the
object) with the same answers as its `trial / commit` in Python; the host passes the port's address to C.
"""

from __future__ import annotations

import ctypes

import mujoco
import numpy as np

from . import ABI_VERSION, CFunction, CStruct, Declaration, bind

_P = ctypes.c_void_p
_I = ctypes.c_int
_D = ctypes.c_double
#: outputs a port may record per row (MBS_PORT_MAXOUT)
MAXOUT = 16


class Port(ctypes.Structure):
    """`mbs_port`: the implementation's state, whether it is affine, its outputs per row and its four functions."""

    _fields_ = [("self", _P), ("affine", _I), ("nout", _I), ("map", _P), ("trial", _P), ("commit", _P),
                ("outputs", _P)]


class _MjPort(ctypes.Structure):
    _fields_ = [("m", _P), ("d", _P), ("job", _P), ("actuator", _I), ("site", _I), ("origin", _I), ("spec", _I),
                ("sign", _D), ("offset", _D), ("committed", _P), ("pending", _P), ("holds", _I), ("nq_out", _I)]


class _LinPort(ctypes.Structure):
    _fields_ = [("n", _I), ("nout", _I), ("Phi", _P), ("G0", _P), ("Gf", _P), ("c", _P), ("cPhi", _P), ("Cout", _P),
                ("cG0", _D), ("cGf", _D), ("x", _P), ("pending", _P)]


#: `oneport.c` as Python binds it (the layouts of `mbs_port`, `mbs_mj_port` and `mbs_lin_port` checked)
DECLARATION = Declaration(
    "engines/native/oneport.c", "mbs_abi_version", ABI_VERSION,
    functions=(CFunction("mbs_mj_port_init", None, (_P, _P)), CFunction("mbs_lin_port_init", None, (_P, _P))),
    structs=(CStruct(Port, "mbs_port_size"), CStruct(_MjPort, "mbs_mj_port_size"),
             CStruct(_LinPort, "mbs_lin_port_size")),
)


class LinearPort:
    """The linear one-port: x_{n+1} = `Phi` x_n + `G0` - `Gf` (f0 + f1), displacement `c` . x, outputs `Cout` x;
    `x` the committed state (copied in). The head map's row `cPhi` = c Phi and scalars `cG0` = c . G0, `cGf` =
    c . Gf are the caller's (so that both twins use the same numbers)."""

    def __init__(self, Phi: np.ndarray, G0: np.ndarray, Gf: np.ndarray, c: np.ndarray, Cout: np.ndarray,
                 x: np.ndarray, cPhi: np.ndarray, cG0: float, cGf: float):
        lib = bind(DECLARATION)
        n = int(np.size(x))
        arr = {"Phi": np.ascontiguousarray(Phi, dtype=float).reshape(n, n),
               "G0": np.ascontiguousarray(G0, dtype=float).reshape(n),
               "Gf": np.ascontiguousarray(Gf, dtype=float).reshape(n),
               "c": np.ascontiguousarray(c, dtype=float).reshape(n),
               "Cout": np.ascontiguousarray(np.atleast_2d(Cout), dtype=float)}
        if arr["Cout"].shape[1] != n or not 1 <= arr["Cout"].shape[0] <= MAXOUT:
            raise ValueError(f"Cout must have 1 .. {MAXOUT} rows of {n} columns, got {arr['Cout'].shape}")
        arr["cPhi"] = np.ascontiguousarray(cPhi, dtype=float).reshape(n)
        self._bufs = [np.ascontiguousarray(x, dtype=float).copy(), np.zeros(n)]
        self._arr = arr
        s = self._s = _LinPort()
        s.n, s.nout = n, arr["Cout"].shape[0]
        for name in ("Phi", "G0", "Gf", "c", "cPhi", "Cout"):
            setattr(s, name, arr[name].ctypes.data)
        s.cG0, s.cGf = float(cG0), float(cGf)
        s.x, s.pending = self._bufs[0].ctypes.data, self._bufs[1].ctypes.data
        self.port = Port()
        lib.mbs_lin_port_init(ctypes.byref(self.port), ctypes.byref(s))

    def _committed(self) -> np.ndarray:
        return self._bufs[0] if self._s.x == self._bufs[0].ctypes.data else self._bufs[1]

    def state(self) -> np.ndarray:
        """The committed state (a copy; the buffers swap at every commit)."""
        return self._committed().copy()

    def set_state(self, x: np.ndarray) -> None:
        """Set the committed state."""
        self._committed()[:] = x


class MujocoPort:
    """The MuJoCo one-port of (`model`, `data`): force actuator `actuator` (gain 1, bias 0), displacement the height
    of site `site` above site `origin` less `offset`, ctrl = `sign` x the step's mean force; `job` is the core's
    `mbs_job` (a `core.Stepper`'s, set for one unrecorded step with every check). Outputs: the height, then the first
    `nq_out` entries of qpos. `state` is the committed integration state (mj_getState), shared with the caller."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, job: ctypes.Structure, actuator: int, site: int,
                 origin: int, sign: float, offset: float, state: np.ndarray, nq_out: int):
        lib = bind(DECLARATION)
        if not 0 <= nq_out <= min(model.nq, MAXOUT - 1):
            raise ValueError(f"nq_out must be in 0 .. {min(model.nq, MAXOUT - 1)}, got {nq_out}")
        spec = mujoco.mjtState.mjSTATE_INTEGRATION
        self.model, self.data, self.job = model, data, job
        self.committed = np.ascontiguousarray(state, dtype=float).copy()
        self.pending = np.empty_like(self.committed)
        s = self._s = _MjPort()
        s.m, s.d, s.job = model._address, data._address, ctypes.addressof(job)
        s.actuator, s.site, s.origin, s.spec = int(actuator), int(site), int(origin), int(spec)
        s.sign, s.offset = float(sign), float(offset)
        s.committed, s.pending, s.nq_out = self.committed.ctypes.data, self.pending.ctypes.data, int(nq_out)
        self.port = Port()
        lib.mbs_mj_port_init(ctypes.byref(self.port), ctypes.byref(s))

    def _committed(self) -> np.ndarray:
        return self.committed if self._s.committed == self.committed.ctypes.data else self.pending

    def state(self) -> np.ndarray:
        """The committed integration state (a copy; the buffers swap at every commit)."""
        return self._committed().copy()

    def set_state(self, state: np.ndarray) -> None:
        """Set the committed integration state (the data is restored from it at the next trial)."""
        self._committed()[:] = state
        self._s.holds = 0
