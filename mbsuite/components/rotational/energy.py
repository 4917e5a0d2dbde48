"""The energy balance of a rotor system's run: input - output - losses - change of stored energy (Oldaker 1997,
Eqs 3.21-3.24, corrected to book the kinetic energy plastic locks remove, `lock_impact`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .interfaces import RefResult, RotorSystem


@dataclass
class Balance:
    """Energy balance of a run over a window [J]: input, output, losses by term, change of stored energy,
    residual = input - output - sum(losses) - stored, and `relative` = residual / turnover (Eqs 3.21-3.24 corrected)."""
    input: float
    output: float
    losses: dict[str, float]
    stored: float
    residual: float

    @property
    def relative(self) -> float:
        """residual / energy turnover, the turnover being the largest of |input|, |output|, sum |losses|, |stored|
        (= the input whenever the drive is driven); 0 when nothing moved at all (no NaN for a zero input)."""
        scale = max(abs(self.input), abs(self.output), sum(abs(v) for v in self.losses.values()), abs(self.stored))
        if scale == 0.0:
            return 0.0 if self.residual == 0.0 else math.copysign(math.inf, self.residual)
        return self.residual / scale


def energy_balance(system: RotorSystem, res: RefResult, i0: int = 0, i1: int = -1) -> Balance:
    """input - output - sum(losses) - delta(stored) between samples i0 and i1 (Eqs 3.21-3.24 corrected). The losses
    include `lock_impact`, the kinetic energy removed by plastic locks, recorded as a cumulative series in step with
    the sampled state, so any window [i0, i1] closes (not only the whole run)."""
    E = res.energy
    d = {k: float(v[i1] - v[i0]) for k, v in E.items()}
    outputs = {p.label for f in system.frictions for p in f.parts if p.output}
    e_in = d.pop("source")
    e_out = sum(d.pop(k) for k in list(d) if k in outputs)
    if "lock_impact" not in E and i0 == 0 and i1 in (-1, res.t.size - 1):  # results without the series
        d["lock_impact"] = float(res.stats.get("reset_energy", 0.0))
    ke1, pe1 = system.stored_energy(res.q[:, i1], res.w[:, i1])
    ke0, pe0 = system.stored_energy(res.q[:, i0], res.w[:, i0])
    stored = ke1 + pe1 - ke0 - pe0
    resid = e_in - e_out - sum(d.values()) - stored
    return Balance(e_in, e_out, d, stored, resid)
