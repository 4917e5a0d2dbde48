"""The orifice's laminar band is converged: dividing its width by 10 changes F1, F2, HD by < 0.1 % in amplitude and
< 1e-3 rad in phase, at the frequencies of the sweep and during the start from P = Ps (pantograph/nonlinear_cylinder,
reference path). The hardest point is 1 Hz, where the pressure swing is smallest against the band (the study,
`scripts/pantograph_orifice_band.py`: every band's largest change over 1-30 Hz is at 1 Hz); 2 and 6 Hz follow."""

from __future__ import annotations

import numpy as np
import pytest

from mbsuite import load_scene
from mbsuite.errors import SceneError
from mbsuite.models.pantograph import orifice_band
from mbsuite.models.pantograph.params import PantographParams

WIDTH = 1.0 - PantographParams().r_laminar


@pytest.fixture(scope="module")
def scene():
    return load_scene("pantograph/nonlinear_cylinder")


def _worst(pts, a, b, freqs):
    by = {(p.width, p.f): p for p in pts}
    return [orifice_band.harmonic_changes(by[(a, f)], by[(b, f)]) for f in freqs]


# frequency: bounds on the (amplitude, phase in rad) change from the default band to a 10x narrower one, 5 s runs;
# measured (amplitude, phase) with the default band 1e-5 / with the 10x wider band 1e-4 (which must fail)
HARMONIC_BOUNDS = {
    1.0: (6e-4, 2e-4),    # 1.22e-4, 4.12e-5 (4.9x, 4.9x) / 3.6e-3, 5.2e-3
    2.0: (4e-5, 1.1e-5),  # 7.6e-6, 2.2e-6 (5.2x, 5.0x) / 7.9e-5, 1.9e-4
    6.0: (5e-6, 2e-5),    # 1.0e-6, 4.0e-6 (5.0x, 5.0x) / 3.1e-5, 3.4e-5
}


def test_band_width_below_one_minus_the_critical_ratio_of_the_scene_gamma(scene):
    """The study's band lies in subsonic flow of the scene's own gas: at gamma = 1.67 the critical ratio is
    (2/2.67)^(1.67/0.67) = 0.486669, so a width 0.5 (edge 0.5, wider than air's 1 - 0.528 allows) is accepted and
    0.52 refused, the message naming the limit 0.513331."""
    sc = scene.replace(params={"gamma": 1.67})
    assert orifice_band._scene_with_band(sc, 0.5).build_params().r_laminar == 0.5
    with pytest.raises(SceneError, match=r"width 0.52 must be in \(0, 0.513331\)"):
        orifice_band._scene_with_band(sc, 0.52)


def test_default_band_converged_at_hardest_frequencies(scene):
    """Default band (1e-5) vs a 10x narrower one at 1, 2 and 6 Hz, 5 s runs (2.5 s settling): each change is below
    its bound (HARMONIC_BOUNDS, about 5x the measured change), every bound below the criterion 1e-3. The bounds
    refuse the next wider band, 1e-4, at every one of the three frequencies; 1e-3 (the whole 2 Hz pressure swing,
    ~359 Pa, lies inside its 811 Pa) changes by 6 % at 1 Hz and 2.7 % at 2 Hz."""
    assert all(max(b) < orifice_band.TOLERANCE for b in HARMONIC_BOUNDS.values())
    short = scene.replace(solver={"duration": 5.0, "t_settle": 2.5})
    freqs = list(HARMONIC_BOUNDS)
    pts = orifice_band.sweep(short, [WIDTH, WIDTH / 10.0], freqs)
    for f, (amp, ph) in zip(freqs, _worst(pts, WIDTH, WIDTH / 10.0, freqs), strict=True):
        assert amp < HARMONIC_BOUNDS[f][0] and ph < HARMONIC_BOUNDS[f][1], f


def test_default_band_converged_at_supply_pressure_start(scene):
    """The start from P = Ps (dp = 0, where the unregularised law's slope is unbounded): the time histories of F1, F2,
    HD over the first second change by 9.7e-6 of their excursion when the band is narrowed 10x (band 1e-4: 1.3e-4,
    band 1e-3: 1.3e-3); bound 5e-5 (5.1x), below the criterion 1e-3 and refusing the band 1e-4."""
    assert orifice_band.start_change(scene, WIDTH) < 5e-5


@pytest.mark.slow
def test_default_band_converged_over_the_whole_sweep(scene):
    """Every frequency of 1-30 Hz (0.5 Hz grid), the scene's 10 s runs: the default band against a 10x narrower one
    (measured: <= 1.2e-4 in amplitude, 4.2e-5 rad in phase, both at 1 Hz; bounds 5e-4 and 2e-4, 4.2x and 4.8x); and
    the next wider band, 1e-4, fails the criterion 1e-3 (0.35 % at 1 Hz): the default is the widest converged band
    of the decades tried."""
    freqs = np.round(np.arange(1.0, 30.25, 0.5), 10)
    pts = orifice_band.sweep(scene, [10.0 * WIDTH, WIDTH, WIDTH / 10.0], freqs)
    for f, (amp, ph) in zip(freqs, _worst(pts, WIDTH, WIDTH / 10.0, freqs), strict=True):
        assert amp < 5e-4 and ph < 2e-4, f
    assert max(a for a, _ in _worst(pts, 10.0 * WIDTH, WIDTH, freqs)) > 2.0 * orifice_band.TOLERANCE
