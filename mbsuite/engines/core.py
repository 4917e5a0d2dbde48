"""The one step-and-record loop of every MuJoCo path in mbsuite.

A `Stepper` holds a compiled model, its data and what to record; `Stepper.run(nstep, ...)` hands the whole loop to
the native core (`native/core.c`): per step, the input row goes into `d.ctrl`, MuJoCo's forward dynamics runs, an
optional native stepper (a model's compiled state machine) acts on the forward, the declared channels are recorded
every `every` steps into one preallocated array, the state is integrated with the model's own integrator, and the
run is checked: MuJoCo's bad-acceleration warning and the faults of mbsuite's plugins every step, finite
qpos/qvel/act every `check_every` steps and at every recorded row, and every recorded value against the plausibility
bounds its channel declares. MuJoCo's own warnings of a broken state (bad qpos, qvel, qacc or ctrl, full arrays) are
failures too: MuJoCo would reset or zero the offending values and go on. The trajectory is bitwise that of `mj_step`
(the core calls what `mj_step` calls).

Inputs:
- an array: `ctrl` of shape (nstep, len(ctrl_idx)), row k written into `d.ctrl[ctrl_idx]` before step k;
- a callable: `between(k, data)` called in Python before step k for every k that is a multiple of `period` (a
  discrete controller at its sample rate; `period=1` makes any Python input possible, at Python's cost);
- native code: a `NativeHook`, a compiled stepper called by the core at every step (no Python at all).

The core holds no global state and releases the GIL while it runs, so steppers in different threads run in
parallel and never mix (`map_threads`). A failure raises `SolverError` naming the run, the time and the cause.
"""

from __future__ import annotations

import ctypes
import math
import os
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

from ..errors import SolverError
from . import native
from .mujoco_engine import active_callbacks, warnings_raised

#: recordable MjData quantities (order mirrors the MBS_F_* enum of native/mbsuite.h)
FIELDS = ("time", "qpos", "qvel", "act", "ctrl", "actuator_force", "actuator_length", "actuator_velocity",
          "sensordata", "qfrc_passive", "qfrc_actuator", "energy", "eq_pos", "eq_force", "hook", "site_xpos")
_FIELD_ID = {f: i for i, f in enumerate(FIELDS)}
_STATUS = {0: "ok", 1: "non-finite state", 2: "MuJoCo warning", 3: "plugin fault", 4: "implausible value",
           5: "native stepper error", 6: "invalid arguments"}
DEFAULT_HINT = "reduce solver.timestep"


@dataclass(frozen=True)
class Channel:
    """One recorded quantity: `size` values of MjData `field` from index `start` (for `eq_pos`/`eq_force`: the
    constraint rows of equality `start`; for `site_xpos`: 3 values from 3*site). Every recorded value must lie in
    [lo, hi] (a plausibility bound; NaN never does), else the run stops with an error naming the channel."""

    name: str
    field: str
    start: int = 0
    size: int = 1
    lo: float = -math.inf
    hi: float = math.inf

    def __post_init__(self) -> None:
        if self.field not in _FIELD_ID:
            raise ValueError(f"unknown channel field {self.field!r}; valid: {list(FIELDS)}")
        if self.size < 1 or self.start < 0:
            raise ValueError(f"channel {self.name!r}: start must be >= 0 and size >= 1")


@dataclass
class NativeHook:
    """A compiled stepper: C function `fn` (mbs_hook_fn), its user data `ud`, and the array the `hook` channel
    records from. `keep` holds whatever must outlive the run (buffers the C side points into). `describe(code)`
    turns a negative return code into words."""

    fn: Any
    ud: Any
    record: np.ndarray | None = None
    keep: tuple = ()
    describe: Callable[[int], str] = field(default=lambda code: f"native stepper error {code}")


def callbacks_installed() -> list[str]:
    """Names of the MuJoCo Python callbacks currently installed in this process (any, not only mbsuite's)."""
    return sorted(name for name, get in _CALLBACK_GETTERS.items() if get() is not None)


def _refuse_python_callbacks(what: str) -> None:
    installed = callbacks_installed()
    if installed:
        raise SolverError(f"{what}: MuJoCo Python callback(s) {installed} are installed in this process and would act "
                          "on this run as well (they are process-global); remove them first")


_CALLBACK_GETTERS = {"passive": mujoco.get_mjcb_passive, "act_dyn": mujoco.get_mjcb_act_dyn,
                     "act_gain": mujoco.get_mjcb_act_gain, "act_bias": mujoco.get_mjcb_act_bias,
                     "control": mujoco.get_mjcb_control, "sensor": mujoco.get_mjcb_sensor}


class _Job(ctypes.Structure):
    _fields_ = [
        ("nstep", ctypes.c_long), ("k0", ctypes.c_long), ("final", ctypes.c_int),
        ("ctrl", ctypes.c_void_p), ("ctrl_idx", ctypes.c_void_p), ("ctrl_ncol", ctypes.c_int),
        ("ctrl_rows", ctypes.c_long),
        ("every", ctypes.c_int), ("rec", ctypes.c_void_p), ("rec_cap", ctypes.c_long), ("rec_row", ctypes.c_long),
        ("rec_ncol", ctypes.c_int), ("nchan", ctypes.c_int), ("chan_field", ctypes.c_void_p),
        ("chan_start", ctypes.c_void_p), ("chan_size", ctypes.c_void_p), ("lo", ctypes.c_void_p),
        ("hi", ctypes.c_void_p), ("check_every", ctypes.c_int),
        ("hook", ctypes.c_void_p), ("hook_ud", ctypes.c_void_p), ("hook_rec", ctypes.c_void_p),
        ("status", ctypes.c_int), ("fail_step", ctypes.c_long), ("fail_time", ctypes.c_double),
        ("fail_col", ctypes.c_int), ("fail_value", ctypes.c_double), ("fail_plugin", ctypes.c_int),
        ("fail_code", ctypes.c_int), ("fail_what", ctypes.c_char_p), ("steps_done", ctypes.c_long),
        ("fail_text", ctypes.c_char_p),
    ]


#: the core's entry point as Python binds it (`native.bind`: the ABI and the `mbs_job` layout checked once, under the
#: library's lock)
JOB = native.Declaration("engines/native/core.c", "mbs_abi_version", native.ABI_VERSION,
                         functions=(native.CFunction("mbs_run", ctypes.c_int, (ctypes.c_void_p,) * 3),),
                         structs=(native.CStruct(_Job, "mbs_job_size"),))


@dataclass
class Trajectory:
    """What a run recorded: times `t` (rows) and one array per channel ((rows,) for size 1, else (rows, size))."""

    t: np.ndarray
    channels: dict[str, np.ndarray]
    steps: int
    warnings: dict[str, int]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.channels[name]


def _ptr(a: np.ndarray | None) -> int | None:
    return None if a is None else a.ctypes.data


def rows_for(nstep: int, every: int) -> int:
    """Recorded rows of a run of `nstep` steps sampled every `every` steps (the final state always included)."""
    return nstep // every + 1 + (1 if nstep % every else 0)


INTERRUPT_STEPS = 50_000  # steps per C call of a run with no Python step between (Ctrl-C latency: ~0.05-0.5 s)


class Stepper:
    """A model and its data, stepped by the native core (module docstring).

    `what` names the run in error messages (e.g. "pantograph scene lab (MuJoCo)"); `hint` is the advice appended to
    numerical failures. MuJoCo's Python callbacks are process-global: one installed anywhere in the process would act on
    this run too, so a Stepper refuses to run while one is installed, unless `allow_callbacks` (a model that is meant
    to run with its Python twins)."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData | None = None, channels: Sequence[Channel] = (), *,
                 every: int = 1, check_every: int = 64, hook: NativeHook | None = None, what: str = "MuJoCo run",
                 hint: str = DEFAULT_HINT, allow_callbacks: bool = False):
        self.lib = native.load()
        self.model = model
        self.data = data if data is not None else mujoco.MjData(model)
        self.channels = tuple(channels)
        if len({c.name for c in self.channels}) != len(self.channels):
            raise ValueError("channel names must be unique")
        self.every = int(every)
        self.check_every = int(check_every)
        if self.every < 1 or self.check_every < 1:
            raise ValueError("every and check_every must be >= 1")
        if self.data.signature != model.signature:
            raise ValueError(f"{what}: the MjData was not made for this MjModel (signatures differ)")
        self.allow_callbacks = allow_callbacks
        if not allow_callbacks:
            _refuse_python_callbacks(what)
        self.hook = hook
        self.what = what
        self.hint = hint
        self._field = np.array([_FIELD_ID[c.field] for c in self.channels], np.int32)
        self._start = np.array([3 * c.start if c.field == "site_xpos" else c.start for c in self.channels], np.int32)
        self._size = np.array([c.size for c in self.channels], np.int32)
        self.ncol = 1 + int(self._size.sum())
        self._lo = np.full(self.ncol, -np.inf)
        self._hi = np.full(self.ncol, np.inf)
        col = 1
        for c in self.channels:
            self._lo[col:col + c.size] = c.lo
            self._hi[col:col + c.size] = c.hi
            col += c.size
        self._check_sizes()
        # the job's constant part, and the pointers, once: a co-simulation calls run(1) at every step
        self._idx_cache: dict[tuple[int, ...] | None, np.ndarray] = {}
        self._job = job = _Job()
        job.every = self.every
        job.rec_ncol = self.ncol
        job.nchan = len(self.channels)
        job.chan_field, job.chan_start, job.chan_size = _ptr(self._field), _ptr(self._start), _ptr(self._size)
        job.lo, job.hi = _ptr(self._lo), _ptr(self._hi)
        job.check_every = self.check_every
        if hook is not None:
            job.hook = ctypes.cast(hook.fn, ctypes.c_void_p)
            job.hook_ud = hook.ud if isinstance(hook.ud, int) else ctypes.cast(hook.ud, ctypes.c_void_p)
            job.hook_rec = _ptr(hook.record)
        self._job_ref = ctypes.byref(job)
        self._m_ptr, self._d_ptr = ctypes.c_void_p(self.model._address), ctypes.c_void_p(self.data._address)
        self._mbs_run = native.bind(JOB).mbs_run

    def _check_sizes(self) -> None:
        m = self.model
        avail = {"time": 1, "qpos": m.nq, "qvel": m.nv, "act": m.na, "ctrl": m.nu, "actuator_force": m.nu,
                 "actuator_length": m.nu, "actuator_velocity": m.nu, "sensordata": m.nsensordata,
                 "qfrc_passive": m.nv, "qfrc_actuator": m.nv, "energy": 2, "site_xpos": 3 * m.nsite,
                 "hook": 0 if self.hook is None or self.hook.record is None else self.hook.record.size}
        for c, start in zip(self.channels, self._start, strict=True):
            if c.field in ("eq_pos", "eq_force"):
                if c.start >= m.neq:
                    raise ValueError(f"channel {c.name!r}: model has no equality {c.start}")
                continue
            if start + c.size > avail[c.field]:
                raise ValueError(f"channel {c.name!r}: {c.field}[{start}:{start + c.size}] is out of range "
                                 f"({avail[c.field]} values)")

    # ------------------------------------------------------------------------------------------------ running
    def run(self, nstep: int, *, ctrl: np.ndarray | None = None, ctrl_idx: Sequence[int] | None = None,
            between: Callable[[int, mujoco.MjData], None] | None = None, period: int = 1,
            record: bool = True) -> Trajectory:
        """Step `nstep` times from the data's current state; returns the recorded trajectory (rows at every
        `every`-th step and the final state; none with `record=False`). See the module docstring for the inputs."""
        nstep = int(nstep)
        if nstep < 0:
            raise ValueError(f"nstep must be >= 0, got {nstep}")
        if active_callbacks() and not self.allow_callbacks:
            _refuse_python_callbacks(self.what)
        job = self._job
        if ctrl is not None:
            if not (isinstance(ctrl, np.ndarray) and ctrl.dtype == np.float64 and ctrl.flags.c_contiguous):
                ctrl = np.ascontiguousarray(ctrl, dtype=np.float64)
            idx = self._index(ctrl_idx)
            ncol = 1 if ctrl.ndim == 1 else ctrl.shape[1]
            if ctrl.ndim > 2 or ncol != idx.size or ctrl.shape[0] < nstep:
                raise ValueError(f"ctrl must have shape (>= {nstep}, {idx.size}) for actuators {idx.tolist()}; "
                                 f"got {ctrl.shape}")
            job.ctrl, job.ctrl_idx, job.ctrl_ncol, job.ctrl_rows = ctrl.ctypes.data, idx.ctypes.data, ncol, \
                ctrl.shape[0]
        else:
            job.ctrl, job.ctrl_idx, job.ctrl_ncol, job.ctrl_rows = None, None, 0, 0
        if record:
            rows = rows_for(nstep, self.every)
            rec = np.empty((rows, self.ncol))
            job.rec, job.rec_cap = rec.ctypes.data, rows
        else:
            rec = None
            job.rec, job.rec_cap = None, 0
        job.rec_row = 0
        t0 = float(self.data.time)
        steps = 0
        # without a Python step between calls, run in pieces of INTERRUPT_STEPS so that Ctrl-C (handled by Python
        # between C calls) stops a long run within a fraction of a second; the pieces continue one run exactly
        chunk = min(max(nstep, 1), INTERRUPT_STEPS) if between is None else max(1, int(period))
        k = 0
        while True:
            n = min(chunk, nstep - k)
            if between is not None and k < nstep:
                between(k, self.data)
            job.nstep, job.k0, job.final = n, k, int(record and k + n >= nstep)
            self._mbs_run(self._m_ptr, self._d_ptr, self._job_ref)
            steps += job.steps_done
            if job.status != 0:
                raise self._error(job)
            k += n
            if k >= nstep:
                break
        if rec is None:
            return Trajectory(np.empty(0), {}, steps, {})
        return self._trajectory(rec[:job.rec_row], steps, t0, nstep)

    def _index(self, ctrl_idx: Sequence[int] | None) -> np.ndarray:
        """The actuator indices of the input columns (validated once per distinct list)."""
        key = None if ctrl_idx is None else tuple(int(i) for i in ctrl_idx)
        idx = self._idx_cache.get(key)
        if idx is None:
            idx = np.arange(self.model.nu, dtype=np.int32) if key is None else np.array(key, dtype=np.int32)
            if np.any((idx < 0) | (idx >= self.model.nu)):
                raise ValueError(f"ctrl_idx {list(idx)}: the model has {self.model.nu} actuators")
            self._idx_cache[key] = idx
        return idx

    def _trajectory(self, rec: np.ndarray, steps: int, t0: float, nstep: int) -> Trajectory:
        """The recorded rows as named arrays. Times are the nominal grid t0 + k h of the recorded steps k: MuJoCo's
        `d.time` is a running sum of h, off the grid by rounding (1e-13 s after 10^4 steps), which would move samples
        across a window boundary such as t >= t_settle."""
        out, col = {}, 1
        for c in self.channels:
            a = rec[:, col:col + c.size]
            out[c.name] = a[:, 0].copy() if c.size == 1 else a.copy()
            col += c.size
        k = np.arange(0, nstep + 1, self.every)
        if k[-1] != nstep:
            k = np.append(k, nstep)
        k = k[:rec.shape[0]]
        t = t0 + k * self.model.opt.timestep
        if not np.allclose(t, rec[:, 0], rtol=0, atol=1e-9 * max(1.0, abs(t[-1]) if t.size else 1.0)):
            raise SolverError(f"{self.what}: recorded times left the step grid (the data's time was changed "
                              "during the run)")
        return Trajectory(t, out, steps, warnings_raised(self.data))

    def _column_name(self, col: int) -> str:
        c0 = 1
        for c in self.channels:
            if col < c0 + c.size:
                return c.name if c.size == 1 else f"{c.name}[{col - c0}]"
            c0 += c.size
        return f"column {col}"

    def _error(self, job: _Job) -> SolverError:
        m = self.model
        integ = mujoco.mjtIntegrator(m.opt.integrator).name[6:].lower()
        setting = f"integrator {integ}, timestep {m.opt.timestep:g} s"
        hint = self.hint
        if hint == DEFAULT_HINT and integ in ("euler", "rk4"):
            hint += " or use an implicit integrator"
        at = f"at t = {job.fail_time:.6g} s"
        if job.status == 3:
            return plugin_error(m, job.fail_plugin, job.fail_text.decode(), job.fail_value, job.fail_time,
                                job.fail_what.decode() if job.fail_what else None, self.what, setting, hint)
        if job.status == 4:
            c = self.channels_flat_bound(job.fail_col)
            return SolverError(f"{self.what}: {self._column_name(job.fail_col)} = {job.fail_value:.6g} is outside its "
                               f"plausible range [{c[0]:g}, {c[1]:g}] {at} ({setting}); {hint}")
        if job.status == 5 and self.hook is not None:
            return SolverError(f"{self.what}: {self.hook.describe(job.fail_code)} {at} ({setting})")
        if job.status == 6:
            return SolverError(f"{self.what}: invalid arguments to the native core (a recording buffer too small or a "
                               "bad input array)")
        if job.status == 2:
            w = mujoco.mjtWarning(job.fail_code)
            name = w.name[7:].lower()
            if w in (mujoco.mjtWarning.mjWARN_CNSTRFULL, mujoco.mjtWarning.mjWARN_CONTACTFULL):
                return SolverError(f"{self.what}: MuJoCo's {name.replace('full', '')} arrays are full {at} "
                                   f"({setting}); give the model more memory (MJCF <size memory=...>)")
            return SolverError(f"{self.what}: MuJoCo diverged (warning {name}: a non-finite or huge value) {at} "
                               f"({setting}); {hint}")
        return SolverError(f"{self.what}: MuJoCo diverged ({_STATUS.get(job.status, job.status)}) {at} ({setting}); "
                           f"{hint}")

    def channels_flat_bound(self, col: int) -> tuple[float, float]:
        """The plausibility bounds of every recorded column, flattened in recording order."""
        return float(self._lo[col]), float(self._hi[col])


def plugin_error(m: mujoco.MjModel, instance: int, text: str, value: float, time: float, what: str | None,
                 run: str, setting: str, hint: str) -> SolverError:
    """The error of an mbsuite plugin fault: the effect (plugin instance) by name, the fault's text (the model's own
    for a model-specific fault), the offending attribute or value, and when."""
    name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_PLUGIN, instance) or f"instance {instance}"
    if time < 0:  # found when the data was created: the model's configuration, nothing to do with the run's numerics
        bad = f" '{what}'" if what else ""
        val = "" if value != value else f" (value {value:.6g})"
        return SolverError(f"{run}: effect '{name}': {text}: attribute{bad}{val} in the model's plugin "
                           "configuration (found at load)")
    detail = f" ({what})" if what else ""
    return SolverError(f"{run}: effect '{name}': {text}{detail} (value {value:.6g}) at t = {time:.6g} s ({setting}); "
                       f"the state is non-physical: check the parameters and the input, or {hint}")


def check_plugin_faults(m: mujoco.MjModel, d: mujoco.MjData, run: str) -> None:
    """Raise the SolverError of the first fault an mbsuite plugin of (m, d) recorded (after any MuJoCo call outside
    the core: an equilibrium's mj_forward, a `mujoco.rollout`)."""
    if not m.nplugin:
        return
    lib = native.load()
    code, time, value = ctypes.c_int(), ctypes.c_double(), ctypes.c_double()
    what, text = ctypes.c_char_p(), ctypes.c_char_p()
    i = lib.mbs_plugin_fault(ctypes.c_void_p(m._address), ctypes.c_void_p(d._address), ctypes.byref(code),
                             ctypes.byref(time), ctypes.byref(value), ctypes.byref(what), ctypes.byref(text))
    if i >= 0:
        setting = f"timestep {m.opt.timestep:g} s"
        raise plugin_error(m, i, text.value.decode(), value.value, time.value,
                           what.value.decode() if what.value else None, run, setting, DEFAULT_HINT)


def n_workers(workers: int = 0) -> int:
    """`workers` if positive, else all cores available to this process."""
    if workers and workers > 0:
        return int(workers)
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - non-Linux
        return os.cpu_count() or 1


def map_threads(fn: Callable[[Any], Any], items: Iterable[Any], workers: int = 0) -> list[Any]:
    """`[fn(x) for x in items]` on `workers` threads (0 = all cores). For functions whose work is native-core runs
    (the GIL is released while the core steps), this is a parallel sweep in C threads; results keep the order of
    `items` and are identical to a serial run."""
    items = list(items)
    nw = min(n_workers(workers), len(items)) or 1
    if nw <= 1:
        return [fn(x) for x in items]
    with ThreadPoolExecutor(max_workers=nw) as ex:
        return list(ex.map(fn, items))
