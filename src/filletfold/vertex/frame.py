"""The rounded neighbourhood of one vertex and its development (paper sec. 2.1, 2.4).

Around a vertex U the incident edges are *sides*: a rounded side is a cylinder whose base
curve ``C(s) = O + kappa r N(s)`` (``s`` in ``[0, a]``) lies in the edge's midpoint
cross-section and runs from face ``f_{i-1}`` (``s = 0``) to face ``f_i`` (``s = a``); ``R`` is the
unit edge vector toward U, and ``(s, z) -> C(s) + z R`` is the cylinder's
orientation-preserving chart (``C'(s) x R = N(s)``).
A boundary side is the unrounded edge line ``M + z R``.

All pieces are developed into one common 2D frame: the chart of ``tau = f_{n-1}`` (origin U). Each
cylinder and face gets a rigid 2D map (3x3 homogeneous) by chaining the tangent-plane gluings
``tau -> cylinder 0 -> f_0 -> ... -> cylinder n-1 -> tau'``. The last map ``rho`` turns by minus the
angle defect; the developed apex is its fixed point, :func:`developed_apices` (docs/method.md,
'Conventions', "One 2D frame per vertex").

:func:`vertex_frames` builds the frames of many vertices at once, on flat arrays over all their
(vertex, ring position) pairs; :func:`vertex_frame` is one vertex through it.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from ..arrays import run_owners, run_starts
from ..errors import MeshError
from ..mesh.polymesh import PolyMesh, VertexRing
from ..rounding.edges import EdgeRounding
from ..rounding.tapered import (
    FilletRows,
    angle_series,
    fillet_chart,
    perpendiculars,
    ruled_gluing_maps,
    series_angles,
)
from ..tolerances import tol


@dataclass
class Side:
    """One incident edge of a vertex, seen from that vertex.

    Attributes
    ----------
    edge : int
    rounded : bool
        True for an interior edge (it has a cylinder chart; radius 0 at a flat edge), False
        for a boundary edge.
    R : (3,) float
        Unit edge direction toward the vertex.
    M : (3,) float
        Edge midpoint.
    length : float
    radius, gamma, arc : float
        Cylinder radius, half angle, arc length ``a`` (0 for a boundary side).
    kappa : int
    O : (3,) float
        Axis point in the midpoint cross-section.
    N0, B : (3,) float
        ``N(s) = cos(s / r) N0 + sin(s / r) B``; ``N0`` is the normal of face ``f_{i-1}``.
    S : (3,) float or None
        On a *conical* side (the edge's other end is a sharp vertex): that end, the apex of
        the conical fillet that rounds the edge instead of a cylinder
        (:mod:`filletfold.rounding.tapered`). None on a cylinder.
    """

    edge: int
    rounded: bool
    R: np.ndarray
    M: np.ndarray
    length: float
    radius: float = 0.0
    gamma: float = 0.0
    arc: float = 0.0
    kappa: int = 0
    O: np.ndarray | None = None
    N0: np.ndarray | None = None
    B: np.ndarray | None = None
    S: np.ndarray | None = None

    @property
    def conical(self) -> bool:
        """True for a conical fillet (:attr:`S` set)."""
        return self.S is not None

    @property
    def flat(self) -> bool:
        """True for an interior edge between coplanar faces (not rounded: ``a = 0``)."""
        return self.rounded and self.radius == 0

    def normal(self, s):
        """(k, 3) front normals of the cylinder along the base curve at parameters ``s``."""
        s = np.asarray(s, dtype=float)[:, None]
        if self.radius == 0:
            return np.repeat(self.N0[None], len(s), axis=0)
        t = s / self.radius
        return np.cos(t) * self.N0 + np.sin(t) * self.B

    def base(self, s):
        """(k, 3) base-curve points ``C(s)``."""
        return self.O + self.kappa * self.radius * self.normal(s)

    def tangent(self, s):
        """(k, 3) unit tangents ``C'(s)``."""
        s = np.asarray(s, dtype=float)[:, None]
        if self.radius == 0:
            return np.repeat(np.cross(self.R, self.N0)[None], len(s), axis=0)
        t = s / self.radius
        return self.kappa * (-np.sin(t) * self.N0 + np.cos(t) * self.B)


def dot_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot products (...,) of vectors (..., 3), each one ``a[k] @ b[k]``."""
    return (a[..., None, :] @ b[..., :, None])[..., 0, 0]


def norm_rows(a: np.ndarray) -> np.ndarray:
    """Row-wise lengths (...,) of vectors (..., 3)."""
    return np.sqrt(dot_rows(a, a))


def _face_axes(mesh: PolyMesh, faces: np.ndarray) -> np.ndarray:
    """In-plane axes of the charts of ``faces`` (k,): (k, 2, 3) rows e1, e2.

    ``e1`` runs from a face's first vertex to its second, ``e2 = n x e1`` (``n`` the front
    normal), so the chart is orientation-preserving.
    """
    first = mesh.face_start[faces]
    a = mesh.vertices[mesh.halfedge_from[first]]
    d = mesh.vertices[mesh.halfedge_from[first + 1]] - a
    e1 = d / norm_rows(d)[:, None]
    return np.stack([e1, np.cross(mesh.face_normal[faces], e1)], axis=1)


def face_frame(mesh: PolyMesh, f: int, origin: np.ndarray) -> np.ndarray:
    """(3, 3) rows: origin, e1, e2 of an orientation-preserving chart of face ``f``."""
    axes = _face_axes(mesh, np.array([f], dtype=np.int64))[0]
    return np.concatenate([np.asarray(origin, dtype=float)[None], axes])


def to_chart(frame: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Chart coordinates (k, 2) of 3D points ``p`` (k, 3) on a face with ``frame``."""
    q = np.atleast_2d(p) - frame[0]
    return np.stack([q @ frame[1], q @ frame[2]], axis=-1)


def rigid(linear: np.ndarray, t: np.ndarray) -> np.ndarray:
    """3x3 homogeneous matrix of the 2D map ``x -> linear @ x + t``.

    Stacked: ``linear`` (..., 2, 2) and ``t`` (..., 2) give (..., 3, 3).
    """
    linear = np.asarray(linear, dtype=float)
    m = np.zeros((*linear.shape[:-2], 3, 3))
    m[..., :2, :2] = linear
    m[..., :2, 2] = t
    m[..., 2, 2] = 1.0
    return m


def apply(m: np.ndarray, p) -> np.ndarray:
    """Apply a 3x3 homogeneous 2D map to points (k, 2)."""
    p = np.atleast_2d(np.asarray(p, dtype=float))
    return p @ m[:2, :2].T + m[:2, 2]


def invert(m: np.ndarray) -> np.ndarray:
    """Inverse of a rigid 3x3 homogeneous 2D map (or of a stack (..., 3, 3) of them)."""
    q = np.swapaxes(m[..., :2, :2], -1, -2)
    return rigid(q, -(q @ m[..., :2, 2:])[..., 0])


@dataclass
class SideArrays:
    """The sides of a closed ring as arrays (see :class:`Side`), for vectorised constraints.

    Attributes
    ----------
    edge : (k,) int
    R, M, O, N0, B : (k, 3) float
    radius, kappa, arc, length : (k,) float
    Q : (k, 2, 2) float
        Linear part of the map from the common frame into each cylinder's chart.
    t : (k, 2) float
        Its translation.
    face_normal : (n_faces, 3) float
        Front normal of each ring face.
    S : (k, 3) float
        Apex of each conical side's fillet (:attr:`Side.S`), NaN on the other sides (None:
        no side is conical). On a conical side the chart is the fillet's (:meth:`chart`),
        not ``(s, z) -> C(s) + z R``.
    """

    edge: np.ndarray
    R: np.ndarray
    M: np.ndarray
    O: np.ndarray
    N0: np.ndarray
    B: np.ndarray
    radius: np.ndarray
    kappa: np.ndarray
    arc: np.ndarray
    length: np.ndarray
    Q: np.ndarray
    t: np.ndarray
    face_normal: np.ndarray
    S: np.ndarray | None = None

    @property
    def conical(self) -> np.ndarray:
        """(k,) bool: the conical sides."""
        if self.S is None:
            return np.zeros(len(self.edge), dtype=bool)
        return ~np.isnan(self.S[:, 0])

    def chart(self, i: np.ndarray, s: np.ndarray):
        """Base-curve points, rulings and their images in the sides' charts at arc parameters
        ``s`` (m,) of sides ``i`` (m,): ``C``, ``R`` (m, 3), ``c``, ``r`` (m, 2).

        A cylinder's chart is ``c = (s, 0)``, ``r = (0, 1)`` with ``R`` the edge direction; a
        conical side's is its fillet's (:func:`~filletfold.rounding.tapered.fillet_chart`).
        """
        i, s = np.asarray(i, dtype=np.int64), np.asarray(s, dtype=float)
        C = self.base(i, s)
        R = self.R[i].copy()
        c = np.stack([s, np.zeros_like(s)], axis=1)
        r = np.repeat([[0.0, 1.0]], len(s), axis=0)
        cone = self.conical[i]
        if cone.any():
            k = i[cone]
            theta = series_angles(self.angle_series(), self.arc, k, s[cone])
            _, R[cone], c[cone], r[cone], _ = fillet_chart(
                self.fillet_rows(k), s[cone], theta=theta
            )
        return C, R, c, r

    def fillet_rows(self, i: np.ndarray) -> FilletRows:
        """The conical fillets of sides ``i`` (k,) int, as rows
        (:class:`~filletfold.rounding.tapered.FilletRows`)."""
        return FilletRows(
            self.O[i], self.N0[i], self.B[i], self.kappa[i], self.radius[i], self.S[i]
        )

    def angle_series(self) -> np.ndarray:
        """(k, L) float: per side, the series of its conical fillet's developed angle over its
        arc (:func:`~filletfold.rounding.tapered.angle_series`; zero on the other sides),
        computed once per :class:`SideArrays`."""
        series = self.__dict__.get("_angle_series")
        if series is None:
            cone = np.flatnonzero(self.conical)
            series = np.zeros((len(self.edge), 1))
            if len(cone):
                found = angle_series(self.fillet_rows(cone), self.arc[cone])
                series = np.zeros((len(self.edge), found.shape[1]))
                series[cone] = found
            self.__dict__["_angle_series"] = series
        return series

    def cone_chart(self, i: np.ndarray, s: np.ndarray):
        """:meth:`chart` of the rows on conical sides only (``None`` when there are none):
        what :meth:`row_maps` and :meth:`surface_normal` share when given the same rows."""
        i = np.asarray(i, dtype=np.int64)
        cone = self.conical[i]
        if not cone.any():
            return None
        return self.chart(i[cone], np.asarray(s, dtype=float)[cone])

    def row_maps(self, i: np.ndarray, s: np.ndarray, cone_chart=None):
        """Per-row charts in which every side reads as a cylinder, for eq. (1) as written.

        On a conical side the chart at ``s`` is turned and moved so that ``c(s)`` lands on
        ``(s, 0)`` and ``r(s)`` on ``(0, 1)``; with ``R`` the ruling at ``s`` and ``M = C(s)``,
        :func:`~filletfold.vertex.crease.crease_numerator` and
        :func:`~filletfold.vertex.crease.crease_denominator` then give the ruled form of
        eq. (1) (:func:`~filletfold.rounding.tapered.crease_height_ruled`), and their
        gradients hold unchanged. On a cylinder these are ``Q``, ``t``, ``R`` and ``M``.

        Returns
        -------
        Q : (m, 2, 2) float
        t : (m, 2) float
            The map from the common frame into each row's chart.
        R, M : (m, 3) float

        ``cone_chart`` is :meth:`cone_chart` of the same rows, when the caller has it.
        """
        i, s = np.asarray(i, dtype=np.int64), np.asarray(s, dtype=float)
        Q, t, R, M = self.Q[i], self.t[i], self.R[i], self.M[i]  # copies (fancy indexing)
        cone = self.conical[i]
        if cone.any():
            C, Rc, c, r = self.chart(i[cone], s[cone]) if cone_chart is None else cone_chart
            # the turn taking r = (sin th, cos th) to (0, 1)
            rot = np.stack([np.stack([r[:, 1], -r[:, 0]], -1), np.stack([r[:, 0], r[:, 1]], -1)], 1)
            Q[cone] = rot @ Q[cone]
            shift = np.stack([s[cone], np.zeros(len(C))], axis=1) - np.einsum("kij,kj->ki", rot, c)
            t[cone] = np.einsum("kij,kj->ki", rot, t[cone]) + shift
            R[cone], M[cone] = Rc, C
        return Q, t, R, M

    def surface_normal(self, i: np.ndarray, s: np.ndarray, cone_chart=None, N=None) -> np.ndarray:
        """(m, 3) front normals of the sides' surfaces along their base curves: ``N(s)`` on a
        cylinder, ``unit(C'(s) x R(s))`` on a conical fillet (the faces' normals at the
        ends). ``cone_chart`` (:meth:`cone_chart` of the same rows) and ``N``
        (:meth:`normal` of them), when the caller has them, are not computed again."""
        N = self.normal(i, s) if N is None else N.copy()
        cone = self.conical[np.asarray(i, dtype=np.int64)]
        if cone.any():
            k = np.asarray(i, dtype=np.int64)[cone]
            if cone_chart is None:
                cone_chart = self.chart(k, np.asarray(s, dtype=float)[cone])
            Rc = cone_chart[1]
            n = np.cross(self.tangent(k, np.asarray(s, dtype=float)[cone]), Rc)
            N[cone] = n / np.linalg.norm(n, axis=1)[:, None]
        return N

    def _angle(self, i: np.ndarray, s: np.ndarray) -> np.ndarray:
        """(m, 1) turning angles ``s / r`` of sides ``i`` (0 on a side of radius 0)."""
        r = self.radius[i]
        return np.where(r > 0, s / np.where(r > 0, r, 1.0), 0.0)[:, None]

    def normal(self, i: np.ndarray, s: np.ndarray) -> np.ndarray:
        """(m, 3) front normals at arc parameters ``s`` (m,) of sides ``i`` (m,)."""
        ang = self._angle(i, s)
        return np.cos(ang) * self.N0[i] + np.sin(ang) * self.B[i]

    def tangent(self, i: np.ndarray, s: np.ndarray) -> np.ndarray:
        """(m, 3) unit tangents ``C'(s)`` of sides ``i`` (``B = R x N0`` on a flat side)."""
        ang = self._angle(i, s)
        k = np.where(self.radius[i] > 0, self.kappa[i], 1.0)[:, None]
        return k * (-np.sin(ang) * self.N0[i] + np.cos(ang) * self.B[i])

    def base(self, i: np.ndarray, s: np.ndarray) -> np.ndarray:
        """(m, 3) base-curve points ``C(s)`` of sides ``i``."""
        return self.base_normal(i, s)[0]

    def base_normal(self, i: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(m, 3) base-curve points ``C(s)`` and (m, 3) front normals ``N(s)`` of sides ``i``
        (the normals computed once for both)."""
        N = self.normal(i, s)
        return self.O[i] + (self.kappa[i] * self.radius[i])[:, None] * N, N

    def samples(self, n_samples):
        """Evenly spaced samples along every arc, ends included (one on a flat side).

        Parameters
        ----------
        n_samples : int or (k,) int
            Samples per arc, for all sides or per side.

        Returns
        -------
        side : (m,) int
            Side of each sample, sides one after another.
        first, last : (k,) int
            Each side's first and last sample.
        s : (m,) float
            Arc parameters.
        C, N : (m, 3) float
            Base-curve points and normals.
        """
        ks = np.where(self.arc > 0, n_samples, 1)
        side = run_owners(ks)
        first = run_starts(ks)[:-1]
        s = self.arc[side] * (np.arange(len(side)) - first[side]) / np.maximum(ks[side] - 1, 1)
        return side, first, first + ks - 1, s, *self.base_normal(side, s)


def stack_sides(sides: list, Q=None, t=None, face_normal=None) -> SideArrays:
    """Rounded :class:`Side` objects as :class:`SideArrays` (charts and face normals as given,
    None by default)."""
    return SideArrays(
        edge=np.array([x.edge for x in sides], dtype=np.int64),
        R=np.array([x.R for x in sides]),
        M=np.array([x.M for x in sides]),
        O=np.array([x.O for x in sides]),
        N0=np.array([x.N0 for x in sides]),
        B=np.array([x.B for x in sides]),
        radius=np.array([x.radius for x in sides]),
        kappa=np.array([x.kappa for x in sides], dtype=float),
        arc=np.array([x.arc for x in sides]),
        length=np.array([x.length for x in sides]),
        Q=Q,
        t=t,
        face_normal=face_normal,
        S=np.array([np.full(3, np.nan) if x.S is None else x.S for x in sides]).reshape(-1, 3),
    )


@dataclass
class _SideStore:
    """The sides of many vertices on flat arrays (:func:`vertex_frames`), from which each
    vertex's :class:`Side` objects are made when first asked for (:class:`_Sides`)."""

    sides: SideArrays
    rounded: np.ndarray  # (P,) bool
    gamma: np.ndarray  # (P,) float

    def side(self, p: int) -> Side:
        """Side ``p`` as a :class:`Side` (Python scalars, rows of the arrays as vectors)."""
        sa = self.sides
        head = (int(sa.edge[p]), bool(self.rounded[p]), sa.R[p], sa.M[p], float(sa.length[p]))
        if not head[1]:
            return Side(*head)
        return Side(
            *head,
            float(sa.radius[p]),
            float(self.gamma[p]),
            float(sa.arc[p]),
            int(sa.kappa[p]),
            sa.O[p],
            sa.N0[p],
            sa.B[p],
            None if sa.S is None or np.isnan(sa.S[p, 0]) else sa.S[p],
        )


class _Sides(Sequence):
    """The :class:`Side` objects of one vertex, made from a :class:`_SideStore` on first use."""

    __slots__ = ("_items", "_lo", "_n", "_store")

    def __init__(self, store: _SideStore, lo: int, hi: int):
        self._store, self._lo, self._n, self._items = store, lo, hi - lo, None

    def __len__(self) -> int:
        return self._n

    def __getitem__(self, i):
        if self._items is None:
            self._items = [self._store.side(p) for p in range(self._lo, self._lo + self._n)]
        return self._items[i]


class _Maps(Sequence):
    """A vertex's cylinder maps: (3, 3) rows of an array, None on an unrounded side."""

    __slots__ = ("maps", "rounded")

    def __init__(self, maps: np.ndarray, rounded: np.ndarray):
        self.maps, self.rounded = maps, rounded

    def __len__(self) -> int:
        return len(self.maps)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        return self.maps[i] if self.rounded[i] else None


@dataclass
class VertexFrame:
    """Sides, charts and 2D maps of one vertex.

    Attributes
    ----------
    vertex : int
    ring : VertexRing
    U : (3,) float
    sides : sequence of Side
        One per ring edge (made on first use in the frames of :func:`vertex_frames`).
    face_frames : sequence of (3, 3) float
        Chart of each ring face (origin U).
    cyl_map : sequence of (3, 3) float or None
        Map of each rounded side's cylinder chart ``(s, z)`` into the common frame.
    face_map : sequence of (3, 3) float
        Map of each ring face's chart into the common frame (for a closed ring, face ``n-1``
        maps by ``rho``, i.e. it is ``tau'``; ``tau`` itself is the identity).
    rho : (3, 3) float or None
        The map ``tau -> tau'`` (closed rings).
    lmax_start, lmax_end : (n_sides,) float
        Distance from the midpoint cross-section to the crossing point T of the tangent lines,
        along the side's line on face ``f_{i-1}`` (start) and ``f_i`` (end); NaN where the side
        has no such face.
    T_start, T_end : (n_sides, 3) float
        Those crossing points.
    corner_angle : (n_faces,) float
        Face angle of each ring face at the vertex (radians; above pi at a reflex corner).
    sharp : bool
        The vertex is sharp: it keeps its corner, and its module is the fan of
        :mod:`filletfold.surface.sharp` (``vertex_frames(..., sharp=)``).
    """

    vertex: int
    ring: VertexRing
    U: np.ndarray
    sides: list
    face_frames: list
    cyl_map: list
    face_map: list
    rho: np.ndarray | None
    lmax_start: np.ndarray
    lmax_end: np.ndarray
    T_start: np.ndarray
    T_end: np.ndarray
    corner_angle: np.ndarray
    sharp: bool = False

    @property
    def n_sides(self) -> int:
        return len(self.sides)

    @property
    def rounded(self) -> np.ndarray:
        """(n_sides,) bool: which sides have a cylinder chart (``cyl_map`` not None)."""
        if isinstance(self.cyl_map, _Maps):
            return self.cyl_map.rounded
        return np.array([m is not None for m in self.cyl_map], dtype=bool)

    @property
    def cyl_maps(self) -> np.ndarray:
        """(n_sides, 3, 3) float: ``cyl_map`` as one array, NaN on an unrounded side."""
        if isinstance(self.cyl_map, _Maps):
            return self.cyl_map.maps
        return np.array([np.full((3, 3), np.nan) if m is None else m for m in self.cyl_map])

    @functools.cached_property
    def arrays(self) -> SideArrays:
        """The sides' and faces' data stacked into arrays (closed rings)."""
        maps = np.array(self.cyl_map)  # (k, 3, 3) rigid: the inverse is [Q^T, -Q^T t]
        Q = maps[:, :2, :2].transpose(0, 2, 1)
        faces = np.array(self.face_frames)
        return stack_sides(
            self.sides,
            Q=Q,
            t=-np.einsum("kij,kj->ki", Q, maps[:, :2, 2]),
            face_normal=np.cross(faces[:, 1], faces[:, 2]),
        )

    def rotation_angle(self) -> float:
        """Rotation angle of ``rho`` (radians, in (-pi, pi])."""
        return float(np.arctan2(self.rho[1, 0], self.rho[0, 0]))

    def developed_apex(self) -> np.ndarray | None:
        """The fixed point of ``rho`` in the common frame, or None if ``rho`` is a translation
        (:func:`developed_apices` of this vertex).

        Returns
        -------
        (2,) float or None
        """
        v = developed_apices(self.rho[None])[0]
        return None if np.isnan(v[0]) else v

    def gluing_start(self, i: int) -> np.ndarray:
        """Map from cylinder ``i``'s chart into the chart of face ``f_{i-1}``."""
        side = self.sides[i]
        frame = self.face_frames[(i - 1) % len(self.ring.faces)]
        return self._gluing(side, frame, 0.0)

    @staticmethod
    def _gluing(side: Side, frame: np.ndarray, s: float) -> np.ndarray:
        s = np.array([s], dtype=float)
        return gluing_maps(side.tangent(s), side.R[None], frame[None], side.base(s), s)[0]


def developed_apices(rho: np.ndarray, min_det: float = tol.fixed_point) -> np.ndarray:
    """The developed apices of many vertices (paper sec. 2.4): the fixed points of their maps
    ``rho`` (``tau -> tau'``).

    A crease point on ``tau`` and its copy on ``tau'`` must be equally far from the developed
    apex ``v`` for the crease to close tangent continuously, so ``v`` is the centre of the
    rotation ``rho = [Q, t]``: ``v = Q v + t``, i.e. ``(I - Q) v = t``. ``det(I - Q)`` is
    ``4 sin^2(theta / 2)`` for a turn by ``theta`` (minus the angle defect): a map that turns
    by (almost) nothing is a translation, with no fixed point.

    Parameters
    ----------
    rho : (n, 3, 3) float
        Rigid homogeneous 2D maps.
    min_det : float
        Below this ``|det(I - Q)|`` a map has no fixed point (default ``tol.fixed_point``).

    Returns
    -------
    (n, 2) float
        Fixed points in each vertex's common frame; NaN where there is none.
    """
    rho = np.asarray(rho, dtype=float).reshape(-1, 3, 3)
    a = np.eye(2) - rho[:, :2, :2]
    turns = np.abs(np.linalg.det(a)) >= min_det
    v = np.full((len(rho), 2), np.nan)
    if turns.any():
        v[turns] = np.linalg.solve(a[turns], rho[turns, :2, 2, None])[..., 0]
    return v


def gluing_maps(
    tangent: np.ndarray, R: np.ndarray, frames: np.ndarray, C: np.ndarray, s: np.ndarray
) -> np.ndarray:
    """Maps from cylinder charts ``(s, z)`` into face charts, where cylinder and face touch.

    Parameters
    ----------
    tangent : (k, 3) float
        Unit tangent ``C'(s)`` of the base curve at the contact line.
    R : (k, 3) float
        Unit edge direction (the charts' ``z`` axis).
    frames : (k, 3, 3) float
        The faces' charts (rows origin, e1, e2).
    C : (k, 3) float
        Base-curve point ``C(s)`` on the contact line.
    s : (k,) float
        Arc parameter of the contact line.

    Returns
    -------
    (k, 3, 3) float
        Rigid maps: ``(s, 0) -> C`` and the chart axes ``(C'(s), R)`` onto the face's.
    """
    axes = frames[:, 1:]
    lin = np.stack([dot_rows(axes, tangent[:, None]), dot_rows(axes, R[:, None])], axis=-1)
    p = dot_rows(axes, (C - frames[:, 0])[:, None])
    return rigid(lin, p - lin[..., 0] * s[:, None])


def _line_crossings(p1, d1, p2, d2):
    """Parameters ``z1, z2`` (k,) with ``p1 + z1 d1 ~= p2 + z2 d2``, row by row.

    Least squares; ``p1, p2`` (k, 3) points, ``d1, d2`` (k, 3) unit directions. Where two lines
    are (nearly) parallel, the least-squares solution of smallest norm (that of
    :func:`numpy.linalg.lstsq`).
    """
    delta = p2 - p1
    c, a, b = dot_rows(d1, d2), dot_rows(d1, delta), dot_rows(d2, delta)
    det = 1.0 - c * c
    parallel = det < tol.parallel
    det = np.where(parallel, 1.0, det)
    z1, z2 = (a - c * b) / det, (c * a - b) / det
    if parallel.any():  # minimum-norm least squares, singular values cut as lstsq does
        A = np.stack([d1[parallel], -d2[parallel]], axis=-1)  # (m, 3, 2)
        u, sv, vt = np.linalg.svd(A, full_matrices=False)
        keep = sv > 3 * np.finfo(float).eps * sv[:, :1]
        w = np.einsum("mij,mi->mj", u, delta[parallel])
        w = np.where(keep, w / np.where(keep, sv, 1.0), 0.0)
        z = np.einsum("mji,mj->mi", vt, w)
        z1[parallel], z2[parallel] = z[:, 0], z[:, 1]
    return z1, z2


def _halfedge_ids(mesh: PolyMesh, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k,) int: the half-edges ``a -> b`` (k,), -1 where there is none.

    :meth:`PolyMesh.halfedge` for arrays.
    """
    keys = mesh._he_key_sorted
    k = np.asarray(a, dtype=np.int64) * mesh.n_vertices + b
    if not len(keys):
        return np.full(k.shape, -1, dtype=np.int64)
    i = np.minimum(np.searchsorted(keys, k), len(keys) - 1)
    return np.where(keys[i] == k, mesh._he_order[i], -1)


def closed_ring_sides(mesh: PolyMesh, verts):
    """The sides of the closed rings among ``verts``, without their frames: what telling a
    saddle apart needs (:func:`~filletfold.vertex.solve.saddle_vertices`), as
    :func:`vertex_frames` finds it (rings in the same order, from the same walks), for the
    vertices ``verts`` (n,) of ``mesh``.

    Returns
    -------
    closed : (c,) int
        The positions in ``verts`` of the closed rings.
    R : (P, 3) float
        Each side's :attr:`Side.R` (unit, from its neighbour to the vertex), rings one after
        another.
    edge, face : (P,) int
        Each side's edge and the ring face after it (``e_i``, ``f_i``).
    count : (c,) int
        Sides per closed ring.

    Raises MeshError as :func:`vertex_frames` does.
    """
    verts = np.asarray(verts, dtype=np.int64).reshape(-1)
    he, nf, _, closed = _ring_walks(mesh, verts)
    idx = np.flatnonzero(closed)
    count = nf[idx]
    sv = np.repeat(idx, count)
    sp = np.arange(int(count.sum())) - np.repeat(run_starts(count)[:-1], count)
    h = he[sv, sp]
    d = mesh.vertices[verts][sv] - mesh.vertices[mesh.halfedge_to[h]]
    R = d / norm_rows(d)[:, None]
    return idx, R, mesh.halfedge_edge[h], mesh.halfedge_face[h], count


def _ring_walks(mesh: PolyMesh, verts: np.ndarray):
    """Walk the rings of many vertices at once, as :meth:`PolyMesh.vertex_ring` does one by one.

    Parameters
    ----------
    mesh : PolyMesh
    verts : (n,) int

    Returns
    -------
    he : (n, w) int
        ``he[j, i]`` is the half-edge ``u -> q`` of ring face ``f_i`` (``i < n_faces[j]``; the
        ring's edge ``e_i`` and face ``f_i``), -1 beyond.
    n_faces : (n,) int
    last : (n,) int
        The half-edge ``p -> u`` whose edge closes an open ring (-1 for a closed ring).
    closed : (n,) bool

    Raises
    ------
    MeshError
        As :meth:`PolyMesh.vertex_ring`, for the first vertex whose ring is not a single fan.
    """
    frm = mesh.halfedge_from
    out = np.nonzero(np.isin(frm, verts))[0]
    out = out[np.argsort(frm[out], kind="stable")]  # outgoing half-edges by vertex, then index
    gv, gstart, gcount = np.unique(frm[out], return_index=True, return_counts=True)
    g = np.minimum(np.searchsorted(gv, verts), max(len(gv) - 1, 0))
    used = gv[g] == verts if len(gv) else np.zeros(len(verts), dtype=bool)
    # start: the first outgoing u -> q without a reverse (an open ring), else the first one
    pos = np.arange(len(out))
    key = np.where(_halfedge_ids(mesh, mesh.halfedge_to[out], frm[out]) < 0, pos, pos + len(out))
    first = np.minimum.reduceat(key, gstart) if len(out) else key
    closed_g = first >= len(out)
    start = out[np.where(closed_g, gstart, first)][g] if len(out) else np.zeros(len(verts), int)
    closed = closed_g[g] if len(out) else np.ones(len(verts), dtype=bool)
    n_out = np.where(used, gcount[g] if len(out) else 0, 0)
    n = len(verts)
    width = int(n_out.max(initial=0))
    he = np.full((n, width + 1), -1, dtype=np.int64)
    last = np.full(n, -1, dtype=np.int64)
    n_faces = np.zeros(n, dtype=np.int64)
    bad = ~used
    active = used.copy()
    cur = start.copy()
    for k in range(width + 1):
        over = active & (k >= n_out)  # more faces than outgoing half-edges: not a fan
        bad |= over
        active &= ~over
        idx = np.nonzero(active)[0]
        if not len(idx):
            break
        h = cur[idx]
        he[idx, k] = h
        ph = mesh.halfedge_prev[h]  # p -> u in the same face; the next face holds u -> p
        nh = _halfedge_ids(mesh, verts[idx], frm[ph])
        end = nh < 0  # reached the boundary: the last edge is (u, p)
        last[idx[end]] = ph[end]
        stop = end | (nh == start[idx])
        n_faces[idx[stop]] = k + 1
        active[idx[stop]] = False
        cur[idx[~stop]] = nh[~stop]
    bad |= n_faces != n_out
    for u in verts[bad]:
        mesh.vertex_ring(int(u))  # raises the MeshError that names the problem
        raise MeshError(f"non-manifold vertex {u}: its faces do not form a fan", vertex=int(u))
    return he[:, :width], n_faces, last, closed


def vertex_frames(
    mesh: PolyMesh, rounding: EdgeRounding, vertices, start_edges=None, sharp=None
) -> list[VertexFrame]:
    """Build the sides, T points and development of many vertices at once.

    Every formula runs on flat arrays over all the vertices' (vertex, ring position) pairs;
    the development's chained maps run ring position by ring position, over all vertices.

    Parameters
    ----------
    mesh : PolyMesh
    rounding : EdgeRounding
    vertices : sequence of int
        The vertices, (n,).
    start_edges : sequence of (int or None), optional
        Per vertex, for a closed ring: the incident edge to list first. The development is cut
        along the start of its cylinder, so this chooses where the module's angle-defect cut
        runs. None (or an edge not in the ring) keeps the ring's own order.
    sharp : (n_vertices,) bool, optional
        The sharp vertices (no cone, the corner kept). A rounded side of a vertex that is not
        sharp, whose other end is, is *conical*: its edge is rounded by the conical fillet
        from that end (:mod:`filletfold.rounding.tapered`), so its T points lie on the
        fillet's end rulings and its gluing maps are the fillet's. None: no sharp vertex.

    Returns
    -------
    list of VertexFrame
        In the order of ``vertices``; the frames of closed rings come with their
        :attr:`VertexFrame.arrays` filled in.

    Raises
    ------
    MeshError
        If a vertex is not used by any face or its faces do not form a single fan.
    """
    verts = np.asarray(vertices, dtype=np.int64).reshape(-1)
    n = len(verts)
    if start_edges is not None and len(start_edges) != n:
        raise ValueError(f"{len(start_edges)} start edges for {n} vertices")
    if n == 0:
        return []
    he, nf, last, closed = _ring_walks(mesh, verts)
    ne = nf + ~closed
    he_edge = mesh.halfedge_edge
    shift = np.zeros(n, dtype=np.int64)  # closed rings: position of the start edge
    if start_edges is not None:
        want = np.array([-1 if e is None else int(e) for e in start_edges], dtype=np.int64)
        hit = (he_edge[he] == want[:, None]) & (he >= 0) & closed[:, None]
        shift = np.where(hit.any(axis=1), hit.argmax(axis=1), 0)

    # ---- flat (vertex, ring position) pairs: sides (one per edge) and faces
    so = run_starts(ne)
    fo = run_starts(nf)
    sv = run_owners(ne)  # (P,) vertex of each side
    sp = np.arange(so[-1]) - so[sv]  # (P,) its ring position
    fv = run_owners(nf)  # (F,) vertex of each face
    fp = np.arange(fo[-1]) - fo[fv]
    nfs = nf[sv]
    fh = he[fv, (fp + shift[fv]) % nf[fv]]  # (F,) half-edge u -> q in face f_i
    sh = he[sv, (sp + shift[sv]) % nfs]  # (P,) half-edge u -> q of edge e_i (i < n_faces)
    tail = sp >= nfs  # the last edge of an open ring
    lh = last[sv[tail]]
    edge = he_edge[sh]
    edge[tail] = he_edge[lh]
    nbr = mesh.halfedge_to[sh]
    nbr[tail] = mesh.halfedge_from[lh]
    face = mesh.halfedge_face[fh]
    corner = mesh.corner_angles()[fh]

    # ---- sides (see Side): rounded ones run from f_{i-1} to f_i
    U = mesh.vertices[verts]
    other = mesh.vertices[nbr]
    d = U[sv] - other
    length = norm_rows(d)
    R = d / length[:, None]
    M = 0.5 * (U[sv] + other)
    rounded = closed[sv] | ((sp > 0) & ~tail)
    f_prev = fo[sv] + (sp - 1) % nfs  # (P,) flat face f_{i-1}, f_i (valid on rounded sides)
    f_next = fo[sv] + sp % nfs
    normals = mesh.face_normal[face]
    n_prev = normals[f_prev]
    curved = rounded & (rounding.radius[edge] > 0)  # else a flat edge: a cylinder of radius 0
    N0 = np.where(rounded[:, None], n_prev, 0.0)
    B = np.where(rounded[:, None], np.cross(R, n_prev), 0.0)
    c = np.nonzero(curved)[0]
    n_next = normals[f_next[c]]
    # B: the unit vector across the edge in the plane of N0 and N(a), turned toward N(a). As
    # R x N0 it is orthogonal to R and N0 to round-off; orthogonalising N(a) against N0
    # instead loses digits on a nearly flat edge (1e-12 off R at a 0.1 degree bend, and the
    # development's maps stop being rigid by as much)
    B[c] *= np.sign(dot_rows(B[c], n_next))[:, None]
    O = M.copy()
    O[c] = rounding.axis_point[edge[c]]
    radius = np.where(curved, rounding.radius[edge], 0.0)
    gamma = np.where(curved, rounding.half_angle[edge], 0.0)
    arc = np.where(curved, rounding.arc_length[edge], 0.0)
    kappa = np.where(curved, rounding.kappa[edge], 0).astype(np.int64)
    S = np.full((len(sv), 3), np.nan)
    if sharp is not None:
        sharp = np.asarray(sharp, dtype=bool)
        cone = curved & sharp[nbr] & ~sharp[verts][sv]
        S[cone] = other[cone]
    # boundary sides get O = M and zero N0, B here, so that their base curve is the point M
    sa = SideArrays(
        edge=edge.astype(np.int64),
        R=R,
        M=M,
        O=O,
        N0=N0,
        B=B,
        radius=radius,
        kappa=kappa.astype(float),
        arc=arc,
        length=length,
        Q=None,
        t=None,
        face_normal=None,
        S=S,
    )
    cone = sa.conical
    frames = np.concatenate([U[fv][:, None], _face_axes(mesh, face)], axis=1)  # (F, 3, 3)

    # ---- T points: the tangent lines on face f_i of sides i (its end) and i + 1 (its start)
    si = so[fv] + fp
    sj = so[fv] + (fp + 1) % ne[fv]
    p1 = sa.base(si, arc[si])
    p2 = sa.base(sj, np.zeros(len(sj)))
    d1, d2 = R[si], R[sj]  # a conical side's line on the face is its end ruling from S
    if cone.any():
        d1, d2 = d1.copy(), d2.copy()
        d1[cone[si]] = sa.chart(si[cone[si]], arc[si[cone[si]]])[1]
        d2[cone[sj]] = sa.chart(sj[cone[sj]], np.zeros(int(cone[sj].sum())))[1]
    z1, z2 = _line_crossings(p1, d1, p2, d2)
    lmax_start, lmax_end = np.full(len(sv), np.nan), np.full(len(sv), np.nan)
    T_start, T_end = np.full((len(sv), 3), np.nan), np.full((len(sv), 3), np.nan)
    lmax_end[si], lmax_start[sj] = z1, z2
    T_end[si] = p1 + z1[:, None] * d1
    T_start[sj] = p2 + z2[:, None] * d2

    # ---- development: chain tau -> cylinder 0 -> f_0 -> ... (closed) or f_0 -> ... (open)
    rs = np.nonzero(rounded)[0]
    s0 = np.zeros(len(rs))
    g_start = np.full((len(sv), 3, 3), np.nan)
    g_end_inv = np.full((len(sv), 3, 3), np.nan)
    g_start[rs] = gluing_maps(sa.tangent(rs, s0), R[rs], frames[f_prev[rs]], sa.base(rs, s0), s0)
    t_end = sa.tangent(rs, arc[rs])
    unbent = ~curved[rs]  # a side of radius 0 (flat or sharp) meets f_i along its own line
    t_end[unbent] = np.cross(R[rs[unbent]], normals[f_next[rs[unbent]]])
    g_end_inv[rs] = invert(
        gluing_maps(t_end, R[rs], frames[f_next[rs]], sa.base(rs, arc[rs]), arc[rs])
    )
    if cone.any():  # a conical side touches its faces along its end rulings
        k = np.flatnonzero(cone)
        for ends, face_of, store in ((np.zeros(len(k)), f_prev, "start"), (arc[k], f_next, "end")):
            C, Rc, c, r = sa.chart(k, ends)
            E, e = perpendiculars(C, sa.tangent(k, ends), Rc, c, r)
            g = ruled_gluing_maps(frames[face_of[k]], C, Rc, E, c, r, e)
            if store == "start":
                g_start[k] = g
            else:
                g_end_inv[k] = invert(g)
    current = np.repeat(np.eye(3)[None], n, axis=0)  # tau = f_{n-1}; f_0 for an open ring
    cyl_map = np.full((len(sv), 3, 3), np.nan)
    face_map = np.empty((len(fv), 3, 3))
    for k in range(int(ne.max())):
        j = np.nonzero(k < ne)[0]
        j = j[rounded[so[j] + k]]
        p = so[j] + k
        cyl_map[p] = current[j] @ g_start[p]
        current[j] = cyl_map[p] @ g_end_inv[p]
        j = np.nonzero(k < nf)[0]
        face_map[fo[j] + k] = current[j]
    sa.Q = cyl_map[:, :2, :2].transpose(0, 2, 1)  # maps are rigid: the inverse is [Q^T, -Q^T t]
    sa.t = -np.einsum("kij,kj->ki", sa.Q, cyl_map[:, :2, 2])
    sa.face_normal = np.cross(frames[:, 1], frames[:, 2])

    # ---- objects: each vertex's views of the flat arrays (its Side objects made on first use)
    store = _SideStore(sa, rounded, gamma)
    per_side = [(fd.name, getattr(sa, fd.name)) for fd in fields(SideArrays)]
    per_side = [(name, a) for name, a in per_side if name != "face_normal"]
    result = []
    for j, u in enumerate(verts.tolist()):
        s, s2, f, f2 = so[j], so[j + 1], fo[j], fo[j + 1]
        ring = VertexRing(
            vertex=u,
            edges=sa.edge[s:s2],
            faces=face[f:f2],
            neighbors=nbr[s:s2],
            closed=bool(closed[j]),
        )
        frame = VertexFrame(
            vertex=u,
            ring=ring,
            U=mesh.vertices[u],
            sides=_Sides(store, s, s2),
            face_frames=frames[f:f2],
            cyl_map=_Maps(cyl_map[s:s2], rounded[s:s2]),
            face_map=face_map[f:f2],
            rho=current[j] if ring.closed else None,
            lmax_start=lmax_start[s:s2],
            lmax_end=lmax_end[s:s2],
            T_start=T_start[s:s2],
            T_end=T_end[s:s2],
            corner_angle=corner[f:f2],
            sharp=bool(sharp is not None and sharp[u]),
        )
        if ring.closed:
            frame.__dict__["arrays"] = SideArrays(
                **{name: a[s:s2] for name, a in per_side},
                face_normal=sa.face_normal[f:f2],
            )
        result.append(frame)
    return result


def vertex_frame(
    mesh: PolyMesh, rounding: EdgeRounding, u: int, start_edge: int | None = None
) -> VertexFrame:
    """Build the sides, T points and development of vertex ``u``.

    One vertex through :func:`vertex_frames`.

    Parameters
    ----------
    mesh : PolyMesh
    rounding : EdgeRounding
    u : int
    start_edge : int, optional
        For a closed ring: the incident edge to list first. The development is cut along the
        start of its cylinder, so this chooses where the module's angle-defect cut runs.

    Returns
    -------
    VertexFrame
    """
    return vertex_frames(mesh, rounding, [u], [start_edge])[0]
