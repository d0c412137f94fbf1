"""OSPA, GOSPA and OSPA(2) against hand-computed values and a brute-force evaluation of their
definitions over all assignments."""

import itertools
import math

import numpy as np
import pytest

import smc_lmb


def brute_ospa(x, y, c, p):
    """OSPA by enumerating every injection of the smaller set into the larger one."""
    x, y = (x, y) if len(x) <= len(y) else (y, x)
    m, n = len(x), len(y)
    if n == 0:
        return 0.0
    best = min(
        sum(min(c, np.linalg.norm(x[i] - y[j])) ** p for i, j in enumerate(perm))
        for perm in itertools.permutations(range(n), m)
    )
    return ((best + c**p * (n - m)) / n) ** (1 / p)


def brute_gospa(x, y, c, p):
    """GOSPA (α = 2): assigned pairs closer than c, every other point costs c^p / 2."""
    m, n = len(x), len(y)
    best = math.inf
    # Every partial matching: choose which truth points pair with which estimates.
    for k in range(min(m, n) + 1):
        for xs in itertools.combinations(range(m), k):
            for ys in itertools.permutations(range(n), k):
                d = [np.linalg.norm(x[i] - y[j]) for i, j in zip(xs, ys)]
                if any(v >= c for v in d):
                    continue
                cost = sum(v**p for v in d) + c**p / 2 * (m + n - 2 * k)
                best = min(best, cost)
    return best ** (1 / p)


def test_ospa_of_hand_made_sets():
    # {0, 10} against {1}, c = 5, p = 1: pair 0↔1 costs 1, the unpaired point c = 5; over 2.
    o = smc_lmb.ospa([[0.0], [10.0]], [[1.0]], c=5.0, p=1.0)
    assert o["distance"] == pytest.approx(3.0)
    assert o["localisation"] == pytest.approx(0.5)
    assert o["cardinality"] == pytest.approx(2.5)
    # Both empty: 0; one empty: c.
    assert smc_lmb.ospa(np.empty((0, 2)), np.empty((0, 2)), c=4.0)["distance"] == 0.0
    assert smc_lmb.ospa([[1.0, 2.0]], np.empty((0, 2)), c=4.0)["distance"] == pytest.approx(4.0)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("p", [1.0, 2.0])
def test_ospa_and_gospa_equal_brute_force(seed, p):
    rng = np.random.default_rng(seed)
    x = rng.uniform(-5, 5, (rng.integers(0, 5), 2))
    y = rng.uniform(-5, 5, (rng.integers(1, 5), 2))
    c = 3.0
    assert smc_lmb.ospa(x, y, c, p)["distance"] == pytest.approx(brute_ospa(x, y, c, p), abs=1e-9)
    assert smc_lmb.gospa(x, y, c, p)["distance"] == pytest.approx(brute_gospa(x, y, c, p), abs=1e-9)


def test_gospa_counts_misses_and_false_alarms():
    # Truth {0, 10}, estimate {1}, c = 4: pair 0↔1 (1), miss 10 (c/2 = 2) → 3.
    g = smc_lmb.gospa([[0.0], [10.0]], [[1.0]], c=4.0)
    assert g["distance"] == pytest.approx(3.0)
    assert (g["n_missed"], g["n_false"]) == (1, 0)


def test_ospa2_of_hand_made_tracks():
    nan = [math.nan, math.nan]
    truth = [np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]])]
    # An estimate 1 m off at every step: time average 1, one pair → 1.
    shifted = [truth[0] + [0.0, 1.0]]
    assert smc_lmb.ospa2(truth, shifted, c=5.0)["distance"] == pytest.approx(1.0)
    # An estimate that starts late (absent at steps 0, 1): d = (5 + 5 + 0 + 0) / 4 = 2.5.
    late = [np.array([nan, nan, [2.0, 0.0], [3.0, 0.0]])]
    assert smc_lmb.ospa2(truth, late, c=5.0)["distance"] == pytest.approx(2.5)
    # Window (2, 4): both present and equal → 0.
    assert smc_lmb.ospa2(truth, late, c=5.0, window=(2, 4))["distance"] == pytest.approx(0.0)
    # Two estimated tracks against one truth: (d̃ = 0 for the match + c for the extra) / 2.
    extra = late + [np.array([[50.0, 0.0]] * 4)]
    assert smc_lmb.ospa2(truth, extra, c=5.0, window=(2, 4))["distance"] == pytest.approx(2.5)
    series = smc_lmb.ospa2_series(truth, late, window_len=1, c=5.0)
    np.testing.assert_allclose(series, [5.0, 5.0, 0.0, 0.0])


def test_bad_arguments_raise_value_errors():
    with pytest.raises(ValueError, match="cut-off|c"):
        smc_lmb.ospa([[0.0]], [[1.0]], c=-1.0)
    with pytest.raises(ValueError, match="dimension"):
        smc_lmb.ospa([[0.0]], [[1.0, 2.0]], c=1.0)
    with pytest.raises(ValueError, match="2-D"):
        smc_lmb.ospa(np.zeros((2, 2, 2)), [[1.0]], c=1.0)
