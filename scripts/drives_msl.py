"""Four Modelica Rotational examples (MSL 4.1.0, the model `rotational`) on both paths of the rotor library: mode
changes (hand path, MuJoCo, the Modelica Association's reference where published) and the worst signal deviation
relative to the regression tube.

Usage: .venv/bin/python scripts/drives_msl.py [--json FILE]   (about 10 s)
"""

from __future__ import annotations

import argparse
import json

from mbsuite.components.rotational.energy import energy_balance
from mbsuite.components.rotational.event_exact import simulate_reference
from mbsuite.components.rotational.mujoco_sim import MujocoRotorSim
from mbsuite.models.rotational import examples as msl
from mbsuite.paths import mjcf_path
from mbsuite.results import format_table

DT = 1e-4


def study(name: str) -> dict:
    ex = msl.example(name)
    hand = simulate_reference(ex.system, ex.q0, ex.w0, ex.t_end, sample_dt=1e-4, rtol=1e-10, atol=1e-12)
    mj = MujocoRotorSim(ex.system, mjcf_path(f"drive_{name}"), timestep=DT).run(ex.q0, ex.w0, ex.t_end, sample_dt=1e-4)
    out: dict = {"name": name, "events": []}
    eh, em = msl.events_as_codes(hand.events), msl.events_as_codes(mj.events)
    ref = msl.load_reference(ex) if ex.reference else None
    base = msl.reference_events(ex, ref) if ref is not None else eh
    rows_h = msl.pair_events(eh, base)
    rows_m = msl.pair_events(em, base)
    for rh, rm in zip(rows_h, rows_m, strict=True):
        out["events"].append({"element": rh["element"], "from": rh["from"], "to": rh["to"], "hand": rh["t"],
                              "mujoco": rm["t"], "reference": rh["t_ref"] if ref is not None else None})
    for path, res in (("hand", hand), ("mujoco", mj)):
        bal = energy_balance(ex.system, res)
        out[f"energy_residual_{path}"] = bal.residual / bal.input
        if ref is not None:
            tube = msl.tube_check(ex, res, ref)
            worst = max(tube, key=lambda k: tube[k]["ratio"])
            out[f"tube_{path}"] = {"signal": worst, **tube[worst]}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json")
    a = ap.parse_args()
    res = [study(n) for n in msl.EXAMPLES]
    code = {-1: "backward", 0: "stuck", 1: "forward", 2: "free"}
    for r in res:
        print(f"\n{r['name']}")
        rows = [[e["element"], f"{code[e['from']]} -> {code[e['to']]}", e["hand"], e["mujoco"], e["reference"],
                 None if e["reference"] is None else e["hand"] - e["reference"],
                 e["mujoco"] - (e["reference"] if e["reference"] is not None else e["hand"])] for e in r["events"]]
        print(format_table(["component", "change", "t hand", "t MuJoCo", "t reference", "hand-ref",
                            "MuJoCo-ref (or -hand)"], rows, ".7g"))
        for p in ("hand", "mujoco"):
            extra = ""
            if f"tube_{p}" in r:
                tb = r[f"tube_{p}"]
                extra = f"; worst signal {tb['signal']}: {tb['max_dev']:.3g} = {tb['ratio']:.3f} of the tube"
            print(f"  {p}: energy residual / input {r[f'energy_residual_{p}']:.2g}{extra}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(res, f, indent=1)


if __name__ == "__main__":
    main()
