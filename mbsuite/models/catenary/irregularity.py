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
from ...limits import real
from .line import Irregularity

IRREGULARITY_KEYS = ("file", "scale", "seed", "rms", "wavelength_min", "wavelength_max", "psd", "n_waves", "dx")
DEFAULT_DX = 0.05
DEFAULT_WAVES = 2000


def _num(d: Mapping[str, Any], key: str, where: str, lo: float = 0.0, lo_open: bool = True,
         default: float | None = None) -> float:
    if key not in d:
        if default is None:
            raise SceneError(f"{where}: {key} is missing")
        return default
    v = real(d[key])
    if v is None or not math.isfinite(v) or (v <= lo if lo_open else v < lo):
        raise SceneError(f"{where}: {key} = {d[key]!r} must be a finite number {'>' if lo_open else '>='} {lo:g}")
    return float(v)


def check_irregularity(d: Any, where: str) -> None:
    """Check an irregularity table (module docstring) without building it: keys, numbers, the file's columns."""
    if not isinstance(d, Mapping):
        raise SceneError(f"{where} must be a table with keys {list(IRREGULARITY_KEYS)}")
    bad = sorted(set(d) - set(IRREGULARITY_KEYS))
    if bad:
        raise SceneError(f"{where}: unknown key(s) {bad}; valid keys: {list(IRREGULARITY_KEYS)}")
    if "file" in d:
        extra = sorted(set(d) - {"file", "scale", "dx"})
        if extra:
            raise SceneError(f"{where}: {extra} belong to a random profile; a profile from a file reads file, "
                             "scale, dx")
        _read_profile(d["file"], where)
        if "scale" in d:
            v = real(d["scale"])
            if v is None or not math.isfinite(v):
                raise SceneError(f"{where}: scale = {d['scale']!r} must be a finite number")
    else:
        if "seed" not in d or real(d["seed"]) is None or int(real(d["seed"])) != real(d["seed"]) or d["seed"] < 0:
            raise SceneError(f"{where}: a random profile needs seed = a non-negative integer (got "
                             f"{d.get('seed')!r}); or give file = a profile CSV")
        if ("psd" in d) == ("rms" in d):
            raise SceneError(f"{where}: give either rms (with wavelength_min, wavelength_max) or psd = [[k, S], ...]")
        if "scale" in d:
            raise SceneError(f"{where}: scale is read only with file")
        _band(d, where)
    dx = _num(d, "dx", where, default=DEFAULT_DX)
    if "file" not in d:
        kmax = _band(d, where)[1]
        if dx > 1.0 / (8.0 * kmax) * (1 + 1e-12):
            raise SceneError(f"{where}: dx = {dx:g} m must be at most an eighth of the shortest wavelength "
                             f"({1.0 / kmax:g} m): <= {1.0 / (8.0 * kmax):g} m")


def _band(d: Mapping[str, Any], where: str) -> tuple[float, float, Any]:
    """(k_min, k_max, S(k)) of a random profile."""
    if "psd" in d:
        tab = d["psd"]
        try:
            a = np.asarray(tab, dtype=float)
        except (TypeError, ValueError):
            a = np.zeros((0,))
        if a.ndim != 2 or a.shape[1] != 2 or a.shape[0] < 2 or not np.all(np.isfinite(a)) or np.any(a <= 0) \
                or np.any(np.diff(a[:, 0]) <= 0):
            raise SceneError(f"{where}: psd must be >= 2 rows [k (cycles/m), S (m^2 m)] with k increasing and all "
                             "values positive")
        lk, ls = np.log(a[:, 0]), np.log(a[:, 1])
        return float(a[0, 0]), float(a[-1, 0]), lambda k: np.exp(np.interp(np.log(k), lk, ls))
    lmin = _num(d, "wavelength_min", where)
    lmax = _num(d, "wavelength_max", where)
    if not lmax > lmin:
        raise SceneError(f"{where}: wavelength_max = {lmax:g} m must exceed wavelength_min = {lmin:g} m")
    rms = _num(d, "rms", where, lo_open=False)
    kmin, kmax = 1.0 / lmax, 1.0 / lmin
    s = rms * rms / (kmax - kmin)
    return kmin, kmax, lambda k: np.full(np.shape(k), s)


def _read_profile(fname: Any, where: str) -> tuple[np.ndarray, np.ndarray]:
    if not isinstance(fname, str):
        raise SceneError(f"{where}: file = {fname!r} must be a file name")
    path = Path(fname)
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
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
    check_irregularity(d, where)
    dx = _num(d, "dx", where, default=DEFAULT_DX)
    n = int(math.floor(length / dx + 1e-9)) + 1
    grid = dx * np.arange(n)
    if "file" in d:
        x, r = _read_profile(d["file"], where)
        scale = float(real(d.get("scale", 1.0)))
        return Irregularity(0.0, dx, scale * np.interp(grid, x, r, left=0.0, right=0.0), source=str(d["file"]))
    kmin, kmax, S = _band(d, where)
    nw = int(_num(d, "n_waves", where, default=DEFAULT_WAVES))
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
    kmin, kmax, S = _band(d, "irregularity")
    nw = int(_num(d, "n_waves", "irregularity", default=DEFAULT_WAVES))
    dk = (kmax - kmin) / nw
    return float(np.sum(S(kmin + (np.arange(nw) + 0.5) * dk)) * dk)
