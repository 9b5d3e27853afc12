"""Polygon mesh: positions plus polygon connectivity as flat index arrays.

Connectivity conventions (used everywhere in filletfold):

* faces are counter-clockwise seen from the front; ``face_normal`` is the front normal;
* ``edges[e] = (a, b)`` with ``a < b``, sorted lexicographically;
* ``edge_faces[e, 0]`` is the face holding the half-edge ``a -> b``, ``edge_faces[e, 1]`` the face
  holding ``b -> a``; ``-1`` where there is none (a boundary edge);
* around a vertex U the ring lists edges ``e_0 ... e_{n-1}`` counter-clockwise seen from the front
  and faces ``f_0 ... f_{n-1}``, face ``f_i`` between ``e_i`` and ``e_{i+1}``. At a boundary vertex
  the ring is open: edges ``e_0 ... e_k`` (both ends boundary edges) and faces ``f_0 ... f_{k-1}``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..arrays import run_next, run_owners, run_starts
from ..errors import MeshError
from .measures import newell_vectors


@dataclass(frozen=True)
class VertexRing:
    """The faces and edges around one vertex, in counter-clockwise order.

    Attributes
    ----------
    vertex : int
    edges : (n_e,) int
        Incident edges ``e_0 ...``; for a closed ring ``n_e == n_f``, else ``n_e == n_f + 1``.
    faces : (n_f,) int
        Incident faces, ``faces[i]`` between ``edges[i]`` and ``edges[i + 1]`` (cyclically).
    neighbors : (n_e,) int
        The other end of each edge.
    closed : bool
        False at a boundary vertex.
    """

    vertex: int
    edges: np.ndarray
    faces: np.ndarray
    neighbors: np.ndarray
    closed: bool


class PolyMesh:
    """A polygon surface mesh (oriented, edge-manifold).

    Parameters
    ----------
    vertices : (n_vertices, 3) float
    faces : sequence of (k,) int
        Polygons, each with ``k >= 3`` distinct vertex indices, counter-clockwise from the front.

    Notes
    -----
    The constructor checks shapes and edge-manifoldness of the half-edges (each directed
    half-edge used once); full validation and repair live in :mod:`filletfold.mesh.clean`.
    """

    def __init__(self, vertices, faces):
        v = np.asarray(vertices, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 3:
            raise MeshError(f"vertices must have shape (n, 3), got {v.shape}")
        self.vertices = v
        self.faces = [np.asarray(f, dtype=np.int64).ravel() for f in faces]
        self._build()

    # ------------------------------------------------------------------ connectivity
    def _build(self):
        n = len(self.vertices)
        face_size = np.array([len(f) for f in self.faces], dtype=np.int64)
        if len(self.faces) and face_size.min() < 3:
            bad = int(np.argmin(face_size))
            raise MeshError(f"face {bad} has fewer than 3 vertices", face=bad)
        he_from = np.concatenate(self.faces) if self.faces else np.zeros(0, np.int64)
        if len(he_from) and (he_from.min() < 0 or he_from.max() >= n):
            raise MeshError("a face refers to a vertex index outside the vertex list")
        self.face_start = run_starts(face_size)
        nxt = run_next(self.face_start)  # the next corner of each face, cyclically
        he_to = he_from[nxt]
        he_face = run_owners(face_size)
        self.halfedge_from = he_from
        self.halfedge_to = he_to
        self.halfedge_face = he_face

        key = he_from * n + he_to
        order = np.argsort(key, kind="stable")
        dup = np.nonzero(np.diff(key[order]) == 0)[0]
        if len(dup):
            h = order[dup[0]]
            a, b = int(he_from[h]), int(he_to[h])
            raise MeshError(
                f"edge ({a}, {b}) is used twice in the same direction: faces are inconsistently "
                "oriented or the edge is non-manifold",
                edge=(a, b),
            )
        lo = np.minimum(he_from, he_to)
        hi = np.maximum(he_from, he_to)
        und = lo * n + hi
        uniq, inverse = np.unique(und, return_inverse=True)
        self.edges = np.stack([uniq // n, uniq % n], axis=1).astype(np.int64)
        counts = np.bincount(inverse, minlength=len(uniq))
        if len(counts) and counts.max() > 2:
            e = int(np.argmax(counts))
            a, b = self.edges[e]
            raise MeshError(
                f"non-manifold edge ({a}, {b}): shared by {counts[e]} faces", edge=(int(a), int(b))
            )
        self.halfedge_edge = inverse
        ef = -np.ones((len(uniq), 2), dtype=np.int64)
        forward = he_from < he_to
        ef[inverse[forward], 0] = he_face[forward]
        ef[inverse[~forward], 1] = he_face[~forward]
        self.edge_faces = ef
        # half-edge lookup: (from, to) -> half-edge index
        self._he_key_sorted = key[order]
        self._he_order = order

    @cached_property
    def halfedge_prev(self) -> np.ndarray:
        """(n_halfedges,) int: the half-edge before each one in its face (it ends at the tail)."""
        prev = np.arange(len(self.halfedge_from)) - 1
        prev[self.face_start[:-1]] = self.face_start[1:] - 1
        return prev

    def halfedge(self, a: int, b: int) -> int:
        """Index of the half-edge ``a -> b``, or -1."""
        k = a * len(self.vertices) + b
        i = np.searchsorted(self._he_key_sorted, k)
        if i < len(self._he_key_sorted) and self._he_key_sorted[i] == k:
            return int(self._he_order[i])
        return -1

    # ------------------------------------------------------------------ sizes
    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    @property
    def n_edges(self) -> int:
        return len(self.edges)

    # ------------------------------------------------------------------ measures
    @cached_property
    def _face_newell(self) -> np.ndarray:
        """(n_faces, 3) float: Newell vectors (twice the vector areas), about each centroid
        (:func:`~filletfold.mesh.measures.newell_vectors`, as
        :func:`~filletfold.mesh.repair.planarize` fits the planes and the certificate measures
        them: about the origin a sliver far from it got a normal off its own plane, its chart's
        axes were not orthogonal to the cylinders' tangent lines by as much, and the
        development's gluing maps shrank lengths by ``1e-11``).
        """
        nxt = run_next(self.face_start)
        return newell_vectors(self.vertices[self.halfedge_from], self.face_start, nxt)

    @cached_property
    def face_normal(self) -> np.ndarray:
        """(n_faces, 3) float: unit front normals (Newell's method, about each centroid)."""
        acc = self._face_newell
        norm = np.linalg.norm(acc, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            return acc / norm[:, None]

    @cached_property
    def face_area(self) -> np.ndarray:
        """(n_faces,) float: polygon areas."""
        return 0.5 * np.linalg.norm(self._face_newell, axis=1)

    @cached_property
    def face_centroid(self) -> np.ndarray:
        """(n_faces, 3) float: mean of each face's vertices."""
        if not self.n_faces:
            return np.zeros((0, 3))
        size = np.diff(self.face_start)
        corners = self.vertices[self.halfedge_from]  # the faces' corners, face after face
        return np.add.reduceat(corners, self.face_start[:-1], axis=0) / size[:, None]

    @cached_property
    def edge_length(self) -> np.ndarray:
        """(n_edges,) float."""
        return np.linalg.norm(
            self.vertices[self.edges[:, 1]] - self.vertices[self.edges[:, 0]], axis=1
        )

    @cached_property
    def mean_edge_length(self) -> float:
        return float(self.edge_length.mean()) if self.n_edges else 0.0

    @cached_property
    def is_boundary_edge(self) -> np.ndarray:
        """(n_edges,) bool."""
        return (self.edge_faces < 0).any(axis=1)

    @cached_property
    def is_boundary_vertex(self) -> np.ndarray:
        """(n_vertices,) bool."""
        out = np.zeros(self.n_vertices, dtype=bool)
        out[self.edges[self.is_boundary_edge].ravel()] = True
        return out

    @cached_property
    def is_closed(self) -> bool:
        return not bool(self.is_boundary_edge.any())

    def corner_angles(self) -> np.ndarray:
        """(n_halfedges,) float: the face angle at the tail vertex of each half-edge (radians).

        Cached; see :attr:`halfedge_corner_angle`.
        """
        return self.halfedge_corner_angle

    @cached_property
    def halfedge_corner_angle(self) -> np.ndarray:
        """(n_halfedges,) float: the face angle at the tail vertex of each half-edge (radians).

        The angle at corner ``halfedge_from[h]`` between the edge to ``halfedge_to[h]`` and the
        edge to the face's previous vertex, measured inside the face (atan2, so small angles
        keep their precision; reflex corners give angles above pi).
        """
        p = self.vertices[self.halfedge_from]
        nxt = self.vertices[self.halfedge_to] - p
        prv = self.vertices[self.halfedge_from[self.halfedge_prev]] - p
        n = self.face_normal[self.halfedge_face]
        s = np.einsum("ij,ij->i", np.cross(nxt, prv), n)
        c = np.einsum("ij,ij->i", nxt, prv)
        return np.mod(np.arctan2(s, c), 2 * np.pi)

    @cached_property
    def vertex_angle_sum(self) -> np.ndarray:
        """(n_vertices,) float: sum of the face angles at each vertex (radians)."""
        return np.bincount(
            self.halfedge_from, weights=self.corner_angles(), minlength=self.n_vertices
        )

    # ------------------------------------------------------------------ rings
    def vertex_ring(self, u: int) -> VertexRing:
        """The counter-clockwise ring of edges and faces around vertex ``u``.

        Raises
        ------
        MeshError
            If the faces around ``u`` do not form a single fan (non-manifold vertex) or ``u`` is
            not used by any face.
        """
        outgoing = np.nonzero(self.halfedge_from == u)[0]
        if len(outgoing) == 0:
            raise MeshError(f"vertex {u} is not used by any face", vertex=u)
        # start: an outgoing half-edge u->q whose reverse q->u has no face (boundary), if any
        start = outgoing[0]
        closed = True
        for h in outgoing:
            if self.halfedge(int(self.halfedge_to[h]), u) < 0:
                start = h
                closed = False
                break
        edges, faces, nbrs = [], [], []
        h = start
        while True:
            q = int(self.halfedge_to[h])
            edges.append(int(self.halfedge_edge[h]))
            nbrs.append(q)
            f = int(self.halfedge_face[h])
            faces.append(f)
            # previous vertex p of u in face f; the next face holds u -> p
            fs, fe = self.face_start[f], self.face_start[f + 1]
            local = h - fs
            p = int(self.halfedge_from[fs + (local - 1) % (fe - fs)])
            nh = self.halfedge(u, p)
            if nh < 0:  # reached the boundary: the last edge is (u, p)
                e_last = int(self.halfedge_edge[self.halfedge(p, u)])
                edges.append(e_last)
                nbrs.append(p)
                break
            if nh == start:
                break
            h = nh
            if len(faces) > len(outgoing):
                raise MeshError(f"non-manifold vertex {u}: its faces do not form a fan", vertex=u)
        if len(faces) != len(outgoing):
            raise MeshError(
                f"non-manifold vertex {u}: its {len(outgoing)} faces form more than one fan",
                vertex=u,
            )
        return VertexRing(
            vertex=u,
            edges=np.array(edges, dtype=np.int64),
            faces=np.array(faces, dtype=np.int64),
            neighbors=np.array(nbrs, dtype=np.int64),
            closed=closed,
        )

    def __repr__(self) -> str:
        return f"PolyMesh(n_vertices={self.n_vertices}, n_faces={self.n_faces})"


def mesh_size(mesh: PolyMesh) -> float:
    """The size crease rulings are measured against: the mesh's bounding-box diagonal."""
    return float(np.linalg.norm(np.ptp(mesh.vertices, axis=0)))


def check_corners(mesh: PolyMesh, limit: int) -> None:
    """A :class:`~filletfold.errors.MeshError` naming the largest face of ``mesh`` when it has
    more than ``limit`` corners, or the vertex meeting the most edges when more than ``limit``
    meet there (``max_corners``: the work on a face or a vertex's ring grows about with the
    square of its corners; a vertex of 3,000 edges took 158 s and 3.3 GB)."""
    sizes = np.diff(mesh.face_start)
    if len(sizes) and sizes.max() > limit:
        f = int(np.argmax(sizes))
        raise too_many_corners(f"face {f} has {int(sizes[f])} corners", limit, face=f)
    valence = np.bincount(np.asarray(mesh.edges).ravel(), minlength=mesh.n_vertices)
    if len(valence) and valence.max() > limit:
        v = int(np.argmax(valence))
        raise too_many_corners(f"vertex {v} meets {int(valence[v])} edges", limit, vertex=v)


#: Points of the crease pattern per edge, fixed and per sample of an arc, in
#: :func:`estimate_pattern_points` (over the built-in examples, 3 to 96 samples, arc step 0
#: and 10 degrees, the pattern had at most 0.77 of the estimate; a 2,904-vertex scan 0.08).
PATTERN_POINTS_PER_EDGE = (64, 4)


def estimate_pattern_points(mesh: PolyMesh, samples: int) -> int:
    """An upper estimate of the crease pattern's points before anything is solved: each edge's
    cylinder, the cones at its ends and the face pieces beside it give at most
    ``64 + 4 * samples`` points (:data:`PATTERN_POINTS_PER_EDGE`)."""
    fixed, per_sample = PATTERN_POINTS_PER_EDGE
    return int(mesh.n_edges) * (fixed + per_sample * int(samples))


def check_pattern_size(mesh: PolyMesh, samples: int, limit: int) -> None:
    """A :class:`~filletfold.errors.MeshError` when the pattern of ``mesh`` at ``samples``
    points per arc is estimated (:func:`estimate_pattern_points`) at more than ``limit``
    points (``max_points``): refused before its time and memory are spent."""
    points = estimate_pattern_points(mesh, samples)
    if points > limit:
        raise MeshError(
            f"the design of {mesh.n_edges:,} edges at {samples} samples is estimated at up to "
            f"{points:,} pattern points, more than {limit:,} (--max-points: time and memory grow "
            "with them); coarsen with --faces N, lower --samples, or raise --max-points"
        )


def too_many_corners(what: str, limit: int, **element) -> MeshError:
    """The error of an element beyond ``max_corners``: ``what`` it has, the limit, why, and
    the options that change it."""
    return MeshError(
        f"{what}, more than {limit} (--max-corners: the work on it grows about with the square "
        "of its corners); raise it, or --faces N to triangulate and coarsen the mesh",
        **element,
    )
