"""The one number formatter of generated model files reads back exactly (or to its stated digits)."""

import math

import numpy as np

from mbsuite.modeltext import number


def test_shortest_text_reads_back_the_same_double():
    rng = np.random.default_rng(7)
    xs = np.concatenate([rng.standard_normal(2000) * 10.0 ** rng.integers(-12, 12, 2000), [0.1 + 0.2, 1e-300, -0.0]])
    for x in xs:
        assert float(number(x)) == x and math.copysign(1.0, float(number(x))) == math.copysign(1.0, x)


def test_rounded_text_has_the_stated_digits_and_an_unsigned_zero():
    assert number(0.1 + 0.2, 15) == "0.3" and number(2.0 / 3.0, 6) == "0.666667"
    assert number(-0.0, 15) == "0" and number(0.0, 15) == "0" and number(-1e-20, 3) == "-1e-20"
    rng = np.random.default_rng(8)
    for x in rng.standard_normal(500) * 1e3:
        assert abs(float(number(x, 15)) - x) <= 5e-15 * abs(x)
