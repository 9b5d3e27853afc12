"""``filletfold.arrays``: helpers that must give what numpy gives."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.arrays import run_next, run_owners, run_starts, split_runs


@settings(max_examples=200, deadline=None)
@given(sizes=st.lists(st.integers(0, 5), min_size=1, max_size=30), width=st.sampled_from([0, 2, 3]))
def test_split_runs_is_np_split(sizes, width):
    """The runs of ``np.split`` (their values and shapes), as views of the array, for equal
    runs (the reshape), mixed and empty ones, of 1D and 2D arrays."""
    cuts = np.cumsum(sizes)[:-1]
    n = int(np.sum(sizes))
    values = np.arange(n * max(width, 1)).reshape((n, width) if width else (n,))
    want = np.split(values, cuts)
    got = split_runs(values, cuts)
    assert len(got) == len(want)
    for a, b in zip(got, want, strict=True):
        assert a.shape == b.shape and np.array_equal(a, b)
        assert a.size == 0 or np.shares_memory(a, values)


@given(st.lists(st.integers(0, 6), max_size=30))
def test_run_starts_and_owners_describe_the_runs(sizes):
    """Each run ``k`` of the flat array is ``[starts[k], starts[k + 1])``, every entry in it
    is owned by ``k``, and split_runs at the inner starts gives runs of those sizes."""
    starts, owners = run_starts(sizes), run_owners(sizes)
    assert starts.dtype == owners.dtype == np.int64
    assert starts.tolist() == [0, *np.cumsum(sizes, dtype=np.int64).tolist()]
    assert len(owners) == starts[-1] == sum(sizes)
    for k, (a, b) in enumerate(itertools.pairwise(starts)):
        assert (owners[a:b] == k).all()
    runs = split_runs(np.arange(starts[-1]), starts[1:-1])
    assert [len(r) for r in runs] == (list(sizes) if sizes else [0])


@settings(max_examples=50, deadline=None)
@given(st.lists(st.integers(1, 6), max_size=8))
def test_run_next_closes_every_run_into_a_loop(sizes):
    start = run_starts(sizes)
    nxt = run_next(start)
    expected = [
        a + (i + 1) % (b - a) for a, b in itertools.pairwise(start.tolist()) for i in range(b - a)
    ]
    assert nxt.tolist() == expected
