"""One-ports in C (`mbsuite.h`, `oneport.c`): the ctypes mirror of `mbs_port`, the protocol by which a compiled host
loop (the FE catenary's) steps a body that it couples through one force, and the MuJoCo one-port (`MujocoPort`), a
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


#: `oneport.c` as Python binds it (the layouts of `mbs_port` and `mbs_mj_port` checked)
DECLARATION = Declaration(
    "engines/native/oneport.c", "mbs_abi_version", ABI_VERSION,
    functions=(CFunction("mbs_mj_port_init", None, (_P, _P)),),
    structs=(CStruct(Port, "mbs_port_size"), CStruct(_MjPort, "mbs_mj_port_size")),
)


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

    def state(self) -> np.ndarray:
        """The committed integration state (the buffers swap at every commit)."""
        addr = self._s.committed
        return self.committed if addr == self.committed.ctypes.data else self.pending
