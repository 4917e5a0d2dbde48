"""Contact-wire height irregularities: a measured or designed profile from a file, or a random profile drawn from a
stated one-sided spectral density with a seed (`build` -> `line.Irregularity`).

Random profile (the spectral representation of a stationary Gaussian process, Shinozuka & Deodatis, "Simulation of
stochastic processes by spectral representation", Appl. Mech. Rev. 44, 1991):

    r(x) = sum_i sqrt(2 S(k_i) dk) cos(2 pi k_i x + phi_i),    k_i = k_min + (i + 1/2) dk,   i = 0 .. n - 1,

k the spatial frequency (cycles/m), S(k) the one-sided PSD of the height (m^2 per cycle/m), phi_i independent
uniform phases from numpy's default generator seeded with `seed`. Its variance is sum_i S(k_i) dk (the PSD's integral
over the band, to the midpoint rule): `rms` gives a flat S = rms^2 / (k_max - k_min) on the band of wavelengths
[wavelength_min, wavelength_max]; `psd = [[k, S], ...]` a table, interpolated log-log, zero outside it.

Section keys (a scene's `[line.irregularity]` or a line file's `[irregularity]`): `file` (CSV with columns x (m) and
r (m), on any increasing grid: resampled on `dx`) and `scale` (default 1), or `seed` with `rms`, `wavelength_min`,
`wavelength_max` or with `psd`; `n_waves` (default 2000), `dx` (grid of the profile, default 0.05 m, at most an
eighth of the shortest wavelength).
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import SceneError
from ...limits import Limit
from ...schema import Items, Rule, Section
from .line import Irregularity

DEFAULT_DX = 0.05
DEFAULT_WAVES = 2000
#: most waves of a random profile, most points of a profile's grid (length / dx), most waves x points (the work of
#: the sum; 2e10 multiply-adds is about a minute) and most rows of a profile file: size guards, checked before
#: anything is allocated
MAX_WAVES = 100_000
MAX_POINTS = 20_000_000
MAX_WORK = 2e10
MAX_PROFILE_ROWS = 1_000_000

_RANDOM_KEYS = ("seed", "rms", "wavelength_min", "wavelength_max", "psd", "n_waves")


def _file_keys(d: Mapping[str, Any]) -> str | None:
    extra = sorted(set(d) & set(_RANDOM_KEYS))
    if "file" in d and extra:
        return f"{extra} belong to a random profile; a profile from a file reads file, scale, dx"
    if "file" not in d and "scale" in d:
        return "scale is read only with file"
    return None


def _random_keys(d: Mapping[str, Any]) -> str | None:
    if "file" in d:
        return None
    if "seed" not in d:
        return "a random profile needs seed = a non-negative integer; or give file = a profile CSV"
    if ("psd" in d) == ("rms" in d):
        return "give either rms (with wavelength_min, wavelength_max) or psd = [[k, S], ...]"
    if "rms" in d and not {"wavelength_min", "wavelength_max"} <= set(d):
        return "rms needs wavelength_min and wavelength_max (m)"
    if "psd" in d and ({"wavelength_min", "wavelength_max"} & set(d)):
        return "wavelength_min and wavelength_max go with rms; psd states its own band"
    return None


def _band_order(d: Mapping[str, Any]) -> str | None:
    if "rms" in d and not d["wavelength_max"] > d["wavelength_min"]:
        return f"wavelength_max = {d['wavelength_max']:g} m must exceed wavelength_min = {d['wavelength_min']:g} m"
    if "psd" in d and any(b[0] <= a[0] for a, b in zip(d["psd"], d["psd"][1:], strict=False)):
        return "psd rows [k (cycles/m), S (m^2 m)] need k increasing"
    return None


def _dx_resolves(d: Mapping[str, Any]) -> str | None:
    if "file" in d:
        return None
    kmax = _band(d)[1]
    if d["dx"] > 1.0 / (8.0 * kmax) * (1 + 1e-12):
        return (f"dx = {d['dx']:g} m must be at most an eighth of the shortest wavelength ({1.0 / kmax:g} m): "
                f"<= {1.0 / (8.0 * kmax):g} m")
    return None


#: the declaration of an irregularity table (a scene's `[line.irregularity]`, a line file's `[irregularity]`)
SECTION = Section("irregularity", {
    "file": Limit(kind=str, doc="CSV profile with the columns x (m) and r (m), x increasing (resampled on dx)"),
    "scale": Limit(lo=-1e3, hi=1e3, doc="factor on the file's heights (with file; absent: 1)"),
    "seed": Limit(kind=int, lo=0, hi=2**63 - 1, doc="seed of the random phases (a random profile)"),
    "rms": Limit(lo=0.0, hi=1.0, unit="m", doc="rms height of a flat spectrum over the wavelength band"),
    "wavelength_min": Limit(lo=0.0, lo_open=True, hi=1e4, unit="m", doc="shortest wavelength of the band (with rms)"),
    "wavelength_max": Limit(lo=0.0, lo_open=True, hi=1e4, unit="m", doc="longest wavelength of the band (with rms)"),
    "psd": Items((Limit(lo=0.0, lo_open=True, hi=1e3, unit="cycles/m", doc="k (cycles/m)"),
                  Limit(lo=0.0, lo_open=True, hi=1.0, unit="m^2 m", doc="S (m^2 per cycle/m)")), min=2, max=10_000,
                 doc="one-sided PSD of the height, interpolated log-log, zero outside"),
    "n_waves": Limit(kind=int, lo=1, hi=MAX_WAVES, default=DEFAULT_WAVES, doc="waves of a random profile"),
    "dx": Limit(lo=1e-3, hi=10.0, unit="m", default=DEFAULT_DX, doc="grid of the profile"),
}, rules=(
    Rule("a profile from a file reads file, scale and dx; a random profile seed, n_waves, dx and rms with "
         "wavelength_min and wavelength_max, or psd", _file_keys, given=True),
    Rule("a random profile needs seed and either rms (with wavelength_min and wavelength_max) or psd", _random_keys,
         given=True),
    Rule("wavelength_max > wavelength_min; psd's k increasing", _band_order),
    Rule("dx <= an eighth of the shortest wavelength (a random profile)", _dx_resolves),
), doc="a contact-wire height profile: from a file, or random from a seed and a spectrum")


def check_irregularity(d: Any, where: str) -> dict[str, Any]:
    """The irregularity table `d` (module docstring) checked against `SECTION`, its profile file read; returns the
    checked table with its defaults."""
    out = SECTION.check(d, where)
    if "file" in out:
        _read_profile(out["file"], where)
    return out


def _band(d: Mapping[str, Any]) -> tuple[float, float, Any]:
    """(k_min, k_max, S(k)) of a checked random profile."""
    if "psd" in d:
        a = np.asarray(d["psd"], dtype=float)
        lk, ls = np.log(a[:, 0]), np.log(a[:, 1])
        return float(a[0, 0]), float(a[-1, 0]), lambda k: np.exp(np.interp(np.log(k), lk, ls))
    lmin, lmax, rms = float(d["wavelength_min"]), float(d["wavelength_max"]), float(d["rms"])
    kmin, kmax = 1.0 / lmax, 1.0 / lmin
    s = rms * rms / (kmax - kmin)
    return kmin, kmax, lambda k: np.full(np.shape(k), s)


def size_of(d: Mapping[str, Any], length: float, where: str) -> int:
    """The grid points of a checked profile over [0, length] m, refused (SceneError naming dx, n_waves and the
    estimate) past `MAX_POINTS` points or `MAX_WORK` waves x points, before anything is allocated."""
    n = int(math.floor(length / d["dx"] + 1e-9)) + 1
    if n > MAX_POINTS:
        raise SceneError(f"{where}: dx = {d['dx']:g} m over the line's {length:g} m is {n:,} grid points "
                         f"({8 * n / 1e6:,.0f} MB a profile); at most {MAX_POINTS:,}: enlarge dx")
    if "file" not in d and n * d["n_waves"] > MAX_WORK:
        raise SceneError(f"{where}: n_waves = {d['n_waves']:,} on {n:,} grid points (dx = {d['dx']:g} m) is "
                         f"{float(n) * d['n_waves']:.3g} multiply-adds; at most {MAX_WORK:.0e}: fewer waves or a "
                         "coarser dx")
    return n


def _read_profile(fname: Any, where: str) -> tuple[np.ndarray, np.ndarray]:
    if not isinstance(fname, str):
        raise SceneError(f"{where}: file = {fname!r} must be a file name")
    path = Path(fname)
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = []
            for row in csv.DictReader(fh):
                if len(rows) >= MAX_PROFILE_ROWS:
                    raise SceneError(f"{where}: the profile {path} has more than {MAX_PROFILE_ROWS:,} rows")
                rows.append(row)
    except OSError as exc:
        raise SceneError(f"{where}: cannot read the profile {path}: {exc.strerror or exc}") from exc
    if not rows or set(rows[0]) != {"x", "r"}:
        raise SceneError(f"{where}: the profile {path} needs exactly the columns x (m) and r (m)")
    try:
        x = np.array([float(r["x"]) for r in rows])
        r = np.array([float(r["r"]) for r in rows])
    except (TypeError, ValueError) as exc:
        raise SceneError(f"{where}: the profile {path} holds a value that is not a number ({exc})") from None
    if x.size < 2 or not np.all(np.isfinite(x)) or not np.all(np.isfinite(r)) or np.any(np.diff(x) <= 0):
        raise SceneError(f"{where}: the profile {path} needs >= 2 finite rows with x increasing")
    return x, r


_BUILT: dict[str, Irregularity] = {}


def build(d: Mapping[str, Any], length: float, where: str = "irregularity") -> Irregularity:
    """The `Irregularity` of a checked table `d` over the line [0, length] (m) (the last few kept: a scene's
    parameters are built more than once)."""
    stamp = None
    if isinstance(d.get("file"), str):  # a profile file: its contents count, not only its name
        try:
            st = Path(d["file"]).stat()
            stamp = (st.st_mtime_ns, st.st_size)
        except OSError:
            stamp = None
    key = repr((sorted(d.items()), float(length), stamp))
    if key not in _BUILT:
        if len(_BUILT) > 8:
            _BUILT.clear()
        _BUILT[key] = _build(d, length, where)
    return _BUILT[key]


def _build(d: Mapping[str, Any], length: float, where: str) -> Irregularity:
    d = check_irregularity(d, where)
    dx = d["dx"]
    n = size_of(d, length, where)
    grid = dx * np.arange(n)
    if "file" in d:
        x, r = _read_profile(d["file"], where)
        scale = float(d.get("scale", 1.0))
        return Irregularity(0.0, dx, scale * np.interp(grid, x, r, left=0.0, right=0.0), source=str(d["file"]))
    kmin, kmax, S = _band(d)
    nw = d["n_waves"]
    dk = (kmax - kmin) / nw
    k = kmin + (np.arange(nw) + 0.5) * dk
    amp = np.sqrt(2.0 * S(k) * dk)
    phi = np.random.default_rng(int(d["seed"])).uniform(0.0, 2.0 * np.pi, nw)
    r = np.zeros(n)
    for i0 in range(0, nw, 256):  # in blocks: n x 256 at a time
        sl = slice(i0, i0 + 256)
        r += np.cos(2.0 * np.pi * np.outer(grid, k[sl]) + phi[sl]) @ amp[sl]
    return Irregularity(0.0, dx, r, source=f"random (seed {int(d['seed'])})")


def variance(d: Mapping[str, Any]) -> float:
    """The variance (m^2) of the random profile of `d`: sum_i S(k_i) dk (module docstring)."""
    d = SECTION.check(d, "irregularity")
    kmin, kmax, S = _band(d)
    nw = d["n_waves"]
    dk = (kmax - kmin) / nw
    return float(np.sum(S(kmin + (np.arange(nw) + 0.5) * dk)) * dk)
