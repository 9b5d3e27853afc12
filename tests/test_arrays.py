"""``filletfold.arrays``: helpers that must give what numpy gives."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.arrays import split_runs


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
