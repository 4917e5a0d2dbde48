"""The rotor library's native stepper: a `RotorRun` packed into the C struct of `native/rotors.c`, run by the core.

`NativeRotorRun(run).run()` packs the rotor system (rotor dof/qpos addresses, inertias, friction elements with their
rotors, breakaway factors, locks and actuators, parts with levels, commands and schedules, sources with c0, c1 and
shapes) into numpy buffers the C struct points into (kept alive by this object), runs `core.Stepper` with the C
function `mbs_rotors_hook` as its native stepper and the controller as its `between` callable at the controller's
period, drains the C event buffer between the chunks, and returns the `RefResult`. Nothing in here is global: two
runs in two threads never mix.
"""

from __future__ import annotations

import ctypes
from typing import Any

import numpy as np

from ...engines import core, mujoco_engine, native
from ...engines.inputs import Signal
from .interfaces import FREE
from .rotor_run import CHATTER_N, CHATTER_WINDOW, CHUNK, HINT, RotorRun

_P = ctypes.c_void_p
_LONG = np.dtype(f"i{ctypes.sizeof(ctypes.c_long)}")


class _Rotors(ctypes.Structure):
    """Mirror of `mbs_rotors` (native/rotors.c); the library's `mbs_rotors_struct_size` checks the layout."""

    _fields_ = [
        ("n", ctypes.c_int), ("ne", ctypes.c_int), ("npart", ctypes.c_int), ("nsrc", ctypes.c_int),
        ("neq", ctypes.c_int), ("timevar", ctypes.c_int), ("chatter_n", ctypes.c_int),
        ("chatter_window", ctypes.c_int), ("dt", ctypes.c_double),
        ("dof", _P), ("qadr", _P), ("J", _P), ("B", _P),
        ("ea", _P), ("eb", _P), ("peak", _P), ("free_tol", _P), ("eq", _P), ("act", _P), ("act_sign", _P),
        ("eq2el", _P),
        ("owner", _P), ("level", _P), ("cmd", _P), ("sched", _P),
        ("sbody", _P), ("c0", _P), ("c1", _P), ("sact", _P), ("shape", _P), ("sig", _P), ("u", _P),
        ("modes", _P), ("armed", _P), ("old", _P), ("scratch", _P), ("chatter", _P), ("nchange", _P),
        ("lam", _P), ("gprev", _P), ("gnow", _P), ("wr", _P), ("lv", _P), ("el", _P), ("lvm", _P), ("elm", _P),
        ("wa", _P), ("qa", _P), ("wtmp", _P), ("acc", _P), ("ctrl0", _P),
        ("first", ctypes.c_int), ("decided", ctypes.c_int), ("reset_energy", ctypes.c_double),
        ("lock_trials", ctypes.c_long),
        ("rec", _P), ("ncmd", ctypes.c_int),
        ("ev", _P), ("ev_cap", ctypes.c_long), ("ev_n", ctypes.c_long),
        ("err_index", ctypes.c_int), ("err_time", ctypes.c_double), ("err_value", ctypes.c_double),
        ("general", ctypes.c_int), ("grow", _P), ("eqsign", _P), ("oneway", _P), ("hold", _P),
        ("ndamp", ctypes.c_int), ("da", _P), ("db", _P), ("dD", _P), ("c2", _P), ("sheld", _P),
        ("gmat", _P), ("gidx", _P),
    ]


#: the ABI of native/rotors.c (`mbs_rotors_abi`): bump both with any change of `mbs_rotors` or of a signature
ABI = 1
#: rotors.c as Python binds it (`engines.native.bind`: loaded once under the library's lock, ABI and `_Rotors` layout
#: checked)
DECLARATION = native.Declaration(
    "components/rotational/native/rotors.c", "mbs_rotors_abi", ABI,
    functions=(native.CFunction("mbs_rotors_hook", ctypes.c_int,
                                (ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_long, ctypes.c_int)),),
    structs=(native.CStruct(_Rotors, "mbs_rotors_struct_size"),),
)


def library() -> native.Binding:
    """The rotor stepper's entry points on the native library (`DECLARATION`)."""
    return native.bind(DECLARATION)


class NativeRotorRun:
    """A `RotorRun` on the native core (module docstring)."""

    def __init__(self, run: RotorRun):
        self.run_ = run
        sim, sys = run.sim, run.sys
        m = run.m
        n, ne = sys.n, len(sys.frictions)
        fr = sys.frictions
        i32, f64 = np.int32, np.float64
        self.events: list[dict[str, Any]] = []
        specs: list[float] = []

        def offset(sig: Signal | None) -> int:
            if sig is None:
                return -1
            off = len(specs)
            specs.extend(sig.spec().tolist())
            return off

        eq2el = np.full(m.neq, -1, i32)
        for e, k in enumerate(sim.eq):
            eq2el[k] = e
        cmd_index = {c: i for i, c in enumerate(run.commands)}
        parts = [pt for f in fr for pt in f.parts]
        b = {  # every buffer the C struct points into; this dict keeps them alive
            "dof": np.array(sim.dof, i32), "qadr": np.array(sim.qadr, i32), "J": np.array(sys.J, f64),
            "B": np.array(sys.B, f64),
            "ea": np.array([f.a for f in fr], i32), "eb": np.array([f.b for f in fr], i32),
            "peak": np.array([f.peak for f in fr], f64),
            "free_tol": np.array([1e-12 * max(1.0, sum(p.level for p in f.parts)) for f in fr], f64),
            "eq": np.array(sim.eq, i32), "act": np.array(sim.act, i32), "act_sign": np.array(sim.act_sign, f64),
            "eq2el": eq2el,
            "owner": np.array(run.part_owner, i32), "level": np.array([pt.level for pt in parts], f64),
            "cmd": np.array([cmd_index[pt.command] if pt.command is not None else -1 for pt in parts], i32),
            "sched": np.array([offset(s) for s in run.schedules], i32),
            "sbody": np.array([s.body for s in sys.sources], i32), "c0": np.array([s.c0 for s in sys.sources], f64),
            "c1": np.array([s.c1 for s in sys.sources], f64), "sact": np.array(sim.src, i32),
            "shape": np.array([offset(s) for s in run.shapes], i32),
            "u": run.u_arr,
            "modes": np.full(ne, FREE, i32), "armed": np.zeros(ne, i32), "old": np.zeros(ne, i32),
            "scratch": np.zeros(2 * n + 2 + 2 * ne, i32), "chatter": np.zeros(ne * CHATTER_N, _LONG),
            "nchange": np.zeros(ne, _LONG),
            "lam": np.zeros(ne), "gprev": np.full(ne, np.nan), "gnow": np.full(ne, np.nan), "wr": np.zeros(ne),
            "lv": np.zeros(len(parts)), "el": np.zeros(ne), "lvm": np.zeros(len(parts)), "elm": np.zeros(ne),
            "wa": np.zeros(n), "qa": np.zeros(n), "wtmp": np.zeros(2 * n + 2),
            "acc": np.zeros(1 + n + len(parts) + len(run.dampers)),
            "ctrl0": np.zeros(max(m.nu, 1)),
            "grow": np.ascontiguousarray(sys.rows, f64).reshape(-1), "eqsign": np.array(sim.eq_sign, f64),
            "oneway": np.array([f.one_way_hold is not None for f in fr], i32),
            "hold": np.array([f.one_way_hold or 0.0 for f in fr], f64),
            "da": np.array([s_.a for s_ in run.dampers], i32), "db": np.array([s_.b for s_ in run.dampers], i32),
            "dD": np.array([s_.D for s_ in run.dampers], f64), "c2": np.array([s_.c2 for s_ in sys.sources], f64),
            "sheld": np.zeros(len(sys.sources)), "gmat": np.zeros(ne * (ne + 1) + ne), "gidx": np.zeros(2 * ne, i32),
        }
        b["sig"] = np.array(specs or [0.0, 0.0], f64)
        self.rec = np.zeros(run.nrec)
        # chunks of the core between two calls of `_between`: the controller period, or a divisor of it of at most
        # CHUNK steps (the event buffer holds a chunk's events: at most one change per element and step)
        p = run.period
        self.chunk = p if p <= CHUNK else next(c for c in range(CHUNK, 0, -1) if p % c == 0)
        self.ev_cap = ne * (self.chunk + 2)
        self.ev = np.zeros((self.ev_cap, 5))
        for k, a in b.items():  # the C side reads the buffers as they are: contiguous, exact dtype
            if a.size == 0:
                b[k] = a = np.zeros(1, a.dtype)
            assert a.flags.c_contiguous, k
        self.buffers = b
        s = _Rotors()
        s.n, s.ne, s.npart, s.nsrc, s.neq = n, ne, len(parts), len(sys.sources), m.neq
        s.timevar, s.chatter_n, s.chatter_window, s.dt = int(run.timevar), CHATTER_N, CHATTER_WINDOW, run.dt
        for k, a in b.items():
            setattr(s, k, a.ctypes.data)
        s.first, s.decided, s.reset_energy, s.lock_trials = 1, 0, 0.0, 0
        s.rec, s.ncmd = self.rec.ctypes.data, len(run.commands)
        s.ev, s.ev_cap, s.ev_n = self.ev.ctypes.data, self.ev_cap, 0
        s.err_index, s.err_time, s.err_value = 0, 0.0, 0.0
        s.general, s.ndamp = int(sim.general), len(run.dampers)
        self.struct = s
        lib = library()
        self.hook = core.NativeHook(fn=lib.mbs_rotors_hook, ud=ctypes.addressof(s), record=self.rec,
                                    keep=(s, b, self.rec, self.ev), describe=self.describe)

    def drain_events(self) -> None:
        """Move the events the C side wrote since the last drain into `events`."""
        s = self.struct
        if s.ev_n:
            run = self.run_
            for t, t_step, e, old, new in self.ev[:s.ev_n]:
                self.events.append(run.event(t, t_step, int(e), int(old), int(new)))
            s.ev_n = 0

    def _between(self, k: int, d) -> None:
        self.drain_events()
        if self.run_.controller is not None and k % self.run_.period == 0:
            self.run_.sample(k)

    def run(self):
        """Run on mbsuite's native core with the C state machine; returns the `RefResult`."""
        run = self.run_
        stepper = core.Stepper(run.m, run.d, [core.Channel("rec", "hook", 0, run.nrec)], every=run.every,
                               check_every=1, hook=self.hook, what="rotor MuJoCo path", hint=HINT)
        tr = stepper.run(run.nstep, between=self._between, period=self.chunk)
        self.drain_events()
        rows = tr["rec"]
        if rows.ndim == 1:
            rows = rows[:, None]
        if run.nstep % run.every:  # the final state is off the output grid: not recorded (as the hand path)
            rows = rows[:-1]
        s = self.struct
        stats = {"reset_energy": float(s.reset_energy), "lock_trials": int(s.lock_trials), "steps": run.nstep,
                 "warnings": mujoco_engine.warnings_raised(run.d)}
        return run.result(rows, self.events, stats)

    def describe(self, code: int) -> str:
        """The native stepper's error `code` in words (element or part named; the core adds the time)."""
        s, sys = self.struct, self.run_.sys
        i = s.err_index
        el = sys.frictions[i].name if 0 <= i < len(sys.frictions) else None
        if code == -1:
            what = (f"lock force of friction element '{el}'" if el else
                    f"speed or position of rotor '{sys.names[-1 - i]}'")
            return f"the {what} is not finite ({s.err_value:g}; {HINT})"
        if code == -2:
            return (f"the stick/slip state machine does not settle: friction element '{el}' changed mode "
                    f"{CHATTER_N + 1} times within {int(s.err_value)} steps (mode chattering: the torque on it "
                    f"reverses within a few steps; {HINT})")
        if code == -3:
            return f"the event buffer ({self.ev_cap} events) overflowed at element '{el}'"
        if code == -4:
            return "the lock trials did not settle (releasing the most overloaded lock did not end)"
        if code == -5:
            labels = self.run_.labels
            src = [s_.label for s_ in sys.sources]
            what = (f"schedule of friction part '{labels[i]}'" if i < len(labels) else
                    f"shape of torque source '{src[i - len(labels)]}'")
            return f"the {what} is not finite ({s.err_value!r})"
        return f"native stepper error {code}"
