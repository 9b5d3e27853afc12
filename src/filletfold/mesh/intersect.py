"""Self-intersection of polygon surfaces (segment-triangle tests, vectorised)."""

from __future__ import annotations

import numpy as np

from ..tolerances import tol


def crossing_triangle_pairs(v: np.ndarray, faces) -> int:
    """Number of pairs of vertex-disjoint triangles (faces fanned) that intersect.

    Parameters
    ----------
    v : (n, 3) float
    faces : sequence of (k,) int
        Planar polygons (fanned from their first corner).

    Returns
    -------
    int
        0 for a surface without self-intersection (triangles sharing a vertex are skipped).
    """
    tri = np.array([[f[0], f[k], f[k + 1]] for f in faces for k in range(1, len(f) - 1)])
    p = v[tri]
    lo, hi = p.min(axis=1), p.max(axis=1)
    i, j = np.triu_indices(len(tri), 1)
    near = (lo[i] <= hi[j]).all(axis=1) & (lo[j] <= hi[i]).all(axis=1)
    i, j = i[near], j[near]
    apart = ~(tri[i][:, :, None] == tri[j][:, None, :]).any(axis=(1, 2))
    i, j = i[apart], j[apart]
    hit = np.zeros(len(i), dtype=bool)
    for a, b in ((i, j), (j, i)):
        for k in range(3):
            hit |= segment_hits_triangle(p[a, k], p[a, (k + 1) % 3], p[b])
    return int(hit.sum())


def segment_hits_triangle(s0: np.ndarray, s1: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(n,) bool: segment ``s0[i] s1[i]`` meets triangle ``t[i]`` (Moller-Trumbore)."""
    d = s1 - s0
    e1 = t[:, 1] - t[:, 0]
    e2 = t[:, 2] - t[:, 0]
    h = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, h)
    scale = np.linalg.norm(d, axis=1) * np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1)
    ok = np.abs(det) > tol.parallel * scale  # not parallel to the triangle's plane
    det = np.where(ok, det, 1.0)
    s = s0 - t[:, 0]
    u = np.einsum("ij,ij->i", s, h) / det
    q = np.cross(s, e1)
    w = np.einsum("ij,ij->i", d, q) / det
    along = np.einsum("ij,ij->i", e2, q) / det
    eps = tol.relative
    return (
        ok & (u >= -eps) & (w >= -eps) & (u + w <= 1 + eps) & (along >= -eps) & (along <= 1 + eps)
    )
