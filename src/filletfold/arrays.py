"""Small array helpers shared by the stages, and the ragged arrays they all use.

A *ragged array* holds ``n`` runs of different lengths (the corners of polygons, the sides of
vertices, the samples of arcs) one run after another in one flat array. Its ``sizes`` (n,)
give each run's length; :func:`run_starts` where each run starts (and the end),
:func:`run_owners` which run each flat entry belongs to, :func:`run_next` each entry's next in
its run read as a closed loop (a polygon's next corner), :func:`split_runs` the runs as views.
"""

from __future__ import annotations

import itertools

import numpy as np

__all__ = ["round_significant", "run_next", "run_owners", "run_starts", "split_runs"]


def run_starts(sizes) -> np.ndarray:
    """(n + 1,) int64: where each run of a ragged array with run lengths ``sizes`` (n,) starts
    in the flat array, then the end (``run_starts(sizes)[:-1]`` the first entry of each
    run, ``np.diff`` of it the sizes again)."""
    sizes = np.asarray(sizes, dtype=np.int64).reshape(-1)
    out = np.zeros(len(sizes) + 1, dtype=np.int64)
    np.cumsum(sizes, out=out[1:])
    return out


def run_next(start) -> np.ndarray:
    """(start[-1],) int64: the index of each entry's next entry in its run, the last entry of
    a run pointing back to the run's first: every run read as a closed loop (the next corner
    of each polygon). ``start`` is :func:`run_starts` of the (nonzero) sizes."""
    start = np.asarray(start, dtype=np.int64).reshape(-1)
    nxt = np.arange(1, int(start[-1]) + 1, dtype=np.int64)
    nxt[start[1:] - 1] = start[:-1]
    return nxt


def run_owners(sizes) -> np.ndarray:
    """(sum(sizes),) int64: the run each entry of a ragged array with run lengths ``sizes``
    (n,) belongs to (``[0, 0, 1, 2, 2, 2]`` for sizes ``[2, 1, 3]``)."""
    sizes = np.asarray(sizes, dtype=np.int64).reshape(-1)
    return np.repeat(np.arange(len(sizes), dtype=np.int64), sizes)


def split_runs(values: np.ndarray, cuts) -> list[np.ndarray]:
    """``np.split(values, cuts)``: the runs of ``values`` (along its first axis) between the
    indices ``cuts`` (ascending), as views: one reshape when every run has the same nonzero
    length (triangles, tab outlines), plain slices otherwise. ``np.split`` slices every run
    through two ``swapaxes`` calls, which took 0.6 s on 100k triangles and 0.4 s of a
    5,051-vertex design's export.

    Parameters
    ----------
    values : (n, ...) array
    cuts : (k,) int
        Where each run after the first starts (``np.cumsum(sizes)[:-1]``, ``start[1:-1]``).

    Returns
    -------
    list of array
        ``k + 1`` runs.
    """
    values = np.asarray(values)
    bounds = np.concatenate([[0], np.asarray(cuts, dtype=np.int64).reshape(-1), [len(values)]])
    size = np.diff(bounds)
    if size[0] > 0 and (size == size[0]).all():
        return list(values.reshape(len(size), int(size[0]), *values.shape[1:]))
    return [values[a:b] for a, b in itertools.pairwise(bounds.tolist())]


def round_significant(x: np.ndarray, digits: int) -> np.ndarray:
    """``x`` (any shape, finite) with each value rounded to ``digits`` significant digits
    as ``%g`` prints it (``-0.0`` becomes ``0.0``): what a file that holds ``x`` so gives its
    reader."""
    x = np.asarray(x, dtype=float)
    flat = (x + 0.0).ravel().tolist()
    text = (f"%.{int(digits)}g " * len(flat)) % tuple(flat)
    return np.array(text.split(), dtype=float).reshape(x.shape) + 0.0
