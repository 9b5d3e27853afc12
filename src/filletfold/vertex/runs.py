"""Reductions over consecutive runs of a flat array (the sides of many vertices, one vertex
after another), each run giving the same float as when reduced alone."""

from __future__ import annotations

import numpy as np

from ..arrays import run_starts

__all__ = ["run_means", "run_sums"]


def run_sums(values: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """(n,) sum of each of ``n`` consecutive runs of ``values`` of lengths ``counts``, each
    the same float as ``np.sum`` of the run alone (runs of equal length reduced together, row
    by row, as numpy reduces a run alone; ``np.add.reduceat`` would sum in another order).
    """
    out = np.empty(len(counts))
    first = run_starts(counts)[:-1]
    for c in np.unique(counts).tolist():
        which = np.flatnonzero(counts == c)
        out[which] = values[first[which, None] + np.arange(c)].sum(axis=1)
    return out


def run_means(values: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """(n,) mean of each of ``n`` consecutive runs of ``values`` of lengths ``counts``, each
    the same float as ``np.mean`` of the run alone (:func:`run_sums` over the counts)."""
    return run_sums(values, counts) / counts
