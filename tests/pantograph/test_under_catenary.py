"""The pantograph scene under the EN 50318 catenary instead of the ram: only the input changes."""

import pytest

from mbsuite import ParameterError, load_scene, run


def test_supercritical_speed_is_refused_before_integrating():
    sc = load_scene("pantograph/under_catenary").replace(input={"speed": 500.0})
    with pytest.raises(ParameterError, match="speed"):
        run(sc)


@pytest.mark.slow
def test_under_catenary_mujoco_and_reference_agree():
    """Both pantograph paths under the same wire at 250 km/h: the same static force and sigma within 0.1 N."""
    sc = load_scene("pantograph/under_catenary")
    mj = run(sc)
    ref = run(sc.replace(solver={"engine": "reference"}))
    assert mj.stats["static_contact_force"] == pytest.approx(ref.stats["static_contact_force"], abs=1e-6)
    assert mj.stats["sigma"] == pytest.approx(ref.stats["sigma"], abs=0.1)
    assert mj.stats["Fm"] == pytest.approx(ref.stats["Fm"], abs=0.1)
    assert 80.0 < mj.stats["Fm"] < 100.0  # the thesis' supply pressure gives ~89 N static uplift
