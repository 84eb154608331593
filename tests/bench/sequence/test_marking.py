import itertools

import numpy as np
import pytest

from bench.sequence.marking import doerfler, mark, maximum


def test_doerfler_marks_a_minimal_bulk_set():
    rng = np.random.default_rng(3)
    eta2 = rng.exponential(size=9)
    for theta in (0.2, 0.5, 0.8):
        marked = doerfler(eta2, theta)
        # sums of 9 numbers O(1) in another order than the marker's: equal to ~10 ulps, so
        # 1e-12 relative slack both ways
        bulk = theta * eta2.sum()
        assert eta2[marked].sum() >= bulk * (1 - 1e-12)
        # brute force: no smaller set reaches the bulk
        smaller = [c for k in range(len(marked)) for c in itertools.combinations(range(9), k)
                   if eta2[list(c)].sum() > bulk * (1 + 1e-12)]
        assert not smaller


def test_maximum_marking():
    eta2 = np.array([1.0, 4.0, 0.25, 3.9])
    assert list(maximum(eta2, 0.5)) == [0, 1, 3]  # eta_T >= 0.5 * 2 = 1


@pytest.mark.parametrize("marking, theta, message", [
    ("bulk", 0.5, "marking='bulk' is not one of doerfler, maximum"),
    ("doerfler", 0.0, r"theta=0.0 is not in \(0, 1\]"),
    ("doerfler", 1.5, r"theta=1.5 is not in \(0, 1\]"),
])
def test_bad_marking_parameters(marking, theta, message):
    with pytest.raises(ValueError, match=message):
        mark(np.ones(3), marking, theta)


def test_marking_refuses_nan():
    with pytest.raises(ValueError, match="NaN"):
        mark(np.array([1.0, np.nan]), "doerfler", 0.5)
