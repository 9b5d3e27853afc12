"""Vertex classification and the vertex normal (paper sec. 2.5, 3.1).

The sign of the edge rows and the choice of ``sigma`` correct the paper (docs/method.md,
'Corrections to the paper', 1 and 2).

The vertex normal ``D`` maximises ``b`` subject to ``D . (-R_i) >= b`` for every incident edge
direction ``R_i`` (toward the vertex), ``D . (sigma N_f) >= b`` for every incident face and
``|D| = 1``. Both signs ``sigma`` are tried; the larger ``b`` wins (-1 on a tie). When neither
has ``b > 0`` no plane through the vertex has all its faces on one side: the vertex is a saddle.

Method, for all vertices at once. Write ``u_k`` for the vectors of one sign and ``K`` for their
convex hull. For a unit ``D``, ``min_k D . u_k = -h_K(-D)`` with ``h_K`` the support function,
so ``b = -min_{|n|=1} h_K(n)`` is the *signed distance* from the origin to ``K``:

* origin outside ``K`` (``b > 0``): ``b = |p*|`` and ``D = p* / |p*|`` with ``p*`` the
  min-norm point of ``K`` (minimax theorem). ``p*`` lies on a face of at most 3 of the ``u_k``
  and is found by a Gilbert-Johnson-Keerthi iteration run over all vertices in lockstep; it
  stops on the duality certificate ``min_k D . u_k >= |p|`` (to rounding), so the result is
  exact, not a local optimum;
* origin in ``K`` (``b <= 0``): ``-b`` is the distance from the origin to the nearest facet plane
  of ``K`` and ``D`` minus that facet's outward normal. Every such optimum is among a finite set
  of candidate directions (each ``u_k``, a direction normal to it, the min-norm point of each
  segment ``[u_i, u_j]``, both normals of each triangle ``u_i u_j u_l``), which are all evaluated
  (vectorised, ``O(k^4)`` per vertex: meant for the few saddle vertices). The same enumeration
  backs up the rare problems GJK does not certify.

A sign's exact bound is computed only when it can matter: GJK gives an upper bound ``|p|`` at
every step, and the sign ``+1`` stops as soon as that falls to the certified bound of ``-1``;
so at a convex or concave vertex only one sign is solved to the end, and only saddles (both
signs ``b <= 0``) are enumerated.
"""

from __future__ import annotations

from functools import cache
from itertools import combinations

import numpy as np

from ..errors import ParameterError
from ..tolerances import tol
from .runs import run_sums

# Numerical constants of the exact solvers below (rounding level, not modelling tolerances);
# lengths are relative to the largest |u_k| of the problem.
_ROUND = 64 * np.finfo(float).eps  # about 1.4e-14: origin "in K" when |p| <= _ROUND
_GAP = 1e3 * np.finfo(float).eps  # relative duality gap accepted as the GJK certificate
_MAX_ITER = 64  # GJK iterations; in 3D a handful is typical
_BLOCK = 1 << 22  # candidate-by-vector products per enumeration block (memory bound)


def vertex_normals(
    edge_dir: np.ndarray,
    face_normal: np.ndarray,
    edge_count: np.ndarray | None = None,
    face_count: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertex normals, bounds and signs of many vertices at once (sec. 3.1).

    Vertex ``v`` uses the rows ``edge_dir[v, :edge_count[v]]`` and
    ``face_normal[v, :face_count[v]]``; the other rows are padding and are not read (they may
    be NaN).

    Parameters
    ----------
    edge_dir : (n, k_e, 3) float
        Unit directions ``R_i`` toward the vertex of its incident edges, padded.
    face_normal : (n, k_f, 3) float
        Front unit normals of its incident faces, padded.
    edge_count : (n,) int, optional
        Number of edges of each vertex, ``0 <= edge_count <= k_e``; default ``k_e``.
    face_count : (n,) int, optional
        Number of faces of each vertex, ``0 <= face_count <= k_f``; default ``k_f``.
        Every vertex needs ``edge_count + face_count >= 1``.

    Returns
    -------
    vertex_normal : (n, 3) float
        Unit ``D`` (also where the bound is not positive).
    vertex_bound : (n,) float
        ``b = min_k D . u_k`` for the chosen sign (``<= tol.normal_bound`` means saddle).
    vertex_sigma : (n,) int
        -1 (apex on the back side) or +1 (front side): +1 only where its bound is larger than
        that of -1 by more than rounding (1.4e-14 times the longest vector).

    Raises
    ------
    ParameterError
        Shapes that do not match, counts out of range, or non-finite values.
    """
    edge_dir = _as_stack(edge_dir, "edge_dir")
    face_normal = _as_stack(face_normal, "face_normal")
    n, k_e, k_f = len(edge_dir), edge_dir.shape[1], face_normal.shape[1]
    if len(face_normal) != n:
        raise ParameterError(
            f"face_normal has {len(face_normal)} vertices, edge_dir {n}", name="face_normal"
        )
    edge_count = _counts(edge_count, n, k_e, "edge_count")
    face_count = _counts(face_count, n, k_f, "face_count")
    _check_finite(edge_dir, edge_count, "edge_dir")
    _check_finite(face_normal, face_count, "face_normal")
    if np.any(edge_count + face_count < 1):
        v = int(np.flatnonzero(edge_count + face_count < 1)[0])
        raise ParameterError(f"vertex {v} has no edge and no face", name="edge_count")
    blocks = [(k_e, edge_count), (k_f, face_count)]
    u, count = _pack(np.concatenate([-edge_dir, -face_normal], axis=1), blocks)
    u_plus, _ = _pack(np.concatenate([-edge_dir, face_normal], axis=1), blocks)
    u, count = np.concatenate([u, u_plus]), np.concatenate([count, count])
    # sets 0 ... n-1: sigma = -1; n ... 2n-1: sigma = +1
    tie = _ROUND * np.sqrt(np.einsum("mkx,mkx->mk", u[:n], u[:n]).max(axis=1))
    minus = _max_min_gjk(u[:n])
    # sigma = +1 wins only when its bound is over that of -1 by more than rounding (tie)
    plus = _max_min_gjk(u[n:], floor=np.where(minus[2], minus[1] + tie, -np.inf))
    d, b, certified, upper = (np.concatenate(x) for x in zip(minus, plus, strict=True))
    # a set needs its exact bound unless certified, or unable to win against the other sign's
    rival = np.roll(np.where(certified, b, -np.inf), n)
    lost = np.concatenate([upper[:n] < rival[:n] - tie, upper[n:] <= rival[n:] + tie])
    redo = ~certified & ~lost
    d[redo], b[redo] = _max_min_enumerate(u[redo], count[redo])
    b[~certified & lost] = -np.inf
    plus = b[n:] > b[:n] + tie
    return (
        np.where(plus[:, None], d[n:], d[:n]),
        np.where(plus, b[n:], b[:n]),
        np.where(plus, 1, -1),
    )


def vertex_normal(edge_dirs: np.ndarray, face_normals: np.ndarray):
    """Vertex normal, its bound and sign ``sigma`` for one vertex (see :func:`vertex_normals`).

    Parameters
    ----------
    edge_dirs : (n_e, 3) float
        Unit edge directions ``R_i`` toward the vertex.
    face_normals : (n_f, 3) float
        Front normals of the incident faces.

    Returns
    -------
    D : (3,) float
    b : float
        The max-min bound for the chosen ``sigma`` (``<= tol.normal_bound`` means saddle).
    sigma : int
        +1 (apex on the front side) or -1 (back side).
    """
    d, b, sigma = vertex_normals(np.asarray(edge_dirs)[None], np.asarray(face_normals)[None])
    return d[0], float(b[0]), int(sigma[0])


def max_min_directions(u: np.ndarray, count: np.ndarray | None = None):
    """Unit vectors ``D`` maximising ``min_k D . u_k``, for many sets of vectors at once.

    Parameters
    ----------
    u : (n, k, 3) float
        Vectors, padded: set ``i`` is ``u[i, :count[i]]``.
    count : (n,) int, optional
        ``1 <= count <= k``; default ``k``.

    Returns
    -------
    D : (n, 3) float
        A unit maximiser (also when the bound is not positive).
    b : (n,) float
        ``min_k D . u_k``: the signed distance from the origin to the hull of the ``u_k``; not
        positive when no open half-space contains all ``u_k``.
    """
    u = _as_stack(u, "u")
    count = _counts(count, len(u), u.shape[1], "count")
    if np.any(count < 1):
        raise ParameterError(f"set {int(np.argmin(count))} is empty", name="count")
    _check_finite(u, count, "u")
    u, count = _pack(u, [(u.shape[1], count)])
    d, b, certified, _ = _max_min_gjk(u)
    redo = ~certified
    d[redo], b[redo] = _max_min_enumerate(u[redo], count[redo])
    return d, b


def max_min_direction(u: np.ndarray) -> tuple[np.ndarray, float]:
    """Unit vector ``D`` maximising ``min_k D . u_k`` (one set; see :func:`max_min_directions`).

    Parameters
    ----------
    u : (k, 3) float
        Unit vectors.

    Returns
    -------
    D : (3,) float
        Unit direction (the best, also when the bound is not positive).
    b : float
        ``min_k D . u_k``; not positive when no open half-space contains all ``u_k``.
    """
    d, b = max_min_directions(np.asarray(u)[None])
    return d[0], float(b[0])


def _as_stack(a, name: str) -> np.ndarray:
    """(n, k, 3) float array, or ParameterError naming ``name``."""
    a = np.asarray(a, dtype=float)
    if a.ndim != 3 or a.shape[2] != 3:
        raise ParameterError(f"{name} must have shape (n, k, 3), not {a.shape}", name=name)
    return a


def _check_finite(a: np.ndarray, count: np.ndarray, name: str) -> None:
    """ParameterError naming ``name`` unless the rows ``a[i, :count[i]]`` are finite."""
    rows = np.arange(a.shape[1]) < count[:, None]
    if not np.all(np.isfinite(a[rows])):
        raise ParameterError(f"{name} has non-finite values", name=name)


def _counts(count, n: int, k: int, name: str) -> np.ndarray:
    """(n,) int counts in ``[0, k]`` (default ``k``), or ParameterError naming ``name``."""
    if count is None:
        return np.full(n, k)
    count = np.asarray(count)
    if count.shape != (n,) or not np.issubdtype(count.dtype, np.integer):
        raise ParameterError(
            f"{name} must be {n} integers, not {count.dtype} {count.shape}", name=name
        )
    if np.any((count < 0) | (count > k)):
        raise ParameterError(f"{name} must lie in [0, {k}]", name=name)
    return count


def _pack(u: np.ndarray, blocks: list) -> tuple[np.ndarray, np.ndarray]:
    """Gather each set's valid rows first and fill the rest with repeats of its first one.

    A repeated vector changes neither the hull nor ``min_k D . u_k``, so the solvers below need
    no masks.

    Parameters
    ----------
    u : (m, k, 3) float
        Padded blocks, one after the other along axis 1.
    blocks : list of (int, (m,) int)
        Each block's size and, per set, its number of valid (leading) rows; sizes sum to k.

    Returns
    -------
    packed : (m, k, 3) float
    count : (m,) int
        Valid rows of each set (``packed[i, :count[i]]``); at least 1.
    """
    m, k = u.shape[:2]
    slot = np.arange(k)
    src = np.zeros((m, k), dtype=np.intp)
    start, offset = np.zeros(m, dtype=np.intp), 0
    for size, count in blocks:
        here = (slot >= start[:, None]) & (slot < (start + count)[:, None])
        src = np.where(here, offset + slot - start[:, None], src)
        start, offset = start + count, offset + size
    src = np.where(slot < start[:, None], src, src[:, :1])
    return np.reshape(u, (-1, 3))[src + k * np.arange(m)[:, None]], start


def _max_min_gjk(u: np.ndarray, floor: np.ndarray | None = None):
    """Min-norm point ``p`` of each hull by Gilbert-Johnson-Keerthi, all sets in lockstep.

    Parameters
    ----------
    u : (m, k, 3) float
        Vector sets (padding by repeats only).
    floor : (m,) float, optional
        Give up on a set once ``|p| <= floor``: its bound cannot exceed ``floor`` then.

    Returns
    -------
    d : (m, 3) float
        ``p / |p|`` where certified (undefined elsewhere).
    b : (m,) float
        ``min_k d . u_k`` where certified (undefined elsewhere).
    certified : (m,) bool
        ``min_k p . u_k >= |p|^2 (1 - _GAP) - _ROUND scale^2`` with ``p`` in the hull (``scale``
        the largest ``|u_k|``): then ``0 <= |p| - b <= _GAP |p| + _ROUND scale^2 / |p|``, and
        ``b`` is the signed distance from the origin to the hull, to rounding.
    upper : (m,) float
        ``|p|`` for the last ``p``: the bound of every set is at most this. Sets whose hull
        holds the origin stop with ``upper <= _ROUND scale``.
    """
    m = len(u)
    d, b, upper = np.zeros((m, 3)), np.zeros(m), np.zeros(m)
    certified = np.zeros(m, bool)
    norm2 = np.einsum("mkx,mkx->mk", u, u)
    scale = np.sqrt(norm2.max(axis=1))
    give_up = _ROUND * scale if floor is None else np.maximum(floor, _ROUND * scale)
    live = np.arange(m)  # the sets still iterating; the arrays below are theirs
    start = np.argmin(norm2, axis=1)
    v = u[live, start]
    vv = vv_before = norm2[live, start]
    simplex = np.repeat(v[:, None], 4, axis=1)  # (m, 4, 3); unused slots hold old points of u
    ids = np.repeat(start[:, None], 4, axis=1)
    lam = np.zeros((m, 4))
    lam[:, 0] = 1.0
    for step in range(_MAX_ITER + 1):
        vn = np.sqrt(vv)
        upper[live] = vn
        dots = (u[live] @ v[:, :, None])[:, :, 0]
        w = np.argmin(dots, axis=1)
        done = np.min(dots, axis=1) >= vv * (1 - _GAP) - _ROUND * scale[live] ** 2
        done &= vn > give_up[live]
        d[live[done]] = v[done] / vn[done, None]
        certified[live[done]] = True
        # stop also when low enough, or stalled by rounding: w already in, or no decrease
        stop = done | (vn <= give_up[live]) | np.any(ids == w[:, None], axis=1)
        go = ~stop if step == 0 else ~stop & (vv < vv_before)
        live, vv, w, simplex, ids, lam = live[go], vv[go], w[go], simplex[go], ids[go], lam[go]
        if not len(live) or step == _MAX_ITER:
            break
        # w goes to slot 0; what was there moves to a slot outside the support (<= 3 points)
        rows = np.arange(len(live))
        slot = np.argmax(lam <= 0, axis=1)
        simplex[rows, slot], ids[rows, slot] = simplex[:, 0], ids[:, 0]
        simplex[:, 0], ids[:, 0] = u[live, w], w
        v, lam, origin = _min_norm_simplex(simplex)
        vv_before, vv = vv, np.where(origin, 0.0, np.einsum("mx,mx->m", v, v))
    b[certified] = (u[certified] @ d[certified][:, :, None]).min(axis=(1, 2))
    return d, b, certified, upper


@cache
def _simplex_faces() -> tuple[np.ndarray, ...]:
    """The faces of a 4-point simplex that hold point 0, by size: (r, c) int, their other points."""
    return tuple(np.array(list(combinations(range(1, 4), r)), dtype=np.intp).T for r in range(4))


def _min_norm_simplex(simplex: np.ndarray):
    """Min-norm point of the hull of 4 points (repeats allowed) where point 0 is new (GJK).

    The min-norm point is the projection of the origin onto the affine hull of the face whose
    relative interior holds it, so it is the nearest to the origin of the projections with
    barycentric weights ``>= 0``. The faces without point 0 were searched the step before
    (they cannot beat it), so only the 8 faces holding point 0 are tried; degenerate faces are
    skipped. Everything comes from the Gram matrix of the points.

    Parameters
    ----------
    simplex : (m, 4, 3) float

    Returns
    -------
    p : (m, 3) float
        The min-norm point, as the convex combination ``lam @ simplex``.
    lam : (m, 4) float
        Its barycentric weights: ``> 0`` on the support, at most 3 points unless ``origin``.
    origin : (m,) bool
        The whole tetrahedron (4 points) holds the origin.
    """
    m = len(simplex)
    g = (simplex @ simplex.transpose(0, 2, 1)).transpose(1, 2, 0)  # (4, 4, m)
    lam, norm2 = [], []
    for rest in _simplex_faces():  # faces of r + 1 points, c of them
        c = rest.shape[1]
        rhs = g[0, 0] - g[0][rest]  # (r, c, m): -(P_i - P_0) . P_0
        edges = g[rest[:, None], rest[None, :]] - g[rest, 0][:, None] + rhs[None, :]
        mu, ok = _solve_small(edges, rhs)
        lam0 = 1 - mu.sum(axis=0)
        ok &= (lam0 >= 0) & np.all(mu >= 0, axis=0)
        # |P_0 + E mu|^2 = G_00 - mu . rhs at the projection
        norm2.append(np.where(ok, g[0, 0] - np.sum(mu * rhs, axis=0), np.inf))
        weights = np.zeros((4, c, m))
        weights[0] = lam0
        weights[rest, np.arange(c)] = mu
        lam.append(np.where(ok, weights, 0.0))
    norm2 = np.concatenate(norm2)
    best = np.argmin(norm2, axis=0)
    lam = np.concatenate(lam, axis=1)[:, best, np.arange(m)].T
    return (lam[:, None] @ simplex)[:, 0], lam, best == len(norm2) - 1  # the last: 4 points


def _solve_small(gram: np.ndarray, rhs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Solve symmetric ``gram @ mu = rhs`` of size r = 0 to 3 in closed form, in bulk.

    Parameters
    ----------
    gram : (r, r, ...) float
        Gram matrices of ``r`` edge vectors (positive semidefinite).
    rhs : (r, ...) float

    Returns
    -------
    mu : (r, ...) float
        The solution (0 where singular).
    ok : (...) bool
        False where ``gram`` is singular to rounding (a degenerate face).
    """
    g, r = gram, len(rhs)
    if r == 0:
        return rhs, np.ones(rhs.shape[1:], bool)
    if r == 1:
        det, adj = g[0, 0], [[1.0]]
    elif r == 2:
        det = g[0, 0] * g[1, 1] - g[0, 1] ** 2
        adj = [[g[1, 1], -g[0, 1]], [-g[0, 1], g[0, 0]]]
    else:
        c00 = g[1, 1] * g[2, 2] - g[1, 2] ** 2
        c01 = g[0, 2] * g[1, 2] - g[0, 1] * g[2, 2]
        c02 = g[0, 1] * g[1, 2] - g[0, 2] * g[1, 1]
        c11 = g[0, 0] * g[2, 2] - g[0, 2] ** 2
        c12 = g[0, 1] * g[0, 2] - g[0, 0] * g[1, 2]
        c22 = g[0, 0] * g[1, 1] - g[0, 1] ** 2
        det = g[0, 0] * c00 + g[0, 1] * c01 + g[0, 2] * c02
        adj = [[c00, c01, c02], [c01, c11, c12], [c02, c12, c22]]
    ok = det > _ROUND * np.prod([g[i, i] for i in range(r)], axis=0)
    safe = np.where(ok, det, 1.0)
    mu = np.stack([sum(adj[i][j] * rhs[j] for j in range(r)) / safe for i in range(r)])
    return np.where(ok, mu, 0.0), ok


@cache
def _subsets(k: int, r: int) -> np.ndarray:
    """(C(k, r), r) int: the r-subsets of ``range(k)``."""
    return np.array(list(combinations(range(k), r)), dtype=np.intp).reshape(-1, r)


def _max_min_enumerate(u: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact max-min direction of each set by evaluating every candidate direction.

    Candidates: each ``u_i``, a direction normal to it, the min-norm point of each segment
    ``[u_i, u_j]`` and both normals of each triangle ``u_i u_j u_l``; every optimum (module
    docstring) is one of them, whatever the sign of ``b``. The best is returned.

    Parameters
    ----------
    u : (m, k, 3) float
        Vector sets, packed (see :func:`_pack`).
    count : (m,) int
        Vectors of each set.

    Returns
    -------
    d : (m, 3) float
        Unit maximiser (``(0, 0, 1)`` for a set of zero vectors).
    b : (m,) float
        ``min_k d . u_k``.
    """
    d = np.tile([0.0, 0.0, 1.0], (len(u), 1))
    for k in np.unique(count):
        sets = np.flatnonzero(count == k)
        pairs, triples = _subsets(k, 2), _subsets(k, 3)
        step = max(1, _BLOCK // (k * (2 * k + len(pairs) + len(triples))))
        for s in range(0, len(sets), step):
            i = sets[s : s + step]
            d[i] = _enumerate_block(u[i, :k], pairs, triples, d[i])
    return d, (u @ d[:, :, None]).min(axis=(1, 2))


def _enumerate_block(u: np.ndarray, pairs: np.ndarray, triples: np.ndarray, d: np.ndarray):
    """:func:`_max_min_enumerate` on one block of sets of equal size; ``d`` is the default."""
    x = np.ascontiguousarray(u.transpose(2, 0, 1))  # (3, m, k): components first
    a, c = x[:, :, pairs[:, 0]], x[:, :, pairs[:, 1]]
    e = c - a
    ee = np.sum(e * e, axis=0)
    t = np.clip(-np.sum(a * e, axis=0) / np.where(ee > 0, ee, 1.0), 0.0, 1.0)
    p = x[:, :, triples[:, 0]]
    cand = np.concatenate(
        [
            x,
            _cross(x, _least_axis(x)),
            (1 - t) * a + t * c,
            _cross(x[:, :, triples[:, 1]] - p, x[:, :, triples[:, 2]] - p),
        ],
        axis=2,
    )  # (3, m, n_cand)
    norm = np.sqrt(np.sum(cand * cand, axis=0))
    cand /= np.where(norm > 0, norm, 1.0)
    dots = u @ np.ascontiguousarray(cand.transpose(1, 0, 2))  # (m, k, n_cand)
    tri = cand.shape[2] - len(triples)  # the triangles' normals: tri ... n_cand - 1
    # values of every candidate, then of the triangles' other normals
    val = np.concatenate([dots.min(axis=1), -dots[:, :, tri:].max(axis=1)], axis=1)
    val[np.concatenate([norm, norm[:, tri:]], axis=1) == 0] = -np.inf
    best = np.argmax(val, axis=1)
    rows = np.arange(len(u))
    found = np.isfinite(val[rows, best])
    other = best >= cand.shape[2]
    best_dir = cand[:, rows, np.where(other, best - len(triples), best)].T
    d = d.copy()
    d[found] = np.where(other[:, None], -best_dir, best_dir)[found]
    return d


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross products of (3, ...) component arrays."""
    return np.stack(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def _least_axis(x: np.ndarray) -> np.ndarray:
    """(3, ...) unit coordinate axes, each the one least along the vector of ``x`` (3, ...)."""
    return (np.abs(x) == np.abs(x).min(axis=0)).cumsum(axis=0).cumsum(axis=0) == 1


def solid_angle_front(kappa: np.ndarray, half_angle: np.ndarray) -> float:
    """Solid angle on the front side of a closed vertex: ``2 pi + sum(kappa * 2 gamma)``.

    Parameters
    ----------
    kappa : (n,) int
        +1 mountain, -1 valley per incident edge.
    half_angle : (n,) float

    Notes
    -----
    The back side is the geodesic polygon of the edge directions on the unit sphere, with
    interior angles ``pi - kappa 2 gamma``; its area is ``2 pi - sum(kappa 2 gamma)``.
    """
    kappa = np.asarray(kappa)
    return float(solid_angles_front(kappa, np.asarray(half_angle), np.array([len(kappa)]))[0])


def solid_angles_front(kappa: np.ndarray, half_angle: np.ndarray, count: np.ndarray) -> np.ndarray:
    """:func:`solid_angle_front` of many closed vertices at once.

    Parameters
    ----------
    kappa : (m,) int
    half_angle : (m,) float
        Per incident edge, the edges of each vertex one after another.
    count : (n,) int
        Incident edges per vertex.

    Returns
    -------
    (n,) float
    """
    return 2 * np.pi + run_sums(kappa * 2 * half_angle, count)


def is_developable(angle_sum: float) -> bool:
    """True when the face angles around a vertex sum to 2 pi (within tolerance)."""
    return abs(angle_sum - 2 * np.pi) < tol.developable
