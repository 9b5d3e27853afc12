"""Folded origami tessellations and a conical mesh, generated in code.

Every tessellation here is a *folded* state of a flat crease pattern: each face is congruent to
its flat counterpart, so the face angles at every interior vertex sum to exactly 2 pi (to
round-off) and the mesh is developable. Faces are counter-clockwise seen from the front (the
side that was up in the flat sheet), planar, and the mean edge length is about 1. The meshes
are open: their boundary is the edge of the sheet.

* :func:`miura` -- Miura-ori, closed form (a discrete translational surface of two zigzags).
* :func:`chicken_wire` -- rows of isosceles trapezoids, zigzag rows in anti-phase; closed form
  from its mirror symmetry (it folds into a corrugated vault).
* :func:`yoshimura` -- the diamond pattern, closed form (stacked antiprism bands of an arch).
* :func:`resch` -- Ron Resch's triangle pattern, partly folded by a numerical solve of the edge
  lengths.
* :func:`conical_dome` -- a planar-quad conical mesh of a dome (not developable).

Each generator returns ``(vertices (n, 3) float64, faces list of (k,) int64)`` and raises
:class:`~filletfold.errors.ParameterError` for a value out of its range.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.sparse import coo_matrix, identity, vstack
from scipy.spatial import cKDTree

from ..errors import ParameterError, SolverError
from .intersect import crossing_triangle_pairs

__all__ = ["chicken_wire", "conical_dome", "miura", "resch", "yoshimura"]

_SQRT3 = np.sqrt(3.0)
#: Points of the Resch grid are one point when their coordinates agree to 1 / this.
_KEY_SCALE = 1e6
#: Unit lengths and distances of the Resch grid are equal to within this.
_GRID_TOL = 1e-6
#: ``ftol`` and ``xtol`` of the least-squares fold of the Resch pattern.
_FIT_TOL = 1e-8
#: The projection onto the edge lengths stops once every length is this close, or once within
#: ``_LENGTH_TOL`` a step no longer halves the largest miss (round-off: about 1.4e-15 on
#: ``resch:4x4``, where 23 more dense steps gained nothing) ...
_LENGTH_DONE = 1e-15
#: ... and fails when one is further than this after its rounds.
_LENGTH_TOL = 1e-12


# ----------------------------------------------------------------------------- validation
def _cells(cells, name: str = "cells", low: int = 1, high: int = 40) -> tuple[int, int]:
    try:
        m, n = (int(c) for c in cells)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be two integers, got {cells!r}", name=name) from None
    if not (low <= m <= high and low <= n <= high):
        raise ParameterError(
            f"{name} must be between {low}x{low} and {high}x{high}, got {m}x{n}", name=name
        )
    return m, n


def _in_range(value, name: str, low: float, high: float) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number, got {value!r}", name=name) from None
    if not (np.isfinite(x) and low <= x <= high):
        raise ParameterError(f"{name} must be in [{low:g}, {high:g}], got {x:g}", name=name)
    return x


def _grid_quads(m: int, n: int) -> list[np.ndarray]:
    """Quads of an ``(m + 1) x (n + 1)`` vertex grid (vertex ``i * (n + 1) + j``), CCW in (i, j)."""
    k = n + 1
    return [
        np.array([i * k + j, (i + 1) * k + j, (i + 1) * k + j + 1, i * k + j + 1])
        for i in range(m)
        for j in range(n)
    ]


def _centred(v: np.ndarray) -> np.ndarray:
    return v - 0.5 * (v.min(axis=0) + v.max(axis=0))


# ------------------------------------------------------------------------------- Miura-ori
def miura(cells=(4, 4), angle: float = 65.0, fold: float = 0.5):
    """A folded Miura-ori: parallelograms with unit sides (closed form).

    The folded sheet is the translational surface ``P(i, j) = A(i) + B(j)`` of a zigzag ``A``
    in the xz-plane (the creases that are straight in the flat sheet) and a zigzag ``B`` in the
    xy-plane (the zigzag creases of the flat sheet). Every face is a parallelogram with sides 1
    and sector angle ``angle``, so the mesh is isometric to the flat pattern for every fold.

    Parameters
    ----------
    cells : (2,) int
        ``(m, n)``: ``m`` parallelograms along the straight creases, ``n`` along the zigzags.
    angle : float
        Sector angle of the parallelograms in degrees, in [30, 85].
    fold : float
        Fold amount in [0.05, 0.95]: 0 is the flat sheet, 1 folded flat.

    Returns
    -------
    vertices : ((m + 1) * (n + 1), 3) float64
        Vertex ``i * (n + 1) + j`` is ``P(i, j)``; centred, the sheet's front side up (+z).
    faces : list of (4,) int64
        ``m * n`` parallelograms, counter-clockwise seen from the front.
    """
    m, n = _cells(cells)
    gamma = np.radians(_in_range(angle, "angle", 30.0, 85.0))
    t = _in_range(fold, "fold", 0.05, 0.95)
    psi = t * gamma  # tilt of the A zigzag out of the xy-plane: 0 flat, gamma folded flat
    phi = np.arcsin(np.cos(gamma) / np.cos(psi))  # keeps the sector angle: cos psi sin phi = cos g
    i = np.arange(m + 1)
    j = np.arange(n + 1)
    a = np.column_stack([i * np.cos(psi), np.zeros(m + 1), (i % 2) * np.sin(psi)])
    b = np.column_stack([(j % 2) * np.sin(phi), j * np.cos(phi), np.zeros(n + 1)])
    v = (a[:, None, :] + b[None, :, :]).reshape(-1, 3)
    return _centred(v), _grid_quads(m, n)


# ---------------------------------------------------------------------------- chicken wire
_CW_H = 1.0  # row height of the flat pattern
_CW_DELTA = 0.2  # zigzag amplitude: vertical edges 1 -+ 0.4, zigzag edges sqrt(1 + 0.16)


def chicken_wire(cells=(4, 4), fold: float = 0.5):
    """A folded "chicken wire" pattern of isosceles trapezoids (closed form).

    In the flat sheet, vertex ``(i, j)`` is at ``(i, j + 0.2 (-1)**(i + j))``: straight creases
    ``x = i`` cross zigzag creases whose neighbouring rows are in anti-phase, so the faces are
    isosceles trapezoids (parallel sides 0.6 and 1.4, legs sqrt(1.16)) alternating in
    orientation, and every vertex is a flat-foldable Miura-type vertex.

    The fold keeps the sheet's mirror symmetry about every straight crease: straight crease ``i``
    lies in the plane ``x = i c``, and the vector between the two ends of zigzag segment
    ``(i, j) - (i + 1, j)`` turns by ``pi - tau`` from row to row, where ``tau`` is the turn of
    the straight creases at each zigzag. The result is a corrugated vault; ``tau`` grows with
    ``fold``.

    Parameters
    ----------
    cells : (2,) int
        ``(m, n)``: ``m`` trapezoids along each row, ``n`` rows.
    fold : float
        Fold amount in [0.05, 0.95]: 0 is flat; 1 would close the vault or collapse the rows.

    Returns
    -------
    vertices : ((m + 1) * (n + 1), 3) float64
        Vertex ``i * (n + 1) + j``; centred, vault crown towards +z.
    faces : list of (4,) int64
        ``m * n`` trapezoids, counter-clockwise seen from the front.
    """
    m, n = _cells(cells)
    t = _in_range(fold, "fold", 0.05, 0.95)
    h, delta = _CW_H, _CW_DELTA
    e2 = 1.0 + 4 * delta**2  # squared length of a zigzag edge
    theta_min = 2 * np.arcsin(2 * delta / np.sqrt(e2))  # columns collapsed (c = 0)
    # the vault turns by tau per row; keep its total turn below 200 degrees
    tau = t * min(np.pi - theta_min, np.radians(200.0) / max(n - 1, 1))
    theta = np.pi - tau
    d = 2 * delta / np.sin(theta / 2)  # length of D(j) = Q1(j) - Q0(j)
    c = np.sqrt(e2 - d**2)  # spacing of the straight creases' mirror planes
    j = np.arange(n + 1)
    ang = j * theta  # D(j) = d (-cos, -sin)(j theta): flat state alternates -2 delta, +2 delta
    dvec = -d * np.column_stack([np.cos(ang), np.sin(ang)])
    seg_len = h - 2 * delta * (-1.0) ** j[:-1]  # even column: flat lengths h -+ 2 delta
    u = ((-1.0) ** j[:-1])[:, None] * (dvec[1:] - dvec[:-1]) / (4 * delta)
    q0 = np.vstack([[0.0, 0.0], np.cumsum(seg_len[:, None] * u, axis=0)])
    q = [q0, q0 + dvec]
    v = np.array([[i * c, *q[i % 2][jj]] for i in range(m + 1) for jj in range(n + 1)])
    faces = _grid_quads(m, n)
    return _front_up(_centred(v), faces), faces


def _front_up(v: np.ndarray, faces) -> np.ndarray:
    """Rotate ``v`` about the x-axis so the area-weighted mean front normal is +z."""
    acc = np.zeros(3)
    for f in faces:
        p = v[f]
        acc += np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)
    ang = np.arctan2(acc[1], acc[2])  # rotate (y, z) of acc onto +z
    c, s = np.cos(ang), np.sin(ang)
    rot = np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])
    return _centred(v @ rot.T)


# ------------------------------------------------------------------------------- Yoshimura
_YO_W = 1.2  # horizontal edge
_YO_H = 0.7  # row height of the flat pattern (diagonals sqrt(0.36 + 0.49))


def yoshimura(cells=(5, 4), fold: float = 0.5):
    """A folded Yoshimura (diamond) pattern of isosceles triangles (closed form).

    Flat: rows of horizontal creases at ``y = 0.7 k``; even rows have vertices at ``x = 1.2 i``,
    odd rows halfway between; diagonals join neighbouring rows. Folded: the vertices of row ``k``
    lie on an arc of radius ``R`` in the plane ``y = k Y``, ``Delta`` apart, odd rows turned by
    ``Delta / 2``; ``R`` and ``Y`` follow from the edge lengths, so the sheet is a stack of
    antiprism bands of an arch. Horizontal creases are valleys, diagonals mountains.

    Parameters
    ----------
    cells : (2,) int
        ``(m, n)``: ``m`` horizontal edges on an even row, ``n`` rows of triangles.
    fold : float
        Fold amount in [0.05, 0.95]: the turn ``Delta`` per horizontal edge as a share of the
        largest one (the rows collapse, or the arch reaches 270 degrees).

    Returns
    -------
    vertices : (n_vertices, 3) float64
        Rows in order; centred, the arch's crown towards +z.
    faces : list of (3,) int64
        Counter-clockwise seen from the front (the outside of the arch).
    """
    m, n = _cells(cells)
    t = _in_range(fold, "fold", 0.05, 0.95)
    w, h = _YO_W, _YO_H
    diag2 = h**2 + w**2 / 4
    delta_max = 4 * np.arccos(w / (2 * np.sqrt(diag2)))  # rows collapse: Y = 0
    delta = t * min(delta_max, 1.5 * np.pi / m)
    radius = w / (2 * np.sin(delta / 2))
    y_step = np.sqrt(diag2 - (2 * radius * np.sin(delta / 4)) ** 2)
    index: dict[tuple[int, int], int] = {}  # (row, 2 * position) -> vertex
    verts = []
    flat = []
    for k in range(n + 1):
        half = np.arange(m + 1) * 2 if k % 2 == 0 else np.arange(m) * 2 + 1
        for p2 in half:
            index[(k, int(p2))] = len(verts)
            a = (p2 / 2 - m / 2) * delta
            verts.append([radius * np.sin(a), k * y_step, radius * np.cos(a)])
            flat.append([p2 / 2 * w, k * h])
    faces = []
    for k in range(n):
        for p2 in range(-1, 2 * m + 1):
            # triangles with two corners on one row (positions p2 - 1 and p2 + 1) and the third
            # at p2 on the other row, when all three exist
            for base, apex in ((k, k + 1), (k + 1, k)):
                tri = [(base, p2 - 1), (base, p2 + 1), (apex, p2)]
                if all(key in index for key in tri):
                    faces.append([index[key] for key in tri])
    flat = np.array(flat)
    out = []
    for f in faces:  # counter-clockwise in the flat sheet
        a, b, c = flat[f]
        cross = (b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0]
        out.append(np.array(f if cross > 0 else f[::-1]))
    out.sort(key=lambda f: (min(f.tolist()), sorted(f.tolist())))
    return _centred(np.array(verts)), out


# ---------------------------------------------------------------------------- conical dome
def conical_dome(cells=(8, 4), opening: float = 60.0, height: float = 1.0):
    """A conical mesh of a dome cap: planar quads on meridians and parallels (not developable).

    The vertices lie on the spheroid ``(x, y, z / height)`` on the unit sphere, at polar angles
    ``opening * k / n`` (``k = 1 .. n``) and azimuths ``2 pi i / m``. Quads between neighbouring
    parallels and meridians are planar isosceles trapezoids; the cap inside the first parallel
    is one planar ``m``-gon. By the mirror symmetry in each meridian plane, the face angles at
    every interior vertex of degree 4 satisfy ``a1 + a3 = a2 + a4``: the mesh is conical (paper
    sec. 4.4), and convex. Scaled to a mean edge length of 1.

    Parameters
    ----------
    cells : (2,) int
        ``(m, n)``: ``m`` meridian segments around (3..64), ``n`` rings of quads.
    opening : float
        Polar angle of the rim in degrees, in [10, 150].
    height : float
        Vertical stretch of the sphere, in [0.2, 5].

    Returns
    -------
    vertices : (m * n, 3) float64
        Parallel ``k`` (from the top, 0-based) holds vertices ``k * m .. k * m + m - 1``.
    faces : list of (k,) int64
        The cap ``m``-gon, then ``m * (n - 1)`` quads; counter-clockwise seen from outside.
    """
    m, n = _cells(cells)
    if m < 3 or m > 64:
        raise ParameterError(f"cells must have 3..64 meridian segments, got {m}", name="cells")
    op = np.radians(_in_range(opening, "opening", 10.0, 150.0))
    stretch = _in_range(height, "height", 0.2, 5.0)
    polar = op * np.arange(1, n + 1) / n
    az = 2 * np.pi * np.arange(m) / m
    pp, aa = np.meshgrid(polar, az, indexing="ij")
    v = np.column_stack(
        [
            (np.sin(pp) * np.cos(aa)).ravel(),
            (np.sin(pp) * np.sin(aa)).ravel(),
            (stretch * np.cos(pp)).ravel(),
        ]
    )
    faces = [np.arange(m)]
    for k in range(n - 1):
        for i in range(m):
            i2 = (i + 1) % m
            faces.append(np.array([k * m + i, (k + 1) * m + i, (k + 1) * m + i2, k * m + i2]))
    edges = {(min(a, b), max(a, b)) for f in faces for a, b in zip(f, np.roll(f, -1), strict=True)}
    e = np.array(sorted(edges))
    mean = np.linalg.norm(v[e[:, 1]] - v[e[:, 0]], axis=1).mean()
    v = v / mean
    v[:, 2] -= v[:, 2].min()
    return v, faces


# ----------------------------------------------------------------------------------- Resch
def resch(cells=(3, 3), fold: float = 0.5):
    """Ron Resch's triangle tessellation, partly folded (numerical solve).

    Crease pattern: regular hexagonal "stars" of side 2, each cut into twelve 30-60-90
    triangles by the lines from its centre to its corners (valleys) and to its edge midpoints
    (mountains), twisted so that every corner of a star is the midpoint of an edge of a
    neighbouring star (stars share half-edges); the gaps are equilateral "tops" of side 1. The
    star centres form a triangular lattice of spacing sqrt(13). The patch holds the ``m x n``
    stars of a lattice parallelogram and the tops with at least two sides on them; the whole
    pattern is scaled to a mean edge length of 1 (tops of side about 0.69).

    Folding: the star centres sink and the stars tuck under the tops, which twist together;
    fully folded, each star becomes six vertical fins under a flat layer of tops. The partly
    folded state is a least-squares solve: the sheet's edge lengths, every star pulled towards
    the six-fold symmetric star of depth ``fold * sqrt(3)`` (all distances between its 13
    points), and a weak pull towards a blend of the flat and the fully tucked states; the
    result is then projected exactly onto the edge lengths (Gauss-Newton, minimal-norm steps).
    The pattern is triangulated, so equal edge lengths make every face congruent. The folded
    sheet curls (a Resch sheet cannot stay flat while partly folded). Spokes to star corners
    are valleys, spokes to edge midpoints and star rims mountains; on patches larger than 3x3
    at folds below about 0.6 a few rim spokes fold the other way.

    Parameters
    ----------
    cells : (2,) int
        ``(m, n)`` stars along the two lattice directions, each in 1..6.
    fold : float
        Fold amount in [0.4, 0.8]: the depth of the star centres as a share of the fully
        tucked depth (0 is flat, 1 the stars folded into fins under a flat layer of tops).

    Returns
    -------
    vertices : (n_vertices, 3) float64
        Centred, the tops' side (the front of the sheet) towards +z.
    faces : list of (3,) int64
        Counter-clockwise seen from the front.

    Raises
    ------
    ParameterError
        A value out of range, or a fold at which the curling sheet passes through itself.
    SolverError
        If the edge lengths cannot be met (does not happen for the accepted parameters).
    """
    m, n = _cells(cells, high=6)
    t = _in_range(fold, "fold", 0.4, 0.8)
    v, faces = _resch_folded(m, n, round(t, 12))
    if crossing_triangle_pairs(v, faces):
        raise ParameterError(
            f"resch {m}x{n} with fold={t:g} passes through itself (the folded sheet curls); "
            "use fewer cells or a smaller fold",
            name="fold",
        )
    return v.copy(), [np.array(f) for f in faces]


def _resch_flat(m: int, n: int):
    """Flat Resch pattern.

    Returns
    -------
    points : (n_points, 2) float
    triangles : list of [a, b, c], counter-clockwise
    centres : (n_stars,) int
        The star centres.
    """
    corner_ang = np.radians(60.0 * np.arange(6))
    corners = 2.0 * np.column_stack([np.cos(corner_ang), np.sin(corner_ang)])
    # a neighbouring star shares the half-edge from corners[0] to the midpoint of its edge
    # corners[0] -> corners[1]: its centre is corners[0] + that midpoint (length sqrt(13))
    t1 = corners[0] + 0.5 * (corners[0] + corners[1])
    c60, s60 = 0.5, _SQRT3 / 2
    t2 = np.array([c60 * t1[0] - s60 * t1[1], s60 * t1[0] + c60 * t1[1]])
    centre_xy = np.array([a * t1 + b * t2 for a in range(m) for b in range(n)])
    pts: list[np.ndarray] = []
    key: dict[tuple[int, int], int] = {}

    def vid(p) -> int:
        k = (round(float(p[0]) * _KEY_SCALE), round(float(p[1]) * _KEY_SCALE))
        if k not in key:
            key[k] = len(pts)
            pts.append(np.asarray(p, dtype=np.float64))
        return key[k]

    tris = []
    centre_ids = []
    rings = []
    star_edges = set()
    for o in centre_xy:
        oc = vid(o)
        centre_ids.append(oc)
        ring = []
        for k in range(6):
            ring += [o + corners[k], o + 0.5 * (corners[k] + corners[(k + 1) % 6])]
        ids = [vid(p) for p in ring]
        rings.append(ids)
        for k in range(12):
            a, b = ids[k], ids[(k + 1) % 12]
            tris.append([oc, a, b])
            star_edges.add((min(a, b), max(a, b)))
    p = np.array(pts)
    # tops: unit equilateral triangles of star boundary points, outside every star, with at
    # least two sides on star edges (a top between only two stars fills a notch of the patch)
    boundary = np.array(sorted(set(range(len(p))) - set(centre_ids)))
    pairs = cKDTree(p[boundary]).query_pairs(1.0 + _GRID_TOL, output_type="ndarray")
    d = np.linalg.norm(p[boundary[pairs[:, 0]]] - p[boundary[pairs[:, 1]]], axis=1)
    pairs = boundary[pairs[np.abs(d - 1.0) < _GRID_TOL]]
    nbr: dict[int, set[int]] = {}
    for a, b in pairs.tolist():
        nbr.setdefault(a, set()).add(b)
        nbr.setdefault(b, set()).add(a)
    cand = sorted(
        {tuple(sorted((a, b, c))) for a, na in nbr.items() for b in na for c in na & nbr[b]}
    )
    for c in cand:
        centroid = p[list(c)].mean(axis=0)
        if np.linalg.norm(centre_xy - centroid, axis=1).min() < _SQRT3 - _GRID_TOL:
            continue  # inside a star (its inscribed circle holds every unit triangle in it)
        sides = ((c[0], c[1]), (c[1], c[2]), (c[0], c[2]))
        if sum(e in star_edges for e in sides) >= 2:
            tris.append(list(c))
    out = []
    for f in tris:
        a, b, c = p[f]
        cross = (b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0]
        out.append(f if cross > 0 else [f[0], f[2], f[1]])
    # the stars fully tucked: star centre o -> V = o / sqrt(13) at depth sqrt(3), its edge
    # midpoints -> V, its corner k -> V + R^k t1 / sqrt(13) (the centre of the star whose
    # edge midpoint that corner is); the tops then tile the plane z = 0 with unit triangles
    tucked = np.zeros((len(p), 3))
    s13 = np.sqrt(13.0)
    rot = [np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]) for a in corner_ang]
    for o, oc in zip(centre_xy, centre_ids, strict=True):
        v = o / s13
        tucked[oc] = [*v, -_SQRT3]
        for k in range(6):
            tucked[vid(o + corners[k])] = [*(v + rot[k] @ t1 / s13), 0.0]
    for o in centre_xy:
        for k in range(6):
            tucked[vid(o + 0.5 * (corners[k] + corners[(k + 1) % 6]))] = [*(o / s13), 0.0]
    return p, out, np.array(centre_ids), np.array(rings), tucked


def _edges_of(faces) -> np.ndarray:
    edges = {(min(a, b), max(a, b)) for f in faces for a, b in zip(f, np.roll(f, -1), strict=True)}
    return np.array(sorted(edges), dtype=np.int64)


def _edge_residual(x: np.ndarray, edges: np.ndarray, length: np.ndarray):
    """Residual ``(|p_a - p_b|^2 - L^2) / (2 L)`` per edge and its sparse Jacobian."""
    p = x.reshape(-1, 3)
    diff = p[edges[:, 0]] - p[edges[:, 1]]
    r = (np.einsum("ij,ij->i", diff, diff) - length**2) / (2 * length)
    g = diff / length[:, None]
    rows = np.repeat(np.arange(len(edges)), 6)
    cols = np.concatenate([3 * edges[:, :1] + np.arange(3), 3 * edges[:, 1:] + np.arange(3)], 1)
    vals = np.concatenate([g, -g], axis=1)
    jac = coo_matrix((vals.ravel(), (rows, cols.ravel())), shape=(len(edges), x.size)).tocsr()
    return r, jac


def _resch_star_heights(depth: float) -> tuple[float, float]:
    """Heights of a symmetric star's corners and edge midpoints above its sunk centre.

    The six-fold symmetric star with its centre ``depth`` below its corners: corners at radius
    ``sqrt(4 - depth**2)``, midpoints at height ``depth + z`` and radius ``sqrt(3 - (depth +
    z)**2)``, 30 degrees from the corners and at distance 1 from them.
    """
    r_c = np.sqrt(4.0 - depth**2)

    def gap(z):
        r_m = np.sqrt(max(3.0 - (depth + z) ** 2, 0.0))
        return r_m**2 + r_c**2 + z**2 - _SQRT3 * r_m * r_c - 1.0

    lo, hi = 0.0, _SQRT3 - depth
    for _ in range(80):  # bisection: gap(lo) <= 0 <= gap(hi)
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if gap(mid) < 0 else (lo, mid)
    return depth, depth + 0.5 * (lo + hi)


@lru_cache(maxsize=16)
def _resch_folded(m: int, n: int, fold: float):
    from scipy.optimize import least_squares  # 0.1-0.3 s to import: only here

    flat2, faces, centres, rings, tucked = _resch_flat(m, n)
    flat = np.column_stack([flat2, np.zeros(len(flat2))])
    edges = _edges_of(faces)
    length = np.linalg.norm(flat[edges[:, 0]] - flat[edges[:, 1]], axis=1)
    n_v = len(flat)
    # start between the flat sheet and the tucked state (scaled up about the patch centre)
    scale = np.sqrt(13.0)
    tucked = (tucked - tucked.mean(axis=0)) * scale + flat.mean(axis=0)
    x0 = (1 - fold) * flat + fold * tucked
    x0[:, 2] = fold * tucked[:, 2] / scale
    # soft targets: every star keeps the shape of the six-fold symmetric star of the same
    # depth (all distances between its 13 points), and a weak pull towards the start
    h_c, h_m = _resch_star_heights(fold * _SQRT3)
    ang = np.radians(30.0 * np.arange(12))
    rad = np.where(np.arange(12) % 2 == 0, np.sqrt(4 - h_c**2), np.sqrt(3 - h_m**2))
    star = np.vstack(
        [
            [0.0, 0.0, 0.0],
            np.column_stack(
                [rad * np.cos(ang), rad * np.sin(ang), np.where(np.arange(12) % 2 == 0, h_c, h_m)]
            ),
        ]
    )
    iu, ju = np.triu_indices(13, 1)
    star_len = np.linalg.norm(star[iu] - star[ju], axis=1)
    members = np.column_stack([centres, rings])  # (n_stars, 13)
    shape_pairs = np.column_stack([members[:, iu].ravel(), members[:, ju].ravel()])
    shape_len = np.tile(star_len, len(members))
    w_pull, w_shape = 0.01, 3.0
    j_pull = w_pull * identity(3 * n_v, format="csr")

    def residual(x):
        r, _ = _edge_residual(x, edges, length)
        rs, _ = _edge_residual(x, shape_pairs, shape_len)
        return np.concatenate([r, w_shape * rs, w_pull * (x - x0.ravel())])

    def jacobian(x):
        _, je = _edge_residual(x, edges, length)
        _, js = _edge_residual(x, shape_pairs, shape_len)
        return vstack([je, w_shape * js, j_pull]).tocsr()

    sol = least_squares(
        residual, x0.ravel(), jac=jacobian, method="trf", ftol=_FIT_TOL, xtol=_FIT_TOL
    )
    x = _project_lengths(sol.x, edges, length)
    v = x.reshape(-1, 3)
    v = v - v.mean(axis=0)
    # front (the tops' side) up: the area-weighted mean front normal becomes +z
    acc = np.zeros(3)
    for f in faces:
        q = v[f]
        acc += np.cross(q[1] - q[0], q[2] - q[0])
    z = acc / np.linalg.norm(acc)
    xa = np.cross([0.0, 1.0, 0.0], z)
    xa /= np.linalg.norm(xa)
    ya = np.cross(z, xa)
    v = v @ np.column_stack([xa, ya, z])
    mean_edge = float(length.mean())
    return _centred(v / mean_edge), tuple(tuple(int(i) for i in f) for f in faces)


def _project_lengths(x: np.ndarray, edges: np.ndarray, length: np.ndarray) -> np.ndarray:
    """Gauss-Newton with minimal-norm steps onto ``|p_a - p_b| = L`` for every edge."""
    miss = np.inf
    for _ in range(30):
        r, jac = _edge_residual(x, edges, length)
        worst = np.abs(r).max()
        if worst < _LENGTH_DONE or (worst < _LENGTH_TOL and worst > 0.5 * miss):
            break
        miss = worst
        step, *_ = np.linalg.lstsq(jac.toarray(), r, rcond=None)
        x = x - step
    r, _ = _edge_residual(x, edges, length)
    if np.abs(r).max() > _LENGTH_TOL:
        raise SolverError(f"the folded Resch pattern misses an edge length by {np.abs(r).max():g}")
    return x
