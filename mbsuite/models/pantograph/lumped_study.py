"""The lumped fit as an analysis (`mbsuite pantograph fit-lumped`): the driving-point receptance of a pantograph scene,
its fitted n-stage lumped pantograph and transfer-function pantograph (`lumped_fit.py`), the fit errors, and the files:
`lumped_fit.json` (the fitted parameters, each as the `[pantograph]` section of a catenary scene), `lumped_fit.csv`
(|G| and phase of the model and both fits per frequency), `lumped_fit.png`, and two catenary scenes under the EN 50318
line with the fitted pantographs (`lumped<n>.toml`, `transfer.toml`: `mbsuite catenary OUT/lumped2.toml`)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import ParameterError
from ...results import Report, format_table, write_csv
from ...scenes import Scene
from .fit_defaults import BAND, DEFAULT_ORDER, DF, STARTS
from .inputs import config_of
from .lumped_fit import band_freqs, driving_point, fit_error, fit_lumped, fit_transfer

#: the fit error is also reported above this frequency (Hz): below it the model's receptance is set by its negative
#: static stiffness and the cylinder, which no positive chain has
ABOVE_HZ = 1.0


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):  # before the numbers: a bool is an int to Python, but true to TOML
        return "true" if v else "false"
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return repr(float(v))


def catenary_scene(kind: str, params: dict[str, Any], description: str) -> str:
    """The text of a catenary scene under the EN 50318 line with the linear pantograph `kind` of `params` (slack
    droppers, 0.5 m elements, 0.2 ms: the reference scene `catenary/en50318`'s settings; the Eppinger scene's finer
    0.1 ms by `--timestep 1e-4`)."""
    inline = ", ".join(f"{k} = {_toml_value(v)}" for k, v in params.items())
    return (f'model = "catenary"\ndescription = "{description}"\n\n[effects]\ndroppers = "slack"\n'
            f'pantograph = "{kind}"\ncontact = "unilateral"\n\n[input]\n'
            f'type = "passage"\nspeed = 250.0\n\n[pantograph]\nparams = {{ {inline} }}\n\n[solver]\n'
            'engine = "reference"\ntimestep = 2e-4\nduration = 6.1   # informative only: a passage runs from x_start '
            'to x_end at the given speed\n')


#: how the lumped fit takes its base spring k_n: held at the model's static stiffness, or fitted (positive)
BASE_SPRINGS = ("static", "fitted")


def fit_report(scene: Scene, stages: int = 2, band: tuple[float, float] = BAND, df: float = DF,
               height: float | None = None, order: int = DEFAULT_ORDER, starts: int = STARTS, seed: int = 0,
               base_spring: str = "static") -> Report:
    """Fit an n-stage lumped and an order-`order` transfer-function pantograph to the driving-point receptance of the
    pantograph `scene` (its parameters and effects) at ram height `height` (m; default its y_op) over `band` (Hz,
    spacing `df`); `base_spring` "static": the chain's base spring holds the model's static stiffness at the head
    (so that its static uplift varies with the height as the model's), "fitted": fitted as the others, positive. A
    Report with the parameters, the fit errors and the files (module docstring)."""
    if base_spring not in BASE_SPRINGS:
        raise ParameterError(f"base_spring = {base_spring!r}; valid: {list(BASE_SPRINGS)}")
    freqs = band_freqs(band, df)
    p = scene.build_params()
    dp = driving_point(p, dict(config_of(scene).__dict__), height, freqs)
    lf = fit_lumped(freqs, dp.G, stages, dp.static_force, starts=starts, seed=seed,
                    static_stiffness=dp.static_stiffness if base_spring == "static" else None)
    tf = fit_transfer(freqs, dp.G, order, dp.static_force)
    above = freqs >= ABOVE_HZ
    G_l, G_t = lf.params.receptance(freqs), tf.params.receptance(freqs)
    err = {"lumped": lf.error, "transfer": tf.error}
    if np.count_nonzero(above) >= 2:
        err_above = {"lumped": fit_error(freqs[above], G_l[above], dp.G[above]),
                     "transfer": fit_error(freqs[above], G_t[above], dp.G[above])}
    else:
        err_above = {}
    sec_l, sec_t = lf.params.section(), tf.params.section()
    data = {
        "height_m": dp.height, "static_contact_force_N": dp.static_force, "static_stiffness_N_per_m":
            dp.static_stiffness, "base_spring": base_spring, "band_hz": [float(band[0]), float(band[1])],
        "df_hz": float(df), "frequencies": int(freqs.size),
        "linearisation": "about the static equilibrium at the height, Coulomb friction left out, force input at the "
                         "contact point (no ram spring)",
        "weights": "relative complex error (G_fit - G) / |G|, every frequency alike",
        "lumped": {"stages": stages, "params": sec_l, "error": lf.error, "error_above_hz": err_above.get("lumped"),
                   "starts": lf.starts, "seed": seed, "evaluations": lf.nfev, "cost": lf.cost,
                   "scene": {"effects": {"pantograph": "lumped"}, "pantograph": {"params": sec_l}}},
        "transfer": {"order": order, "num": list(tf.num), "den": list(tf.den), "params": sec_t, "error": tf.error,
                     "error_above_hz": err_above.get("transfer"),
                     "poles_hz": [[z.real / (2 * math.pi), z.imag / (2 * math.pi)] for z in tf.poles],
                     "unstable_poles_hz": [z.real / (2 * math.pi) for z in tf.unstable],
                     "scene": {"effects": {"pantograph": "transfer"}, "pantograph": {"params": sec_t}}},
        "above_hz": ABOVE_HZ,
    }
    rows = []
    for name, e in err.items():
        ea = err_above.get(name, {})
        rows.append([name, e["max_amplitude_rel"], e["at_f_amplitude_hz"], e["max_phase_deg"], e["at_f_phase_hz"],
                     ea.get("max_amplitude_rel", math.nan), ea.get("max_phase_deg", math.nan)])
    lines = [f"driving-point receptance at height {dp.height:g} m (static contact force {dp.static_force:.4g} N, "
             f"static stiffness {dp.static_stiffness:.4g} N/m), {freqs[0]:g}-{freqs[-1]:g} Hz, {freqs.size} "
             f"frequencies; base spring {base_spring}",
             f"{stages}-stage lumped: m = {_fmt(lf.params.m)} kg, k = {_fmt(lf.params.k)} N/m, c = "
             f"{_fmt(lf.params.c)} N s/m, F0 = {lf.params.F0:.5g} N",
             f"transfer function of order {order}: poles "
             + ", ".join(f"{z.real / (2 * math.pi):.3g}{z.imag / (2 * math.pi):+.3g}j" for z in tf.poles if
                         z.imag >= 0) + " Hz" + (" (unstable: the model's negative static stiffness)" if tf.unstable
                                                 else ""),
             format_table(["model", "max |G| rel. err", "at Hz", "max phase err deg", "at Hz",
                           f"|G| rel. err >= {ABOVE_HZ:g} Hz", f"phase err >= {ABOVE_HZ:g} Hz"], rows, ".4g")]

    def write(out: Path) -> list[Path]:
        from ...plotting import save
        from .lumped_fit import write_json

        files = [write_json(out / "lumped_fit.json", data)]
        cols = [("f", "Hz", freqs)]
        for name, g in (("multibody", dp.G), (f"lumped{stages}", G_l), ("transfer", G_t)):
            cols += [(f"{name}_abs", "m/N", np.abs(g)), (f"{name}_phase", "deg", np.degrees(np.angle(g)))]
        files.append(write_csv(out / "lumped_fit.csv", cols))
        files.append(save(plot_fit(freqs, {"multibody (linearised)": dp.G, f"{stages}-stage lumped": G_l,
                                           f"transfer function, order {order}": G_t}), out / "lumped_fit.png"))
        for kind, params, text in ((f"lumped{stages}", sec_l, f"{stages}-stage lumped pantograph"),
                                   ("transfer", sec_t, f"transfer-function pantograph of order {order}")):
            path = out / f"{kind}.toml"
            path.write_text(catenary_scene(kind.rstrip("0123456789"), params, f"EN 50318 catenary (slack droppers) "
                                           f"under the {text} fitted to the Eppinger pantograph at {dp.height:g} m"))
            files.append(path)
        return files

    return Report(data, "\n".join(lines), write)


def _fmt(v: tuple[float, ...]) -> str:
    return "[" + ", ".join(f"{x:.5g}" for x in v) + "]"


def plot_fit(freqs: np.ndarray, curves: dict[str, np.ndarray]):
    """|G| (log) and phase (deg) of each receptance against frequency."""
    from ...plotting import figure

    fig, (a1, a2) = figure(2, 1, size=(8.0, 6.5), sharex=True)
    for (name, g), ls in zip(curves.items(), ("-", "--", ":", "-."), strict=False):
        a1.semilogy(freqs, np.abs(g), ls, label=name)
        a2.plot(freqs, np.degrees(np.angle(g)), ls, label=name)
    a1.set_ylabel("|G| (m/N)")
    a1.set_title("driving-point receptance of the contact point: head displacement per upward force")
    a1.legend()
    a2.set_ylabel("phase (deg)")
    a2.set_xlabel("frequency (Hz)")
    a2.set_yticks(range(-180, 181, 90))
    for a in (a1, a2):
        a.grid(True, alpha=0.3)
    return fig
