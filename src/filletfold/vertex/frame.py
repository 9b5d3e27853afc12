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
angle defect; the developed apex is its fixed point (METHOD-NOTES, "one common 2D frame").
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..mesh.polymesh import PolyMesh, VertexRing
from ..rounding import EdgeRounding


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

    def start_point(self):
        """Point of the side's line on face ``f_{i-1}`` in the midpoint cross-section."""
        return self.base([0.0])[0] if self.rounded else self.M

    def end_point(self):
        """Point of the side's line on face ``f_i`` in the midpoint cross-section."""
        return self.base([self.arc])[0] if self.rounded else self.M


def face_frame(mesh: PolyMesh, f: int, origin: np.ndarray) -> np.ndarray:
    """(3, 3) rows: origin, e1, e2 of an orientation-preserving chart of face ``f``."""
    n = mesh.face_normal[f]
    face = mesh.faces[f]
    d = mesh.vertices[face[1]] - mesh.vertices[face[0]]
    e1 = d / np.linalg.norm(d)
    e2 = np.cross(n, e1)
    return np.stack([origin, e1, e2])


def to_chart(frame: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Chart coordinates (k, 2) of 3D points ``p`` (k, 3) on a face with ``frame``."""
    q = np.atleast_2d(p) - frame[0]
    return np.stack([q @ frame[1], q @ frame[2]], axis=-1)


def rigid(linear: np.ndarray, t: np.ndarray) -> np.ndarray:
    """3x3 homogeneous matrix of the 2D map ``x -> linear @ x + t``."""
    m = np.eye(3)
    m[:2, :2] = linear
    m[:2, 2] = t
    return m


def apply(m: np.ndarray, p) -> np.ndarray:
    """Apply a 3x3 homogeneous 2D map to points (k, 2)."""
    p = np.atleast_2d(np.asarray(p, dtype=float))
    return p @ m[:2, :2].T + m[:2, 2]


def invert(m: np.ndarray) -> np.ndarray:
    """Inverse of a rigid 3x3 homogeneous 2D map."""
    q = m[:2, :2].T
    return rigid(q, -q @ m[:2, 2])


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

    def normal(self, i: np.ndarray, s: np.ndarray) -> np.ndarray:
        """(m, 3) front normals at arc parameters ``s`` (m,) of sides ``i`` (m,)."""
        r = self.radius[i]
        ang = np.where(r > 0, s / np.where(r > 0, r, 1.0), 0.0)[:, None]
        return np.cos(ang) * self.N0[i] + np.sin(ang) * self.B[i]

    def base(self, i: np.ndarray, s: np.ndarray) -> np.ndarray:
        """(m, 3) base-curve points ``C(s)`` of sides ``i``."""
        return self.O[i] + (self.kappa[i] * self.radius[i])[:, None] * self.normal(i, s)

    def samples(self, n_samples: int):
        """Evenly spaced samples along every arc, ends included (one on a flat side).

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
        side = np.repeat(np.arange(len(ks)), ks)
        first = np.concatenate([[0], np.cumsum(ks)[:-1]])
        s = self.arc[side] * (np.arange(len(side)) - first[side]) / np.maximum(ks[side] - 1, 1)
        return side, first, first + ks - 1, s, self.base(side, s), self.normal(side, s)


@dataclass
class VertexFrame:
    """Sides, charts and 2D maps of one vertex.

    Attributes
    ----------
    vertex : int
    ring : VertexRing
    U : (3,) float
    sides : list of Side
        One per ring edge.
    face_frames : list of (3, 3) float
        Chart of each ring face (origin U).
    cyl_map : list of (3, 3) float or None
        Map of each rounded side's cylinder chart ``(s, z)`` into the common frame.
    face_map : list of (3, 3) float
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

    @property
    def n_sides(self) -> int:
        return len(self.sides)

    @functools.cached_property
    def arrays(self) -> SideArrays:
        """The sides' and faces' data stacked into arrays (closed rings)."""
        sides = self.sides
        maps = np.array(self.cyl_map)  # (k, 3, 3) rigid: the inverse is [Q^T, -Q^T t]
        Q = maps[:, :2, :2].transpose(0, 2, 1)
        faces = np.array(self.face_frames)
        return SideArrays(
            edge=np.array([s.edge for s in sides], dtype=np.int64),
            R=np.array([s.R for s in sides]),
            M=np.array([s.M for s in sides]),
            O=np.array([s.O for s in sides]),
            N0=np.array([s.N0 for s in sides]),
            B=np.array([s.B for s in sides]),
            radius=np.array([s.radius for s in sides]),
            kappa=np.array([s.kappa for s in sides], dtype=float),
            arc=np.array([s.arc for s in sides]),
            length=np.array([s.length for s in sides]),
            Q=Q,
            t=-np.einsum("kij,kj->ki", Q, maps[:, :2, 2]),
            face_normal=np.cross(faces[:, 1], faces[:, 2]),
        )

    def rotation_angle(self) -> float:
        """Rotation angle of ``rho`` (radians, in (-pi, pi])."""
        return float(np.arctan2(self.rho[1, 0], self.rho[0, 0]))

    def developed_apex(self) -> np.ndarray | None:
        """The fixed point of ``rho`` in the common frame, or None if ``rho`` is a translation.

        Returns
        -------
        (2,) float or None
        """
        q = self.rho[:2, :2]
        a = np.eye(2) - q
        if abs(np.linalg.det(a)) < 1e-14:
            return None
        return np.linalg.solve(a, self.rho[:2, 2])

    def gluing_start(self, i: int) -> np.ndarray:
        """Map from cylinder ``i``'s chart into the chart of face ``f_{i-1}``."""
        side = self.sides[i]
        frame = self.face_frames[(i - 1) % len(self.ring.faces)]
        return self._gluing(side, frame, 0.0)

    def gluing_end(self, i: int) -> np.ndarray:
        """Map from cylinder ``i``'s chart into the chart of face ``f_i``."""
        side = self.sides[i]
        return self._gluing(side, self.face_frames[i], side.arc)

    @staticmethod
    def _gluing(side: Side, frame: np.ndarray, s: float) -> np.ndarray:
        tan = side.tangent([s])[0]
        lin = np.array([[tan @ frame[1], side.R @ frame[1]], [tan @ frame[2], side.R @ frame[2]]])
        p = to_chart(frame, side.base([s])[0])[0]
        return rigid(lin, p - lin @ np.array([s, 0.0]))


def build_side(
    mesh: PolyMesh,
    rounding: EdgeRounding,
    u: int,
    e: int,
    n_prev: np.ndarray | None,
    n_next: np.ndarray | None,
) -> Side:
    """The side of edge ``e`` seen from vertex ``u``.

    ``n_prev`` and ``n_next`` are the front normals of the ring faces before and after the edge
    (``f_{i-1}`` and ``f_i``).
    """
    a, b = mesh.edges[e]
    other = b if a == u else a
    d = mesh.vertices[u] - mesh.vertices[other]
    length = float(np.linalg.norm(d))
    R = d / length
    M = 0.5 * (mesh.vertices[u] + mesh.vertices[other])
    common = {"edge": int(e), "R": R, "M": M, "length": length}
    if n_prev is None or n_next is None:
        return Side(rounded=False, **common)
    r = float(rounding.radius[e])
    if r <= 0:  # flat edge between coplanar faces: a cylinder of radius 0
        return Side(rounded=True, O=M, N0=n_prev, B=np.cross(R, n_prev), **common)
    B = n_next - (n_next @ n_prev) * n_prev
    B /= np.linalg.norm(B)
    return Side(
        rounded=True,
        radius=r,
        gamma=float(rounding.half_angle[e]),
        arc=float(rounding.arc_length[e]),
        kappa=int(rounding.kappa[e]),
        O=rounding.axis_point[e],
        N0=n_prev,
        B=B,
        **common,
    )


def _line_crossing(p1, d1, p2, d2):
    """Parameters (z1, z2) with p1 + z1 d1 ~= p2 + z2 d2 (least squares; unit d1, d2)."""
    delta = p2 - p1
    c = float(d1 @ d2)
    a, b = float(d1 @ delta), float(d2 @ delta)
    det = 1.0 - c * c
    if det < 1e-12:  # (nearly) parallel: the least-squares solution of smallest norm
        z, *_ = np.linalg.lstsq(np.stack([d1, -d2], axis=1), delta, rcond=None)
        return float(z[0]), float(z[1])
    return (a - c * b) / det, (c * a - b) / det


def vertex_frame(
    mesh: PolyMesh, rounding: EdgeRounding, u: int, start_edge: int | None = None
) -> VertexFrame:
    """Build the sides, T points and development of vertex ``u``.

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
    ring = mesh.vertex_ring(u)
    if ring.closed and start_edge is not None:
        hit = np.nonzero(ring.edges == start_edge)[0]
        if len(hit):
            k = int(hit[0])
            ring = VertexRing(
                vertex=ring.vertex,
                edges=np.roll(ring.edges, -k),
                faces=np.roll(ring.faces, -k),
                neighbors=np.roll(ring.neighbors, -k),
                closed=True,
            )
    U = mesh.vertices[u]
    nf = len(ring.faces)
    ne = len(ring.edges)
    normals = mesh.face_normal[ring.faces]
    sides = []
    for i, e in enumerate(ring.edges):
        prev = normals[i - 1] if (ring.closed or i > 0) else None
        nxt = normals[i] if (ring.closed or i < nf) else None
        sides.append(build_side(mesh, rounding, u, int(e), prev, nxt))
    frames = [face_frame(mesh, int(f), U) for f in ring.faces]
    angles = mesh.corner_angles()
    corner_angle = np.array([angles[mesh.halfedge(u, int(q))] for q in ring.neighbors[:nf]])
    lmax_start = np.full(ne, np.nan)
    lmax_end = np.full(ne, np.nan)
    T_start = np.full((ne, 3), np.nan)
    T_end = np.full((ne, 3), np.nan)
    for i in range(nf):
        j = (i + 1) % ne
        s1, s2 = sides[i], sides[j]
        p1, p2 = s1.end_point(), s2.start_point()
        z1, z2 = _line_crossing(p1, s1.R, p2, s2.R)
        lmax_end[i], lmax_start[j] = z1, z2
        T_end[i] = p1 + z1 * s1.R
        T_start[j] = p2 + z2 * s2.R
    frame = VertexFrame(
        vertex=u,
        ring=ring,
        U=U,
        sides=sides,
        face_frames=frames,
        cyl_map=[None] * ne,
        face_map=[None] * nf,
        rho=None,
        lmax_start=lmax_start,
        lmax_end=lmax_end,
        T_start=T_start,
        T_end=T_end,
        corner_angle=corner_angle,
    )
    if ring.closed:
        current = np.eye(3)  # tau = f_{n-1}
        for i in range(ne):
            frame.cyl_map[i] = current @ frame.gluing_start(i)
            current = frame.cyl_map[i] @ invert(frame.gluing_end(i))
            frame.face_map[i] = current
        frame.rho = current
    else:
        frame.face_map[0] = np.eye(3)
        for i in range(1, ne - 1):
            frame.cyl_map[i] = frame.face_map[i - 1] @ frame.gluing_start(i)
            frame.face_map[i] = frame.cyl_map[i] @ invert(frame.gluing_end(i))
    return frame
