"""Linear pantographs that describe no pantograph are refused with the reason, against hand-made cases:
unstable (a pole of A with a real part >= 0; one real one only when stated: a negative static stiffness), not passive
(Im G(j w) > 0: the head would feed energy to the wire), a non-positive static force, a negative mass, a negative base
spring not stated; pressed on the wire, the pantograph and the wire's static stiffness together unstable. The
declarations take numpy users' numbers."""

from __future__ import annotations

import numpy as np
import pytest

from mbsuite.components.linear_pantograph import LumpedParams, TransferParams, lumped
from mbsuite.errors import ParameterError


def test_an_unstable_transfer_function_is_refused_naming_its_pole():
    """G(s) = 1 / (s - 1): one real pole at +1 and G(0) = -1 m/N (a negative static stiffness). Without the statement
    it is refused naming the pole; stated, it is a pantograph held up by its wire. G(s) = -1 / (s - 1) has the same
    pole with G(0) = +1: no negative static stiffness explains it, refused even when stated."""
    with pytest.raises(ParameterError, match=r"real pole\(s\) \[1.0\] 1/s >= 0.*negative_static_stiffness = true"):
        TransferParams.from_tf([1.0], [1.0, -1.0], 10.0)
    assert TransferParams.from_tf([1.0], [1.0, -1.0], 10.0, negative_static_stiffness=True).F0 == 10.0
    with pytest.raises(ParameterError, match=r"real pole\(s\) \[1.0\].*G\(0\) = 1 m/N"):
        TransferParams.from_tf([-1.0], [1.0, -1.0], 10.0, negative_static_stiffness=True)


def test_a_growing_oscillation_is_refused_even_when_stated():
    """s^2 - 2 s + 100: poles 1 +- 9.95j (negative damping), refused with or without the statement; s^2 + 2 s + 500
    (a 3.56 Hz mode with 4.5 % damping) is a pantograph."""
    for stated in (False, True):
        with pytest.raises(ParameterError, match=r"unstable: pole\(s\) \[\(1\+9.949874j\), \(1-9.949874j\)\]"):
            TransferParams.from_tf([1.0], [1.0, -2.0, 100.0], 90.0, negative_static_stiffness=stated)
    ok = TransferParams.from_tf([0.1], [1.0, 2.0, 500.0], 90.0)
    assert abs(ok.receptance(np.array([0.0]))[0] - 0.1 / 500.0) < 1e-15


def test_a_non_passive_transfer_function_is_refused_naming_the_frequency():
    """G(s) = (1 - s) / (s + 1)^2 is stable (a double pole at -1) but Im G(j w) = (w^3 - 3 w) / (1 + w^2)^2 > 0 for
    w > sqrt 3 (f > 0.2757 Hz): the head would give energy to the wire there. The check's grid (601 points from 1 mHz
    to 1 kHz, 2.3 % apart) finds it: the lowest frequency named is the first grid point above sqrt(3) / (2 pi) Hz."""
    with pytest.raises(ParameterError, match=r"not passive: Im G = .* > 0 at .* Hz, the lowest") as err:
        TransferParams.from_tf([-1.0, 1.0], [1.0, 2.0, 1.0], 90.0)
    f_named = float(str(err.value).split(" Hz, the lowest")[0].rsplit(" at ", 1)[1])
    assert np.sqrt(3) / (2 * np.pi) < f_named <= np.sqrt(3) / (2 * np.pi) * 10 ** 0.01 * 1.0001
    w = 2 * np.pi * 0.5
    g = (1 - 1j * w) / (1j * w + 1) ** 2
    assert g.imag == pytest.approx((w ** 3 - 3 * w) / (1 + w * w) ** 2) and g.imag > 0


@pytest.mark.parametrize("F0", [0.0, -5.0])
def test_a_non_positive_static_force_is_refused(F0):
    with pytest.raises(ParameterError, match=rf"F0 = {F0!r} in transfer-function pantograph is invalid; valid: "
                                             r"\(0, 10000\] N"):
        TransferParams.from_tf([0.1], [1.0, 2.0, 500.0], F0)
    with pytest.raises(ParameterError, match=r"F0 = .* in lumped pantograph is invalid"):
        LumpedParams((10.0,), (1e3,), (5.0,), F0)


def test_lumped_masses_springs_and_the_base_spring():
    """m = -1 refused; a negative base spring refused unless stated, stated without one refused; k = [100, -200]:
    1 + k_n / k_1 = -1 <= 0, the static force F0 / -1 not positive: refused."""
    with pytest.raises(ParameterError,
                       match=r"m\[0\] = -1.0 in lumped pantograph is invalid; valid: \[1e-06, 10000\] kg"):
        LumpedParams((-1.0,), (1e3,), (5.0,), 90.0)
    with pytest.raises(ParameterError, match=r"base spring k\[1\] = -30.0 N/m is negative.*negative_base_spring"):
        LumpedParams((10.0, 10.0), (1e4, -30.0), (10.0, 100.0), 90.0)
    p = LumpedParams((10.0, 10.0), (1e4, -30.0), (10.0, 100.0), 90.0, negative_base_spring=True)
    assert p.static_force() == pytest.approx(90.0 / (1.0 - 30.0 / 1e4), rel=1e-15)
    with pytest.raises(ParameterError, match=r"negative_base_spring = true, but the base spring k\[1\] = 30.0"):
        LumpedParams((10.0, 10.0), (1e4, 30.0), (10.0, 100.0), 90.0, negative_base_spring=True)
    with pytest.raises(ParameterError, match=r"1 \+ k_n sum 1/k_i = -1 <= 0"):
        LumpedParams((10.0, 10.0), (100.0, -200.0), (10.0, 100.0), 90.0, negative_base_spring=True)


def test_pressed_on_a_soft_wire_a_negative_base_spring_is_unstable():
    """m = 10, 10 kg, k = 1e4, -100 N/m: the chain's static stiffness is 1 / (1/1e4 - 1/100) = -101.0 N/m. On a wire
    of 50 N/m the pair has -51 N/m: a real pole > 0, refused naming it; on 1000 N/m (+899 N/m) it stands. By hand:
    the chain pushes F0s - 101 y with F0s = F0 / (1 + k_n / k_1), the wire 1000 y, so f = 1000 F0s / (1000 - 101)."""
    p = LumpedParams((10.0, 10.0), (1e4, -100.0), (10.0, 100.0), 90.0, negative_base_spring=True)
    with pytest.raises(ParameterError, match=r"pressed on the wire \(static stiffness 50 N/m\) is unstable: pole"):
        lumped(p).static(0.0, 50.0)
    f = lumped(p).static(0.0, 1000.0)
    F0s = 90.0 / (1.0 - 100.0 / 1e4)
    assert f == pytest.approx(F0s * 1000.0 / (1000.0 - 101.0101010101), rel=1e-9)


def test_numpy_users_numbers():
    a = LumpedParams(np.array([10.0, 12.0]), np.array([9000.0, 300.0]), (np.float32(30.0), 60.0), np.array(100.0))
    b = LumpedParams((10.0, 12.0), (9000.0, 300.0), (30.0, 60.0), 100.0)
    assert a == b
    t = TransferParams(np.array([[0.0, 1.0], [-500.0, -2.0]]), np.array([0.0, 0.1]), [1.0, np.int64(0)], 90)
    assert t.A == ((0.0, 1.0), (-500.0, -2.0)) and t.C == (1.0, 0)
    for bad in (True, float("nan"), float("inf"), "90"):
        with pytest.raises(ParameterError, match="F0"):
            LumpedParams((10.0,), (1e3,), (5.0,), bad)


def test_a_rigid_body_pole_is_refused_in_a_transfer_function():
    """G(s) = 1 / (s (s + 1)): a pole at 0, G(0) infinite (no static stiffness). A transfer-function pantograph's
    receptance is finite at 0 Hz; a constant uplift is the lumped chain with k_n = 0 (accepted: its rigid-body mode is
    held by the wire, the static force F0 / (1 + 0) = F0)."""
    with pytest.raises(ParameterError, match=r"A has 1 pole\(s\) at 0 \(a rigid-body mode"):
        TransferParams.from_tf([1.0], [1.0, 1.0, 0.0], 90.0)
    assert LumpedParams((10.0, 10.0), (1e4, 0.0), (10.0, 100.0), 90.0).static_force() == 90.0


def test_a_negative_damper_above_the_grid_is_refused_by_the_high_frequency_rule():
    """G(s) = 1 / (s + 1)^2 - e / (s + 1), e = 1e-8: stable (a double pole at -1); Im G(j w) = -2 w / (1 + w^2)^2 +
    e w / (1 + w^2) > 0 only for w > sqrt(2 / e - 1) = 14142 rad/s (2251 Hz), above the 1 kHz grid. Exactly: C B = -e,
    the head a negative damper at high frequency. With e = 0 (C B = 0, C A B = 1: a 1 kg head) it is accepted."""
    e = 1e-8
    w = np.sqrt(2 / e - 1)
    for x, sign in ((0.99 * w, -1), (1.01 * w, 1)):  # the hand computation: the sign of Im G changes at w
        assert np.sign(-2 * x / (1 + x * x) ** 2 + e * x / (1 + x * x)) == sign
    with pytest.raises(ParameterError, match=r"not passive at high frequencies: C B = -1e-08 m/\(N s\) < 0"):
        TransferParams.from_tf([-e, 1.0 - e], [1.0, 2.0, 1.0], 90.0)
    ok = TransferParams.from_tf([1.0], [1.0, 2.0, 1.0], 90.0)
    A, B, C = ok.arrays()
    assert C @ B == 0.0 and C @ A @ B == pytest.approx(1.0)


def test_large_state_matrix_entries_are_numbers_not_errors():
    """A companion form's entries are the poles' products (an order-10 fit's exceed 1e12): any finite number. G(s) =
    1 / (s + 1e13): G(0) = 1e-13 m/N."""
    p = TransferParams([[-1e13]], [1.0], [1.0], 90.0)
    assert p.receptance(np.array([0.0]))[0] == pytest.approx(1e-13)
    with pytest.raises(ParameterError, match=r"A\[0\]\[0\] = inf in transfer-function pantograph is invalid"):
        TransferParams([[float("inf")]], [1.0], [1.0], 90.0)


def test_an_undamped_chain_stands_on_the_wire():
    """c = 0: lossless modes (neither growing nor decaying) are not refused under the wire; the static force is the
    chain's F0 / (1 + k_3 (1/k_1 + 1/k_2)) against a stiff wire (1e9 N/m: its compliance shifts it by < 1e-6)."""
    p = LumpedParams((5.0, 8.0, 12.0), (6000.0, 3000.0, 80.0), (0.0, 0.0, 0.0), 90.0)
    assert lumped(p).static(0.0, 1e9) == pytest.approx(90.0 / (1 + 80.0 * (1 / 6000.0 + 1 / 3000.0)), rel=1e-6)


def test_registry_pantograph_params_are_checked_by_their_declared_limits():
    """The Eppinger pantograph's `[pantograph] params`: a numpy scalar is the number it holds; a bool, NaN or text is
    refused naming the key."""
    from mbsuite.errors import SceneError
    from mbsuite.models.catenary.pantographs import validate_section

    out = validate_section({"params": {"Pg": np.float32(750000.0)}})["params"]["Pg"]
    assert out == 750000.0 and type(out) is float
    for bad in (True, float("nan"), "7.5e5"):
        with pytest.raises(SceneError, match=r"Pg = .* in \[pantograph\] params \(the 'eppinger' pantograph\)"):
            validate_section({"params": {"Pg": bad}})
