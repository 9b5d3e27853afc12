"""Reductions over consecutive runs (:mod:`filletfold.vertex.runs`): each run's sum and mean
are the very floats ``np.sum`` and ``np.mean`` give for that run alone, whatever the other
runs' lengths, and runs of length 0 sum to 0."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.vertex.runs import run_means, run_sums

#: Values of very different sizes, so that a different summation order gives other bits.
values_st = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False) | st.floats(-1e-6, 1e-6)


@st.composite
def runs(draw, min_count: int = 0):
    counts = draw(st.lists(st.integers(min_count, 12), max_size=20))
    values = draw(st.lists(values_st, min_size=sum(counts), max_size=sum(counts)))
    return np.array(values, dtype=float), np.array(counts, dtype=np.int64)


def loop_reduce(values: np.ndarray, counts: np.ndarray, reduce) -> np.ndarray:
    """The plain loop: each run reduced alone."""
    out, at = [], 0
    for c in counts.tolist():
        out.append(reduce(values[at : at + c]))
        at += c
    return np.array(out, dtype=float)


@settings(max_examples=100, deadline=None)
@given(runs())
def test_run_sums_are_the_sums_of_each_run_alone(data):
    values, counts = data
    got = run_sums(values, counts)
    assert got.shape == counts.shape and got.dtype == np.float64
    np.testing.assert_array_equal(got, loop_reduce(values, counts, np.sum))


@settings(max_examples=100, deadline=None)
@given(runs(min_count=1))
def test_run_means_are_the_means_of_each_run_alone(data):
    values, counts = data
    got = run_means(values, counts)
    assert got.shape == counts.shape
    np.testing.assert_array_equal(got, loop_reduce(values, counts, np.mean))


@settings(max_examples=50, deadline=None)
@given(runs(min_count=1), st.integers(0, 10**6))
def test_a_run_does_not_depend_on_its_neighbours(data, seed):
    """Moving the runs into another order moves their sums, bit for bit."""
    values, counts = data
    first = np.cumsum(counts) - counts
    order = np.random.default_rng(seed).permutation(len(counts))
    shuffled = np.concatenate(
        [values[first[k] : first[k] + counts[k]] for k in order] or [np.zeros(0)]
    )
    np.testing.assert_array_equal(
        run_sums(shuffled, counts[order]), run_sums(values, counts)[order]
    )


def test_the_order_of_summation_is_numpys():
    """A run long enough for numpy's pairwise summation, where the left-to-right sum differs."""
    rng = np.random.default_rng(2)
    values = rng.normal(size=300) * 10.0 ** rng.integers(-8, 8, size=300)
    counts = np.array([1, 299])
    assert sum(values[1:].tolist()) != np.sum(values[1:])  # the orders give other bits here
    got = run_sums(values, counts)
    assert got[1] == np.sum(values[1:])
    assert got[0] == values[0]


def test_empty_runs():
    assert run_sums(np.zeros(0), np.zeros(0, dtype=np.int64)).shape == (0,)
    assert run_means(np.zeros(0), np.zeros(0, dtype=np.int64)).shape == (0,)
    got = run_sums(np.array([1.0, 2.0, 3.0]), np.array([0, 2, 0, 1, 0]))
    np.testing.assert_array_equal(got, [0.0, 3.0, 0.0, 3.0, 0.0])
    # the mean of an empty run is np.mean's: NaN
    with np.errstate(invalid="ignore"):
        mean = run_means(np.array([4.0]), np.array([0, 1]))
    assert np.isnan(mean[0]) and mean[1] == 4.0
