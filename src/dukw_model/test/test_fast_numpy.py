"""The wrapper-free numpy entries give the public functions' results, bit for bit."""
import numpy as np

from dukw_model import fast_numpy as fnp


def test_each_entry_gives_the_public_functions_bits():
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(5, 7)), rng.normal(size=7)
    assert np.array_equal(fnp.dot(a, b), np.dot(a, b))
    assert np.array_equal(fnp.clip(b, -0.3, 0.4), np.clip(b, -0.3, 0.4))
    xp = np.sort(rng.normal(size=9))
    assert np.array_equal(fnp.interp(b, xp, xp ** 2), np.interp(b, xp, xp ** 2))
    assert fnp.max_of(b) == b.max() and fnp.sum_of(b) == b.sum()


def test_new_tuple_builds_a_named_tuple_from_all_its_values():
    from typing import NamedTuple

    class Pair(NamedTuple):
        a: float
        b: float

    assert fnp.new_tuple(Pair, (1.0, 2.0)) == Pair(1.0, 2.0)
    assert type(fnp.new_tuple(Pair, (1.0, 2.0))) is Pair
