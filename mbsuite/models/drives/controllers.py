"""Switching controllers of the drives (thesis App. E and App. F, reconstructed from the printed C listings).

Every controller is sampled at `fs` and returns the commanded clutch/brake states; the actuation delays are applied by
`commands.CommandQueue` (quantised to samples, as the thesis' shift registers). Rotor order: motor 0, spring 1, load 2.
The same controller object drives the hand-derived and the MuJoCo paths (as the thesis ran the prototype's C code in
its simulator, Sec. 4.3.5).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...components.rotational.commands import delay_samples, time_to_samples
from ...errors import ParameterError

STEP_UP_CONTROLLERS = ("pwm", "resonant", "motor_resonant")


# ---- velocity matching ----------------------------------------------------------------------------------------------
def clutch_loiter(Omega: float, theta_e: float, w_m: float, w_l: float) -> float:
    """Eq 2.1 (App. A, corrected): time after brake release at which the spring end reaches the load speed,
    w_s(t) = Omega theta_e sin(Omega t) - w_m cos(Omega t) + w_m. Returns 0 if w_l <= 0 (as the thesis code);
    a negative discriminant (no real root: the spring cannot reach w_l) is clamped to 0 as in `set_clutch_loiter`."""
    if w_l <= 0.0:
        return 0.0
    d = w_l - 2.0 * w_m
    if abs(d) < np.finfo(float).eps:
        d = 1e-30
    disc = max(0.0, Omega**2 * theta_e**2 - w_l * d)
    t = (2.0 / Omega) * math.atan((Omega * theta_e - math.sqrt(disc)) / d)
    if t < 0.0:  # the atan branch below zero is the same event one period earlier: lift into [0, 2 pi / Omega)
        t += 2.0 * math.pi / Omega
    return t


def match_time(Omega: float, theta_e: float, w_e: float, w_t: float, theta_sign: int) -> tuple[float, bool]:
    """Robust velocity-match time for the free spring system (Eq 2.2 / App. B, root choice by enumeration).

    Free motion: w(t) = A cos(psi), theta(t) = (A/Omega) sin(psi), psi = Omega t + phi, A = hypot(w_e, Omega theta_e).
    Returns the earliest t in [0, 2 pi/Omega) with w = w_t and sign(theta) = theta_sign, and True. If no real root
    exists (the spring system's energy is below 1/2 J_s w_t^2), returns the time of peak speed in the direction of
    w_t (thesis §6.5 recommendation (i): the least slip) and False."""
    A = math.hypot(w_e, Omega * theta_e)
    phi = math.atan2(Omega * theta_e, w_e)
    period = 2.0 * math.pi / Omega
    if A > 0.0 and abs(w_t) <= A:
        psi = (1 if theta_sign >= 0 else -1) * math.acos(max(-1.0, min(1.0, w_t / A)))
        ok = True
    else:
        psi = 0.0 if w_t >= 0 else math.pi
        ok = False
    t = ((psi - phi) / Omega) % period
    return t, ok


# ---- step-up drive (App. E) -----------------------------------------------------------------------------------------
@dataclass
class StepUpController:
    """PWM (`switch_pwm`), resonant (`switch_fdt`) and motor-resonant (`switch_mv`) switching with optional clutch
    matching (Eq 2.1) and the incremental PI on the storage time t_k (App. E, every sample).
    `anti_windup=True` (default): t_k clamped to [0, max_tk] and the clamped value stored. `anti_windup=False`: the
    printed code - state stored before the clamp, upper clamp only - which winds up; the `step_up_closed_loop` scene
    selects it explicitly to reproduce the thesis' closed loop."""

    kind: str
    fs: float
    t_l: float = 0.2
    duty: float = 0.5
    t_n: float = 0.048
    twist_tol: float = 0.0
    min_vel: float = 40.0
    max_vel: float = 60.0
    clutch_matching: bool = False
    Omega: float = 65.6
    delay_comp: float = 0.0  # clutch delay minus brake delay, subtracted from the loiter time (Sec. 2.1.3)
    closed_loop: bool = False
    Kp: float = 0.12
    Ki: float = 4.4e-5
    ref: float = 287.0
    max_tk: float | None = None
    anti_windup: bool = True
    state: int = 1
    log: list[dict[str, Any]] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.kind not in STEP_UP_CONTROLLERS:
            raise ParameterError(f"unknown step-up controller {self.kind!r}; valid: {list(STEP_UP_CONTROLLERS)}")
        self.dt = 1.0 / self.fs
        self.tk_prev = 0.0
        self.e_prev = 0.0
        self.tki = self.tli = self.tci = self.tni = 0
        self.tccount = -1
        self.c_on = 0
        # each count only where the scheme reads it (`config.used_params`): t_l not by motor-resonant switching, t_n
        # not by PWM
        if self.max_tk is None and self.kind != "motor_resonant":
            self.max_tk = 0.5 * self.t_l
        self.tlcount = (time_to_samples(self.t_l, self.fs, "nearest", "cycle time t_l")
                        if self.kind != "motor_resonant" else 0)
        self.tncount = time_to_samples(self.t_n, self.fs, "nearest", "dead time t_n") if self.kind != "pwm" else 0

    def _loiter(self, q: np.ndarray, w: np.ndarray) -> int:
        if not self.clutch_matching:
            return -1
        td = clutch_loiter(self.Omega, q[0] - q[1], w[0], w[2]) - self.delay_comp
        return time_to_samples(max(td, 0.0), self.fs, "floor", "clutch loiter time")

    def __call__(self, k: int, t: float, q: np.ndarray, w: np.ndarray) -> dict[str, int] | None:
        if k == 0:
            return {"brake": 1, "clutch": 0}
        if self.closed_loop:
            e = self.ref - w[2]
            tk = self.tk_prev + self.Kp * (e - self.e_prev) + self.Ki * e
            if self.anti_windup:
                tk = min(max(tk, 0.0), self.max_tk)
                self.tk_prev = tk
            else:
                self.tk_prev = tk  # stored before clamping (no anti-windup, as printed)
                tk = min(tk, self.max_tk)
            self.e_prev = e
        else:
            tk = self.duty * self.t_l
        # storage time: a duration (nearest sample); a negative PI output (printed PI, no anti-windup) is no storage
        tkcount = time_to_samples(max(tk, 0.0), self.fs, "nearest", "storage time t_k")
        self.tk_samples = tkcount
        twist = q[0] - q[1]
        out: dict[str, int] = {}
        if self.kind == "pwm":
            self.tli += 1
            if self.state == 1:
                self.tki += 1
                if self.tki >= tkcount:
                    out["brake"] = 0
                    self.state = 2
                    self.tccount = self._loiter(q, w)
                    self.tci = 0
            if self.state == 2:
                self.tci += 1
                if self.tci >= self.tccount:
                    out["clutch"] = 1
                    self.state = 3
                    self.c_on = 1
            if self.state == 3:
                if self.tli >= self.tlcount:
                    out.update(clutch=0, brake=1)
                    self.tki = self.tli = 0
                    self.state = 1
                    self.log.append({"t": t, "event": "cycle"})
                if self.c_on and twist < self.twist_tol:
                    out["clutch"] = 0
                    self.c_on = 0
        else:
            if self.state == 1:
                self.tki += 1
                go = (w[0] < self.min_vel) if self.kind == "motor_resonant" else (self.tki >= tkcount)
                if go:
                    out["brake"] = 0
                    self.state = 2
                    self.tccount = self._loiter(q, w)
                    self.tci = 0
            if self.state == 2:
                self.tci += 1
                if self.tci > self.tccount:
                    out["clutch"] = 1
                    self.state = 3
            if self.state == 3 and twist < self.twist_tol:
                out["clutch"] = 0
                self.state = 4
                self.tni = 0
            if self.state == 4:
                self.tni += 1
                if self.tni > self.tncount and (self.kind != "motor_resonant" or w[0] > self.max_vel):
                    out["brake"] = 1
                    self.state = 1
                    self.tki = 0
                    self.log.append({"t": t, "event": "cycle"})
        return out


# ---- step-up/step-down drive (App. F, `switch_bds`, with the documented bug fixes) -----------------------------------
@dataclass
class EnergyPacketController:
    """Bi-directional energy-packet resonant switching for the step-up/step-down drive.

    Fixes relative to the printed App. F code (each documented in README):
    1. extraction and transfer waits use `match_time` (root by enumeration with the sign condition of Tables B.1/B.2),
       which removes the negative extraction delay for w_e < 0, w_t < 0;
    2. no real root: wait for the spring's peak speed toward the target instead of the printed `disc <= 0` branch;
    3. the engagement delay C_d is subtracted from both waits, and the end of extraction is predicted (release when
       |theta| >= theta_target - |w_src| R_d, R_d the release delay), like the transfer release (|theta| <= |w_s| R_d);
       the printed code has one clutch delay for both (R_d = C_d, every shipped parameter set).
    Closed loop: velocity-squared energy-packet PI, once per energy cycle (Eq 5.29),
    eps_k = eps_{k-1} + (Kp + Ki t_s) e_k - Kp e_{k-1} with e = sign(r)(|r| r - |w| w), clamped to the spring capacity
    +-1/2 K x_max^2 with the clamped value stored (anti-windup, the default; `anti_windup=False` stores the unclamped
    value and winds up - there is no printed PI to reproduce here, App. F's is P-only and App. J sets anti_windup=1).
    Open loop: a packet of 1/2 K x_max^2 toward sign(ref).
    Log: "cycle" (packet demand eps), "extract_on"/"extracted" (input clutch commanded on/off), "transfer_on"/
    "transferred" (output clutch commanded on/off); `drive.energy_packets` turns them into packet energies.
    """

    fs: float
    K: float
    Omega: float
    clutch_delay: float
    spring_max: float
    release_delay: float | None = None  # None: the same as clutch_delay (every shipped parameter set)
    min_motor_vel: float = 70.0
    min_load_vel: float = 0.0
    closed_loop: bool = False
    Kp: float = 0.00112
    Ki: float = 0.0161
    ref: Any = 400.0  # float or callable(t)
    anti_windup: bool = True
    state: int = 0
    log: list[dict[str, Any]] = field(default_factory=list)

    def __post_init__(self) -> None:
        for nm in ("fs", "K", "Omega", "spring_max"):
            v = getattr(self, nm)
            if not (math.isfinite(v) and v > 0):
                raise ParameterError(f"energy-packet controller: {nm} must be positive, got {v!r}")
        if self.release_delay is None:
            self.release_delay = self.clutch_delay
        for nm in ("clutch_delay", "release_delay", "min_motor_vel", "min_load_vel"):
            v = getattr(self, nm)
            if not (math.isfinite(v) and v >= 0):
                raise ParameterError(f"energy-packet controller: {nm} must be >= 0, got {v!r}")
        self.dt = 1.0 / self.fs
        if max(self.clutch_delay, self.release_delay) >= 2 * math.pi / self.Omega:
            raise ParameterError(f"clutch delay {max(self.clutch_delay, self.release_delay)} s is longer than a "
                                 f"free-oscillation cycle 2 pi/Omega = {2 * math.pi / self.Omega:.4g} s")
        self.E_max = 0.5 * self.K * self.spring_max**2
        self.eps = 0.0
        self.eps_state = 0.0
        self.e_prev = 0.0
        self.t_cycle = None
        self.cd = delay_samples(self.clutch_delay, self.fs)

    def r(self, t: float) -> float:
        """The speed reference at time t [rad/s] (a constant or a profile)."""
        return float(self.ref(t)) if callable(self.ref) else float(self.ref)

    def __call__(self, k: int, t: float, q: np.ndarray, w: np.ndarray) -> dict[str, int] | None:
        wm, ws, wl = w
        ths = q[1]
        out: dict[str, int] = {}
        if self.state == 0:  # run-up: wait for the motor (App. F)
            if abs(wm) > 1.3 * self.min_motor_vel:
                self.state = 1
            else:
                return {"ca": 0, "cb": 0} if k == 0 else None
        if self.state == 1:  # START_OF_CYCLE
            r = self.r(t)
            if self.closed_loop:
                e = math.copysign(1.0, r) * (abs(r) * r - abs(wl) * wl) if r != 0 else -abs(wl) * wl
                ts = (t - self.t_cycle) if self.t_cycle is not None else 0.0
                eps = self.eps_state + (self.Kp + self.Ki * ts) * e - self.Kp * self.e_prev
                clamped = max(-self.E_max, min(self.E_max, eps))
                self.eps_state = clamped if self.anti_windup else eps  # anti-windup: store the clamped value
                self.eps = clamped
                self.e_prev = e
            else:
                self.eps = self.E_max  # open loop: full packets motor -> load, pushed toward sign(ref)
            self.r_dir = 1 if r >= 0 else -1
            self.t_cycle = t
            self.E_dir = 1 if self.eps >= 0 else -1
            src = wm if self.E_dir == 1 else wl
            if self.E_dir == -1 and abs(wl) <= max(self.min_load_vel, 1e-9):
                self.E_dir = 1  # nothing to regenerate from a load at rest
                src = wm
            self.Ess = abs(self.eps)
            te, ok = match_time(self.Omega, ths, ws, src, 1 if src >= 0 else -1)
            # wait_samples: the computed wait in samples before the int() truncation (a value within ~1e-4 of an
            # integer can truncate either way under a ~1e-6 difference in state: one sample later or earlier)
            self.log.append({"t": t, "event": "cycle", "eps": self.eps, "dir": self.E_dir, "root": ok,
                             "wait_samples": te * self.fs})
            self.count = max(0, time_to_samples(te, self.fs, "floor", "extraction wait") - self.cd)
            self.i = 0
            self.state = 2
        if self.state == 2:  # WAIT_ENERGY_EXTRACTION
            self.i += 1
            if self.i > self.count:
                self.target = math.sqrt(2.0 * self.Ess / self.K + ths * ths)
                out["ca" if self.E_dir == 1 else "cb"] = 1
                self.state = 3
                self.src_sign = 1 if (wm if self.E_dir == 1 else wl) >= 0 else -1
                self.log.append({"t": t, "event": "extract_on", "clutch": "ca" if self.E_dir == 1 else "cb"})
                return out
        if self.state == 3:  # ENERGY_EXTRACTION (delay-compensated end)
            src = wm if self.E_dir == 1 else wl
            min_v = self.min_motor_vel if self.E_dir == 1 else self.min_load_vel
            # packet full (predicted at the actual release), source too slow, or source reversed (nothing left)
            if (abs(ths) >= self.target - abs(src) * self.release_delay or abs(src) < min_v
                    or src * self.src_sign <= 0):
                out["ca" if self.E_dir == 1 else "cb"] = 0
                if self.E_dir == 1:
                    tgt, push = wl, self.r_dir
                else:
                    tgt, push = wm, (1 if wm >= 0 else -1)
                # predict the state at the actual release (after the clutch delay) with the source's speed
                th_rel = ths + ws * self.release_delay
                tt, ok = match_time(self.Omega, th_rel, ws, tgt, -push)
                self.count = max(0, time_to_samples(tt + self.release_delay, self.fs, "floor", "transfer wait")
                                 - self.cd)
                self.i = 0
                self.state = 4
                self.log.append({"t": t, "event": "extracted", "theta": ths, "root": ok,
                                 "clutch": "ca" if self.E_dir == 1 else "cb",
                                 "wait_samples": (tt + self.release_delay) * self.fs})
                return out
        if self.state == 4:  # WAIT_ENERGY_TRANSFER
            self.i += 1
            if self.i > self.count:
                out["cb" if self.E_dir == 1 else "ca"] = 1
                self.state = 5
                self.th_peak = abs(ths)
                self.log.append({"t": t, "event": "transfer_on", "clutch": "cb" if self.E_dir == 1 else "ca"})
                return out
        if self.state == 5:  # ENERGY_TRANSFER: predictive release
            self.th_peak = max(self.th_peak, abs(ths))
            if abs(ths) <= abs(ws * self.release_delay):
                out["cb" if self.E_dir == 1 else "ca"] = 0
                self.state = 1
                self.log.append({"t": t, "event": "transferred", "theta_peak": self.th_peak,
                                 "clutch": "cb" if self.E_dir == 1 else "ca"})
        return out
