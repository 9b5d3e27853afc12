"""Validation and repair of an input polygon mesh.

:func:`clean_mesh` turns raw ``(vertices, faces)`` into a :class:`~filletfold.mesh.PolyMesh`
that the rest of filletfold can trust: finite, no duplicate vertices, no degenerate faces,
edge- and vertex-manifold, consistently oriented (outward for closed shells), every polygon
planar and convex, neighbouring coplanar faces merged into convex polygons. What can be
repaired is repaired (:mod:`filletfold.mesh.repair`) and reported in ``CleanLog.repairs``;
``strict=True`` refuses instead.

Errors and repairs name the element by its index in the *input* (vertex, edge as a pair of
input vertex indices, or face).
"""

from __future__ import annotations

import itertools
import logging
import math
from collections import deque
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..arrays import run_owners, run_starts, split_runs
from ..errors import MeshError
from ..tolerances import tol
from .measures import newell_vectors
from .polymesh import PolyMesh
from .repair import (
    RepairLog,
    corner_turns,
    detach_faces,
    drop_duplicate_faces,
    edge_keys,
    fix_degenerate_faces,
    planarize,
    plane_axes,
    polygon_normal,
    split_face_loops,
    split_into_triangles,
    split_non_manifold,
    triangulate_polygon_3d,
)

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class CleanLog:
    """What :func:`clean_mesh` changed.

    Attributes
    ----------
    merged_vertices : int
        Input vertices merged into another one because they were (almost) at the same place.
    flipped_faces : int
        Faces reversed to make the orientation consistent (and outward on closed shells).
    merged_faces : int
        Faces removed by merging neighbouring coplanar faces into one polygon.
    removed_vertices : int
        Vertices dropped: unreferenced ones, interior vertices of merged coplanar regions, and
        straight (angle pi) corners removed after merging.
    vertex_map : (n_input_vertices,) int
        Index in the cleaned mesh of each input vertex, ``-1`` where it was dropped (the first
        copy of a vertex split into several).
    face_origin : (n_faces,) int
        For each cleaned face, the smallest input face index it was made from.
    repairs : list of Repair
        Every repair of a defect (:mod:`filletfold.mesh.repair`): what, where, why.
    """

    merged_vertices: int
    flipped_faces: int
    merged_faces: int
    removed_vertices: int
    vertex_map: np.ndarray = field(repr=False)
    face_origin: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64), repr=False)
    repairs: list = field(default_factory=list)


def clean_mesh(
    vertices,
    faces,
    *,
    coplanar_deg: float = tol.coplanar_deg,
    merge_coplanar: bool = True,
    strict: bool = False,
) -> tuple[PolyMesh, CleanLog]:
    """Validate and repair a polygon mesh.

    Steps, in order: validate; drop faces on non-finite vertices; weld vertices closer than
    ``tol.weld`` of the bounding-box diagonal; split faces that visit a vertex twice and drop
    faces of fewer than three vertices; remove faces of (almost) zero area (inserting their
    middle vertex into the face beside their longest edge); drop duplicate faces (a face and
    its reversed copy both, where that leaves no hole) and unused vertices; split non-manifold
    vertices and cut non-manifold edges open; orient faces consistently per connected
    component (outward on closed components, the faces reversed reported; a component that
    cannot be oriented is cut open where it conflicts); cut open the edges along which two
    faces lie back to back; triangulate non-planar and non-convex polygons (along diagonals
    that are no edge yet); merge neighbouring coplanar faces into convex polygons; remove
    straight corners and split polygons at corners within ``tol.straight`` of straight; check
    every polygon is planar, and (a guard) every edge used at most twice, in opposite
    directions. Every repair is listed in ``log.repairs``.

    Parameters
    ----------
    vertices : (n_vertices, 3) float
    faces : sequence of (k,) int, or (n_faces, k) int
        Polygons (0-based vertex indices), ``k >= 3``; orientation may be inconsistent.
    coplanar_deg : float
        Two faces sharing an edge are merged when their front normals differ by less than this
        angle (degrees).
    merge_coplanar : bool
        Set False to keep every input face.
    strict : bool
        Repair nothing: the first defect raises the :class:`MeshError` that names it (vertices
        are then welded only within ``tol.merge``, as exact duplicates).

    Returns
    -------
    mesh : PolyMesh
    log : CleanLog

    Raises
    ------
    MeshError
        With ``vertex``, ``edge`` (pair of input vertex indices) or ``face`` (input index) set:
        index out of range, no faces, a triangle soup (no two faces share an edge, even after
        welding), a mesh with nothing left after repairs; with ``strict``: non-finite
        coordinate, degenerate or duplicate face, non-manifold edge or vertex, non-orientable
        component, faces back to back, non-planar face.

    Notes
    -----
    A coplanar region is merged face by face (breadth first from its lowest face) while the
    merged polygon stays one simple, convex, planar loop without a corner within
    ``tol.straight`` of straight (exactly straight corners excepted: they are removed where
    the vertex has no other edge). A straight corner is removed when it has exactly two edges
    (two faces inside the surface, or one face on the boundary) and its angle is pi within
    ``tol.collinear`` in each of its faces.
    """
    v, face_list = _validate(vertices, faces)
    n_input = len(v)
    log = RepairLog(strict=strict)
    face_origin = np.arange(len(face_list), dtype=np.int64)

    # 2. faces on vertices with a non-finite coordinate
    face_list, face_origin = _drop_non_finite(v, face_list, face_origin, log)

    _check_resolution(v, face_list)

    # 3. weld close vertices, then fix face loops and zero-area faces
    rep = _close_vertex_representatives(v, face_list, log)
    merged_vertices = n_input - len(np.unique(rep))
    face_list = [rep[f] for f in face_list]
    vorig = np.arange(n_input, dtype=np.int64)
    face_list, face_origin = split_face_loops(face_list, face_origin, vorig, log)
    if face_list:
        face_list, face_origin = fix_degenerate_faces(
            face_list, face_origin, v, vorig, log, tol.degenerate
        )
    if face_list:
        face_list, face_origin = drop_duplicate_faces(face_list, face_origin, log)
    if not face_list:
        raise MeshError("the mesh has no face left once its degenerate faces are removed")

    # 4. drop unreferenced vertices
    used = np.unique(np.concatenate(face_list))
    new_of_rep = -np.ones(n_input, dtype=np.int64)
    new_of_rep[used] = np.arange(len(used))
    vertex_map = new_of_rep[rep]
    removed_vertices = int(n_input - merged_vertices - len(used))
    vert_orig = used.copy()  # input index of each current vertex
    v = v[used]
    face_list = [new_of_rep[f] for f in face_list]

    # 5. non-manifold vertices and edges split; 6. orientation (a component that cannot be
    # oriented is cut open where it conflicts)
    face_list, v, vert_orig, he, flipped = _manifold_oriented(
        face_list, face_origin, v, vert_orig, log, strict
    )
    _check_not_soup(he, face_list, face_origin)
    face_list, face_origin, v, vert_orig, flipped2 = _unfold(
        he, face_list, face_origin, v, vert_orig, log, strict
    )
    flipped += flipped2

    # 7. non-planar and non-convex polygons are triangulated (and regrouped by the merge)
    n_v = len(v)
    face_list, face_origin, v = _split_non_planar(face_list, face_origin, v, log)
    if not strict:
        face_list, face_origin, v = _split_non_convex(face_list, face_origin, v, log)
    vert_orig = _new_vertices(vert_orig, len(v) - n_v)

    # 8. coplanar merge, straight corners, unreferenced vertices
    merged_faces = 0
    if merge_coplanar and coplanar_deg > 0 and len(face_list) > 1:
        n_before = len(face_list)
        face_list, face_origin = _merge_coplanar(face_list, face_origin, v, coplanar_deg)
        for _ in range(64):  # interior vertices of flat regions are removed, then merged again
            face_list, face_origin, removed = _remove_flat_vertices(
                face_list, face_origin, v, coplanar_deg
            )
            if not removed:
                break
            face_list, face_origin = _merge_coplanar(face_list, face_origin, v, coplanar_deg)
        merged_faces = n_before - len(face_list)
    face_list = _remove_straight_corners(face_list, v)
    if not strict:
        face_list, face_origin = _split_straight_corners(
            face_list, face_origin, v, vert_orig, coplanar_deg, log
        )
    used = np.unique(np.concatenate(face_list))
    if len(used) < len(v):
        compact = -np.ones(len(v), dtype=np.int64)
        compact[used] = np.arange(len(used))
        removed_vertices += int(len(v) - len(used))
        vertex_map = np.where(vertex_map >= 0, compact[np.maximum(vertex_map, 0)], -1)
        vert_orig = vert_orig[used]
        v = v[used]
        face_list = [compact[f] for f in face_list]

    # 9. planarity: exact (to round-off) where the polygons are planar within the tolerance
    if not strict:
        v, residual = planarize(face_list, v, log)
        rest = np.flatnonzero(residual > tol.flat)
        if len(rest):  # polygons the planes of their neighbours do not let be planar
            n_v = len(v)
            face_list, face_origin, v = split_into_triangles(
                face_list,
                face_origin,
                v,
                rest,
                log,
                lambda i: (
                    f"not planar to round-off ({residual[i]:.2g} of its diameter) once "
                    "its vertices are moved onto their planes"
                ),
                lambda o, i: "",
            )
            vert_orig = _new_vertices(vert_orig, len(v) - n_v)
    _check_planar(face_list, v, face_origin)
    face_list, v, vert_orig, flipped2 = _ensure_manifold(
        face_list, face_origin, v, vert_orig, log, strict
    )
    flipped += flipped2

    mesh = PolyMesh(v, face_list)
    log = CleanLog(
        merged_vertices=int(merged_vertices),
        flipped_faces=int(flipped),
        merged_faces=int(merged_faces),
        removed_vertices=int(removed_vertices),
        vertex_map=vertex_map,
        face_origin=face_origin,
        repairs=list(log.repairs),
    )
    logger.debug("clean_mesh: %s", log)
    return mesh, log


def _vertex_name(vert_orig: np.ndarray, x: int) -> str:
    """Input index of current vertex ``x``, or what it is when a repair added it."""
    u = int(vert_orig[x])
    return str(u) if u >= 0 else "(added at the middle of a face)"


def _new_vertices(vert_orig: np.ndarray, k: int) -> np.ndarray:
    """``vert_orig`` with ``k`` vertices added by the repairs (no input index: -1)."""
    if k <= 0:
        return vert_orig
    return np.concatenate([vert_orig, -np.ones(k, dtype=np.int64)])


# ------------------------------------------------------------------------------ 1. validate
def _validate(vertices, faces) -> tuple[np.ndarray, list[np.ndarray]]:
    try:
        v = np.asarray(vertices, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise MeshError(f"vertices cannot be read as a float array: {exc}") from exc
    if v.ndim != 2 or v.shape[1] != 3:
        raise MeshError(f"vertices must have shape (n, 3), got {v.shape}")
    if faces is None or len(faces) == 0:
        raise MeshError("the mesh is empty: it has no faces")
    n = len(v)
    block = _face_block(faces)
    if block is not None and _valid_block(block, n):
        return v, list(block.astype(np.int64))
    out = []
    for i, f in enumerate(faces):
        a = np.asarray(f)
        if a.ndim != 1 or a.dtype.kind not in "iuf":
            raise MeshError(f"face {i} is not a list of vertex indices: {f!r}", face=i)
        if a.dtype.kind == "f":
            if not (np.isfinite(a).all() and np.array_equal(a, np.round(a))):
                raise MeshError(f"face {i} has non-integer vertex indices {a.tolist()}", face=i)
        a = a.astype(np.int64)
        if len(a) and (a.min() < 0 or a.max() >= n):
            k = int(a[(a < 0) | (a >= n)][0])
            raise MeshError(
                f"face {i} refers to vertex {k}, outside the {n} vertices (0..{n - 1})", face=i
            )
        out.append(a)
    return v, out


def _face_block(faces) -> np.ndarray | None:
    """The faces as one (n_faces, k) array of numbers when they all have ``k`` corners (a
    numeric 2-D array, or a sequence of equal-length rows), else None."""
    try:
        block = np.asarray(faces)
    except (TypeError, ValueError):  # ragged
        return None
    if block.ndim != 2 or block.dtype.kind not in "iuf":
        return None
    return block


def _valid_block(block: np.ndarray, n: int) -> bool:
    """Whether every row of ``block`` is a face of whole vertex indices in ``0 .. n - 1``: the
    checks of :func:`_validate` on all rows at once (False: let the row-by-row checks find and
    report the first bad face)."""
    if block.dtype.kind == "f" and not (
        np.isfinite(block).all() and (block == np.round(block)).all()
    ):
        return False
    return block.size == 0 or (block.min() >= 0 and block.max() < n)


# ------------------------------------------------------------------ 2. non-finite, welding
def _drop_non_finite(v: np.ndarray, face_list, face_origin, log: RepairLog):
    """Drop the faces that use a vertex with a non-finite coordinate (reported)."""
    bad = ~np.isfinite(v).all(axis=1)
    if not bad.any():
        return face_list, face_origin
    i = int(np.flatnonzero(bad)[0])
    if log.strict:
        raise MeshError(f"vertex {i} has a non-finite coordinate {v[i].tolist()}", vertex=i)
    keep = [not bad[f].any() for f in face_list]
    for k, f in enumerate(face_list):
        if not keep[k]:
            u = int(f[bad[f]][0])
            log.add(
                "drop-face",
                f"face {int(face_origin[k])}",
                f"its vertex {u} has a non-finite coordinate {v[u].tolist()}",
                error="",
            )
    if not any(keep):
        raise MeshError(
            f"every face uses a vertex with a non-finite coordinate (vertex {i}: {v[i].tolist()})",
            vertex=i,
        )
    face_list = [f for f, k in zip(face_list, keep, strict=True) if k]
    return face_list, face_origin[np.asarray(keep)]


def _check_resolution(v: np.ndarray, face_list) -> None:
    """Refuse a mesh that double precision cannot resolve where it lies: one so small for its
    distance from the origin that its coordinates resolve less than ``tol.planar`` of its size
    (a millimetre model at a thousand kilometres), or whose used vertices all coincide."""
    used = v[np.unique(np.concatenate(face_list))]
    size = float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))
    far = float(np.abs(used).max())
    step = np.spacing(far) if far > 0 else 0.0
    if size == 0:
        raise MeshError(f"all the vertices of the mesh's faces are at one point {used[0].tolist()}")
    if step > tol.planar * size:
        raise MeshError(
            f"the mesh is {size:.3g} across at {far:.3g} from the origin: double precision "
            f"resolves its coordinates only to {step:.2g} there ({step / size:.2g} of its "
            "size); move it nearer the origin or scale it up"
        )


def _close_vertex_representatives(v: np.ndarray, face_list, log: RepairLog) -> np.ndarray:
    """(n,) int: for each vertex, the smallest index of the cluster of vertices it is close to.

    Vertices closer than ``tol.merge`` of the bounding-box diagonal of the used vertices are
    the same point (as in every STL file); vertices closer than ``tol.weld`` of it are welded
    too (reported, one repair per cluster), except with ``log.strict``.
    """
    n = len(v)
    if n < 2:
        return np.arange(n, dtype=np.int64)
    used = np.unique(np.concatenate(face_list))
    box = v[used]
    diag = float(np.linalg.norm(box.max(axis=0) - box.min(axis=0)))
    radius = (tol.merge if log.strict else tol.weld) * diag
    finite = np.flatnonzero(np.isfinite(v).all(axis=1))
    pairs = cKDTree(v[finite]).query_pairs(radius, output_type="ndarray")
    if len(pairs) == 0:
        return np.arange(n, dtype=np.int64)
    pairs = finite[pairs]
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    first = np.full(labels.max() + 1, n, dtype=np.int64)
    np.minimum.at(first, labels, np.arange(n))
    rep = first[labels]
    gap = np.linalg.norm(v[pairs[:, 0]] - v[pairs[:, 1]], axis=1)
    far = pairs[gap > tol.merge * diag]
    if len(far):
        cluster = np.unique(rep[far[:, 0]])
        for c in cluster.tolist():
            members = np.flatnonzero(rep == c)
            spread = float(np.linalg.norm(v[members] - v[c], axis=1).max())
            shown = ", ".join(map(str, members[:6].tolist())) + (
                ", ..." if len(members) > 6 else ""
            )
            log.add(
                "weld",
                f"vertices {shown}",
                f"{len(members)} vertices within {spread:.3g} of each other "
                f"({spread / diag:.2g} of the mesh size, below {tol.weld:g}) welded into one",
                error="",
            )
    return rep


@dataclass(frozen=True)
class _Flat:
    """A polygon list as flat corner arrays (corner ``c`` = vertex ``index[c]`` of ``face[c]``)."""

    index: np.ndarray  # (n_corners,) vertex of each corner
    start: np.ndarray  # (n_faces + 1,) first corner of each face
    size: np.ndarray  # (n_faces,)
    face: np.ndarray  # (n_corners,)
    next: np.ndarray  # (n_corners,) next corner in the same face
    prev: np.ndarray  # (n_corners,)

    @classmethod
    def of(cls, face_list) -> _Flat:
        size = np.array([len(f) for f in face_list], dtype=np.int64)
        start = run_starts(size)
        index = np.concatenate(face_list).astype(np.int64)
        face = run_owners(size)
        local = np.arange(len(index)) - start[face]
        nxt = start[face] + (local + 1) % size[face]
        prv = start[face] + (local - 1) % size[face]
        return cls(index, start, size, face, nxt, prv)

    def split(self, values: np.ndarray) -> list[np.ndarray]:
        return split_runs(values, self.start[1:-1])


def _face_newell(fl: _Flat, v: np.ndarray) -> np.ndarray:
    """(n_faces, 3) float: Newell vectors (twice the vector areas), computed about each centroid."""
    return newell_vectors(v[fl.index], fl.start, fl.next)


def _corner_angles(fl: _Flat, v: np.ndarray) -> np.ndarray:
    """(n_corners,) float: interior angle at each corner (radians, reflex corners above pi)."""
    n = _face_newell(fl, v)
    n = n / np.linalg.norm(n, axis=1)[:, None]
    p = v[fl.index]
    to_next = v[fl.index[fl.next]] - p
    to_prev = v[fl.index[fl.prev]] - p
    s = np.einsum("ij,ij->i", np.cross(to_next, to_prev), n[fl.face])
    c = np.einsum("ij,ij->i", to_next, to_prev)
    return np.mod(np.arctan2(s, c), 2 * np.pi)


def _face_planarity(fl: _Flat, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Max distance of each face's vertices from its Newell plane, and each face's diameter.

    Returns
    -------
    distance, diameter : (n_faces,) float
    """
    p = v[fl.index]
    centroid = np.add.reduceat(p, fl.start[:-1], axis=0) / fl.size[:, None]
    n = _face_newell(fl, v)
    n = n / np.linalg.norm(n, axis=1)[:, None]
    dist = np.abs(np.einsum("ij,ij->i", p - centroid[fl.face], n[fl.face]))
    distance = np.maximum.reduceat(dist, fl.start[:-1])
    diameter = np.zeros(len(fl.size))
    local = np.arange(len(fl.index)) - fl.start[fl.face]
    for step in range(1, int(fl.size.max()) // 2 + 1):
        other = fl.start[fl.face] + (local + step) % fl.size[fl.face]
        d = np.linalg.norm(v[fl.index[other]] - p, axis=1)
        diameter = np.maximum(diameter, np.maximum.reduceat(d, fl.start[:-1]))
    return distance, diameter


# --------------------------------------------------------------------------- half-edges
class _HalfEdges:
    """Flat half-edge arrays of a polygon list whose orientation may be inconsistent."""

    def __init__(self, face_list: list[np.ndarray], n_vertices: int):
        fl = _Flat.of(face_list)
        self.start = fl.start
        self.frm = fl.index
        self.to = fl.index[fl.next]
        self.face = fl.face
        self.next = fl.next
        lo = np.minimum(self.frm, self.to)
        hi = np.maximum(self.frm, self.to)
        keys, self.edge, counts = np.unique(
            lo * n_vertices + hi, return_inverse=True, return_counts=True
        )
        self.edge = self.edge.ravel()
        self.edge_ends = np.stack([keys // n_vertices, keys % n_vertices], axis=1)
        self.edge_count = counts
        # the (up to) two half-edges of each edge
        order = np.argsort(self.edge, kind="stable")
        first = np.searchsorted(self.edge[order], np.arange(len(keys)))
        self.edge_he0 = order[first]
        he1 = -np.ones(len(keys), dtype=np.int64)
        two = counts == 2
        he1[two] = order[first[two] + 1]
        self.edge_he1 = he1


# -------------------------------------------------------------------------------- 4. manifold
def _check_manifold(he: _HalfEdges, vert_orig: np.ndarray) -> None:
    many = np.nonzero(he.edge_count > 2)[0]
    if len(many):
        e = int(many[0])
        a, b = (int(vert_orig[x]) for x in he.edge_ends[e])
        n_faces = int(he.edge_count[e])
        raise MeshError(
            f"non-manifold edge ({a}, {b}): shared by {n_faces} faces (at most 2 allowed)",
            edge=(a, b),
        )
    # corners around a vertex are joined across each interior edge; one fan == one component
    inner = np.nonzero(he.edge_count == 2)[0]
    h1 = he.edge_he0[inner]
    h2 = he.edge_he1[inner]
    same = he.frm[h1] == he.frm[h2]
    # corner of vertex x in a face is the half-edge leaving x in that face
    x_in_1, y_in_1 = h1, he.next[h1]
    x_in_2 = np.where(same, h2, he.next[h2])
    y_in_2 = np.where(same, he.next[h2], h2)
    n_he = len(he.frm)
    rows = np.concatenate([x_in_1, y_in_1])
    cols = np.concatenate([x_in_2, y_in_2])
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n_he, n_he))
    _, label = connected_components(graph, directed=False)
    pairs = np.unique(np.stack([he.frm, label], axis=1), axis=0)
    fans = np.bincount(pairs[:, 0], minlength=int(he.frm.max()) + 1)
    bad = np.nonzero(fans > 1)[0]
    if len(bad):
        u = int(vert_orig[bad[0]])
        raise MeshError(
            f"non-manifold vertex {u}: its faces form {int(fans[bad[0]])} separate fans "
            f"(faces touching only at this vertex)",
            vertex=u,
        )


def _ensure_manifold(face_list, face_origin, v, vert_orig, log: RepairLog, strict: bool):
    """The last guard: every edge used by at most two faces, in opposite directions.

    The steps after orientation keep that (a triangulation uses no diagonal that is an edge
    already, a merge or a removed corner makes no new edge), so this does nothing; should a
    step ever break it, the edges are cut open and the faces oriented again, reported, rather
    than the mesh refused (or, with ``strict``, the first is named).

    Returns
    -------
    faces, v, vert_orig, flipped
    """
    fl = _Flat.of(face_list)
    frm, to = fl.index, fl.index[fl.next]
    directed = np.sort(frm * len(v) + to)
    undirected = np.sort(np.minimum(frm, to) * len(v) + np.maximum(frm, to))
    if not (directed[1:] == directed[:-1]).any() and not (undirected[2:] == undirected[:-2]).any():
        return face_list, v, vert_orig, 0
    he = _HalfEdges(face_list, len(v))
    directed = he.frm * len(v) + he.to
    if strict:
        _check_manifold(he, vert_orig)
        order = np.argsort(directed, kind="stable")
        h = int(order[np.flatnonzero(np.diff(directed[order]) == 0)[0]])
        a, b = int(vert_orig[he.frm[h]]), int(vert_orig[he.to[h]])
        raise MeshError(
            f"edge ({a}, {b}) is used twice in the same direction: its two faces cannot be "
            "oriented consistently",
            edge=(a, b),
        )
    face_list, v, vert_orig, _, flipped = _manifold_oriented(
        face_list, face_origin, v, vert_orig, log, False
    )
    return face_list, v, vert_orig, flipped


def _manifold_oriented(face_list, face_origin, v, vert_orig, log: RepairLog, strict: bool):
    """Non-manifold vertices and edges split (without ``strict``, sheets still joined along
    an edge of more than two faces detached first), then the faces oriented consistently; a
    component that cannot be oriented is cut open where it conflicts and oriented again.

    Returns
    -------
    face_list, v, vert_orig, he, flipped
        ``he`` the half-edges of the result, ``flipped`` the number of faces turned over.
    """
    face_list, v, vert_orig = split_non_manifold(face_list, face_origin, v, vert_orig, log)
    he = _HalfEdges(face_list, len(v))
    if not strict and (he.edge_count > 2).any():  # sheets still joined elsewhere: cut them off
        face_list, v, vert_orig = detach_faces(face_list, face_origin, v, vert_orig, he, log)
        face_list, v, vert_orig = split_non_manifold(face_list, face_origin, v, vert_orig, log)
        he = _HalfEdges(face_list, len(v))
    _check_manifold(he, vert_orig)
    face_list, flipped, conflicts = _orient(
        he, face_list, v, face_origin, strict, log=log, vert_orig=vert_orig
    )
    if conflicts:
        face_list, v, vert_orig = split_non_manifold(
            face_list, face_origin, v, vert_orig, log, unpaired=conflicts
        )
        he = _HalfEdges(face_list, len(v))
        face_list, flipped2, _ = _orient(
            he, face_list, v, face_origin, True, log=log, vert_orig=vert_orig
        )
        flipped += flipped2
    return face_list, v, vert_orig, he, flipped


# ------------------------------------------------------------------------------ 5. orient
def _flip(f: np.ndarray) -> np.ndarray:
    return np.concatenate([f[:1], f[:0:-1]])


def _orient(he: _HalfEdges, face_list, v, face_origin, strict: bool, *, log=None, vert_orig=None):
    """Orient every connected component consistently: outward where it is closed, as most of
    its faces where it is open.

    The faces reversed are reported in ``log`` (unless it is strict), one ``flip-face``
    repair per component: naming an edge two of its faces used in the same direction, or
    saying that the closed component was inside out.

    Returns
    -------
    faces : list of (k,) int
    flipped : int
        Faces reversed.
    conflicts : list of (int, int)
        When a component cannot be oriented (and not ``strict``): the edges (a, b), a < b,
        across which the breadth-first orientation conflicts, to be cut open; the faces are
        then returned unchanged.

    Raises
    ------
    MeshError
        With ``strict``, for a component that cannot be oriented.
    """
    n_faces = len(face_list)
    inner = np.nonzero(he.edge_count == 2)[0]
    h1 = he.edge_he0[inner]
    h2 = he.edge_he1[inner]
    fa = he.face[h1]
    fb = he.face[h2]
    same = (he.frm[h1] == he.frm[h2]).astype(np.int64)  # 1: the two faces disagree
    adjacency: list[list[tuple[int, int]]] = [[] for _ in range(n_faces)]
    for a, b, s in zip(fa.tolist(), fb.tolist(), same.tolist(), strict=True):
        adjacency[a].append((b, s))
        adjacency[b].append((a, s))
    parity = -np.ones(n_faces, dtype=np.int64)
    component = -np.ones(n_faces, dtype=np.int64)
    n_comp = 0
    for seed in range(n_faces):
        if parity[seed] >= 0:
            continue
        parity[seed] = 0
        component[seed] = n_comp
        queue = deque([seed])
        while queue:
            f = queue.popleft()
            for g, s in adjacency[f]:
                if parity[g] < 0:
                    parity[g] = parity[f] ^ s
                    component[g] = n_comp
                    queue.append(g)
        n_comp += 1
    conflict = np.nonzero((parity[fa] ^ parity[fb]) != same)[0]
    if len(conflict) and not strict:
        edges = he.edge_ends[inner[conflict]]
        return face_list, 0, [(int(a), int(b)) for a, b in edges]
    if len(conflict):
        c = int(conflict[0])
        f = int(face_origin[fa[c]])
        raise MeshError(
            f"non-orientable surface: the component containing face {f} cannot be oriented "
            f"consistently (a Möbius-like band)",
            face=f,
        )
    # closed components: outward (positive signed volume); open ones: flip the minority
    boundary_faces = he.face[he.edge_he0[he.edge_count == 1]]
    is_open = np.zeros(n_comp, dtype=bool)
    is_open[component[boundary_faces]] = True
    sign = 1 - 2 * parity  # +1 keep, -1 flip
    centre = v.mean(axis=0)
    p = v - centre
    first = p[he.frm[he.start[he.face]]]
    vol6 = np.einsum("ij,ij->i", first, np.cross(p[he.frm], p[he.to]))
    face_vol6 = np.bincount(he.face, weights=vol6, minlength=n_faces) * sign
    comp_vol = np.bincount(component, weights=face_vol6, minlength=n_comp)
    comp_size = np.bincount(component, minlength=n_comp)
    comp_flips = np.bincount(component, weights=parity, minlength=n_comp)
    invert = np.where(is_open, comp_flips * 2 > comp_size, comp_vol < 0)
    parity = parity ^ invert[component].astype(np.int64)
    out = [_flip(f) if parity[i] else f for i, f in enumerate(face_list)]
    if log is not None and not log.strict and parity.any():
        comps = _Components(component, comp_size, is_open)
        pairs = _InnerEdges(inner, same, fa, fb)
        _report_flips(log, parity, comps, pairs, he, face_origin, vert_orig)
    return out, int(parity.sum()), []


class _Components(NamedTuple):
    """The connected components of the faces (:func:`_orient`): each face's component, each
    component's number of faces, and whether it has a border."""

    of_face: np.ndarray
    size: np.ndarray
    is_open: np.ndarray


class _InnerEdges(NamedTuple):
    """The edges with two faces (:func:`_orient`): their indices among the edges, 1 where both
    faces use the edge in the same direction, and the two faces."""

    edge: np.ndarray
    same: np.ndarray
    fa: np.ndarray
    fb: np.ndarray


def _report_flips(
    log, parity, comps: _Components, pairs: _InnerEdges, he, face_origin, vert_orig
) -> None:
    """One ``flip-face`` repair per component with reversed faces (see :func:`_orient`)."""
    component, comp_size, is_open = comps
    inner, same, fa, fb = pairs
    flipped = np.flatnonzero(parity)
    comps = component[flipped]
    order = np.argsort(comps, kind="stable")
    bounds = np.flatnonzero(np.r_[True, comps[order][1:] != comps[order][:-1], True])
    clash = np.flatnonzero(same == 1)  # inner edges used twice in one direction
    witness = {}
    for k in clash[::-1].tolist():  # the first of each component wins
        witness[int(component[fa[k]])] = k
    for g in range(len(bounds) - 1):
        faces = np.sort(face_origin[flipped[order[bounds[g] : bounds[g + 1]]]])
        c = int(comps[order[bounds[g]]])
        shown = ", ".join(map(str, faces[:6].tolist())) + (", ..." if len(faces) > 6 else "")
        where = f"face {shown}" if len(faces) == 1 else f"faces {shown}"
        if c in witness:
            k = witness[c]
            a, b = sorted(int(vert_orig[x]) for x in he.edge_ends[inner[k]])
            f, h = sorted((int(face_origin[fa[k]]), int(face_origin[fb[k]])))
            why = (
                f"faces {f} and {h} use edge ({a}, {b}) in the same direction (inconsistent "
                f"orientation): {len(faces)} of the {int(comp_size[c])} faces of that piece "
                "reversed to agree with their neighbours"
                + ("" if is_open[c] else ", the closed piece facing outward")
            )
        else:
            why = (
                f"the closed piece of {int(comp_size[c])} faces was inside out (negative "
                "volume): all its faces reversed to face outward"
            )
        log.add("flip-face", where, why, error="")


def _folded_edges(he: _HalfEdges, face_list, v) -> list:
    """The edges along which two faces meet back to back (their normals opposite within
    ``tol.coplanar_deg``: folded by 180 degrees, the surface doubling back on itself -- a
    flange or fin modelled without thickness, a triangle folded over, two objects lying on
    each other), as ``(x, y, f, g)``: current vertices ``x < y`` and faces ``f < g``."""
    normal = _face_newell(_Flat.of(face_list), v)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    inner = np.flatnonzero(he.edge_count == 2)
    fa, fb = he.face[he.edge_he0[inner]], he.face[he.edge_he1[inner]]
    flat = np.einsum("ij,ij->i", normal[fa], normal[fb]) < -np.cos(np.radians(tol.coplanar_deg))
    out = []
    for k in np.flatnonzero(flat).tolist():
        x, y = (int(u) for u in he.edge_ends[inner[k]])
        f, g = sorted((int(fa[k]), int(fb[k])))
        out.append((x, y, f, g))
    return out


def _unfold(he: _HalfEdges, face_list, face_origin, v, vert_orig, log: RepairLog, strict: bool):
    """Resolve every edge along which two faces lie back to back (:func:`_folded_edges`).

    Such an edge is cut open where that separates its two faces (:func:`split_non_manifold`:
    where the cuts reach the border or split a vertex's fan); an edge inside the surface
    cannot be cut alone, and there the face of the two that agrees least with its other
    neighbours (a triangle folded over) is dropped, leaving a hole. Each reported; a cut
    makes no new fold, a dropped face none either, so two rounds suffice.

    Returns
    -------
    faces, origin, v, vert_orig, flipped

    Raises
    ------
    MeshError
        With ``strict``, naming the first such edge (input indices) and its two faces.
    """
    flipped = 0
    for _ in range(4):
        folded = _folded_edges(he, face_list, v)
        if not folded:
            break
        x, y, f, g = folded[0]
        a, b = sorted((int(vert_orig[x]), int(vert_orig[y])))
        if strict:
            f0, g0 = int(face_origin[f]), int(face_origin[g])
            raise MeshError(
                f"faces {f0} and {g0} lie back to back along edge ({a}, {b}) (folded by 180 deg): "
                "the surface doubles back on itself there (two objects on each other?)",
                edge=(a, b),
            )
        cut = folded
        while cut:  # the edges whose cut separates their faces (a trial on a scratch log)
            trial = split_non_manifold(
                face_list, face_origin, v, vert_orig, RepairLog(), unpaired=[e[:2] for e in cut]
            )[0]
            apart = [e for e in cut if _separated(trial, e)]
            if len(apart) == len(cut):
                break
            cut = apart
        drop = [e for e in folded if e not in cut]
        why = {
            (x, y): (
                f"faces {int(face_origin[f])} and {int(face_origin[g])} lie back to back along "
                "it (folded by 180 deg: the surface doubles back on itself there): cut open, "
                "each face keeps a border there"
            )
            for x, y, f, g in cut
        }
        if cut:
            face_list, v, vert_orig = split_non_manifold(
                face_list, face_origin, v, vert_orig, log, unpaired=[e[:2] for e in cut], why=why
            )
        if drop:
            face_list, face_origin = _drop_folded_over(
                he, face_list, face_origin, v, vert_orig, drop, log
            )
            face_list, v, vert_orig = split_non_manifold(face_list, face_origin, v, vert_orig, log)
        he = _HalfEdges(face_list, len(v))
        face_list, flipped2, _ = _orient(
            he, face_list, v, face_origin, True, log=log, vert_orig=vert_orig
        )
        flipped += flipped2
        he = _HalfEdges(face_list, len(v))
    return face_list, face_origin, v, vert_orig, flipped


def _separated(faces, e) -> bool:
    """Whether faces ``f`` and ``g`` of ``e = (x, y, f, g)`` no longer share two vertices."""
    _, _, f, g = e
    return len(set(faces[f].tolist()) & set(faces[g].tolist())) < 2


def _drop_folded_over(he: _HalfEdges, face_list, face_origin, v, vert_orig, edges, log):
    """Drop, for each ``(x, y, f, g)`` of ``edges``, the face of ``f``, ``g`` whose normal
    agrees least (mean cosine) with its neighbours' across its other edges (reported)."""
    normal = _face_newell(_Flat.of(face_list), v)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    inner = np.flatnonzero(he.edge_count == 2)
    fa, fb = he.face[he.edge_he0[inner]], he.face[he.edge_he1[inner]]
    dots = np.einsum("ij,ij->i", normal[fa], normal[fb])
    agree = np.zeros(len(face_list))
    count = np.zeros(len(face_list))
    np.add.at(agree, fa, dots)
    np.add.at(agree, fb, dots)
    np.add.at(count, fa, 1)
    np.add.at(count, fb, 1)
    dropped = set()
    for x, y, f, g in edges:
        if f in dropped or g in dropped:
            continue
        d = float(normal[f] @ normal[g])  # their own edge, taken out of both means
        mean = [(agree[h] - d) / max(count[h] - 1, 1) for h in (f, g)]
        h, other = (g, f) if mean[1] <= mean[0] else (f, g)
        dropped.add(h)
        a, b = sorted((int(vert_orig[x]), int(vert_orig[y])))
        log.add(
            "drop-face",
            f"face {int(face_origin[h])}",
            f"it lies back to back on face {int(face_origin[other])} along edge ({a}, {b}) "
            "(folded over by 180 deg, inside the surface where no cut can separate them) and "
            f"agrees least with its other neighbours: dropped, leaving a hole",
            error="",
        )
    keep = np.array([i not in dropped for i in range(len(face_list))])
    return [f for f, k in zip(face_list, keep, strict=True) if k], face_origin[keep]


def _check_not_soup(he: _HalfEdges, face_list, face_origin) -> None:
    """Raise when no two of three or more faces share an edge (a triangle soup that welding
    did not join)."""
    if len(face_list) > 2 and not (he.edge_count == 2).any():
        raise MeshError(
            f"no two of the {len(face_list)} faces share an edge, even after welding vertices "
            f"closer than {tol.weld:g} of the mesh size: a triangle soup, not a surface",
            face=int(face_origin[0]),
        )


# ------------------------------------------------------------- 7. non-planar, non-convex faces
def _split_non_planar(face_list, face_origin, v, log: RepairLog):
    """Triangulate every polygon not planar within ``tol.planar`` of its diameter."""
    fl = _Flat.of(face_list)
    dist, diam = _face_planarity(fl, v)
    bad = np.flatnonzero((dist > tol.planar * diam) & (fl.size > 3))
    return split_into_triangles(
        face_list,
        face_origin,
        v,
        bad,
        log,
        lambda i: (
            f"not planar (a vertex is {dist[i] / diam[i]:.2g} of its diameter from its plane)"
        ),
        lambda o, i: (
            f"face {o} is not planar: a vertex is {dist[i]:.3g} from its best plane, "
            f"more than {tol.planar:g} x its diameter {diam[i]:.3g}"
        ),
    )


def _split_non_convex(face_list, face_origin, v, log: RepairLog):
    """Triangulate every polygon with a reflex corner (a reflex corner would leave its vertex
    without a cone); the coplanar merge regroups the triangles into convex parts."""
    fl = _Flat.of(face_list)
    reflex = _corner_angles(fl, v) > np.pi + tol.collinear
    bad = np.flatnonzero(np.bincount(fl.face[reflex], minlength=len(fl.size)) > 0)
    return split_into_triangles(
        face_list,
        face_origin,
        v,
        bad,
        log,
        lambda i: (
            "not convex (a reflex corner leaves no room for the straight crease of its "
            "vertex's cone)"
        ),
        lambda o, i: "",
    )


# ------------------------------------------------------------------------ 8. coplanar merge
def _merge_coplanar(face_list, face_origin, v, coplanar_deg):
    """Merge neighbouring coplanar faces into convex polygons.

    Regions start as the faces; neighbouring regions across an edge whose faces' normals
    differ by less than ``coplanar_deg`` are merged, pair after pair from a work list (in
    face order, breadth first; a merged region's pairs are tried again), when the merged
    polygon stays one simple loop (the two share one chain of edges), convex, within
    ``tol.planar`` of its diameter from the first face's plane, and without a corner within
    ``tol.straight`` of straight that is not straight within ``tol.collinear``. Only the two
    corners at the ends of the shared chain change, so only they are checked.

    Returns
    -------
    faces : list of (k,) int
    origin : (n_faces,) int
        Smallest input face of each merged polygon.
    """
    he = _HalfEdges(face_list, len(v))
    normal = _face_newell(_Flat.of(face_list), v)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    inner = np.nonzero(he.edge_count == 2)[0]
    fa = he.face[he.edge_he0[inner]]
    fb = he.face[he.edge_he1[inner]]
    cos_lim = np.cos(np.radians(coplanar_deg))
    flat = np.einsum("ij,ij->i", normal[fa], normal[fb]) > cos_lim
    if not flat.any():
        return face_list, face_origin
    n_faces = len(face_list)
    neighbours: list[set] = [set() for _ in range(n_faces)]
    for x, y in zip(fa[flat].tolist(), fb[flat].tolist(), strict=True):
        neighbours[x].add(y)
        neighbours[y].add(x)
    parent = list(range(n_faces))  # union-find of regions; a region is named by its root

    def root(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    loop = {f: face_list[f].tolist() for f in range(n_faces) if neighbours[f]}
    axes_of = _plane_axes_many(normal)
    plane = {}  # root -> (normal, point, axes)
    diam = {}
    pts = v.tolist()
    work = deque((f, g) for f in range(n_faces) for g in sorted(neighbours[f]) if f < g)
    while work:
        x, y = (root(f) for f in work.popleft())
        if x == y:
            continue
        a, b = min(x, y), max(x, y)  # the region of the lower face absorbs the other
        merged = _splice(loop[a], loop[b])
        if merged is None:
            continue
        if a not in plane:
            plane[a] = (normal[a], v[loop[a][0]], axes_of[a])
            diam[a] = _diameter(v[loop[a]])
        n, p0, axes = plane[a]
        d = max(diam[a], _diameter(v[merged]))
        off = np.abs((v[loop[b]] - p0) @ n).max()
        if off > tol.planar * d or not _convex_ends(merged, loop[a], loop[b], pts, axes):
            continue
        parent[b] = a
        loop[a] = merged
        diam[a] = d
        neighbours[a] |= neighbours[b]
        for g in sorted(neighbours[b]):
            if root(g) != a:
                work.append((a, g))
    out, origin = [], []
    members: dict[int, list[int]] = {}
    for f in range(n_faces):
        members.setdefault(root(f), []).append(f)
    for r in sorted(members):
        fs = members[r]
        out.append(np.asarray(loop[r], dtype=np.int64) if len(fs) > 1 else face_list[r])
        origin.append(int(face_origin[fs].min()))
    return out, np.asarray(origin, dtype=np.int64)


def _remove_flat_vertices(face_list, face_origin, v, coplanar_deg):
    """Remove the interior vertices of flat regions: a vertex whose faces around it are all
    coplanar (within ``coplanar_deg``) has nothing to round; its fan is replaced by the
    triangles of the polygon around it, for the merge to regroup into convex parts.

    Returns
    -------
    faces : list of (k,) int
    origin : (n_faces,) int
    removed : int
        Vertices removed.
    """
    he = _HalfEdges(face_list, len(v))
    normal = _face_newell(_Flat.of(face_list), v)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    f0 = he.face[he.edge_he0]
    f1 = he.face[np.maximum(he.edge_he1, 0)]
    cos_lim = np.cos(np.radians(coplanar_deg))
    flat = (he.edge_count == 2) & (np.einsum("ij,ij->i", normal[f0], normal[f1]) > cos_lim)
    ends = he.edge_ends
    n = len(v)
    not_flat = np.zeros(n, dtype=bool)
    not_flat[ends[~flat].ravel()] = True  # a bent or boundary edge
    candidates = np.flatnonzero(~not_flat & (np.bincount(ends.ravel(), minlength=n) > 0))
    if not len(candidates):
        return face_list, face_origin, 0
    faces_of: dict[int, list[int]] = {}
    for f, x in zip(he.face.tolist(), he.frm.tolist(), strict=True):
        faces_of.setdefault(x, []).append(f)
    touched: set[int] = set()
    replace: dict[int, list] = {}  # first face of a fan -> its triangles; others dropped
    dropped: set[int] = set()
    base = len(v)
    used = edge_keys(face_list, base)
    for u in candidates.tolist():
        fan = faces_of[u]
        if touched.intersection(fan):
            continue
        loop = _fan_boundary(u, [face_list[f].tolist() for f in fan])
        if loop is None:
            continue
        tris = triangulate_polygon_3d(v[loop])
        new = {
            min(loop[t[i]], loop[t[i - 1]]) * base + max(loop[t[i]], loop[t[i - 1]])
            for t in tris
            for i in range(3)
        }
        ring = {
            min(a, b) * base + max(a, b) for a, b in zip(loop, loop[1:] + loop[:1], strict=True)
        }
        if (new - ring) & used:
            continue  # a diagonal that is an edge elsewhere (the mesh crosses itself): keep u
        used |= new
        touched.update(fan)
        first = min(fan)
        tris = [np.asarray([loop[i] for i in t], dtype=np.int64) for t in tris]
        replace[first] = (tris, int(face_origin[fan].min()))
        dropped.update(f for f in fan if f != first)
    if not replace:
        return face_list, face_origin, 0
    out, origin = [], []
    for f, (face, o) in enumerate(zip(face_list, face_origin.tolist(), strict=True)):
        if f in dropped:
            continue
        if f in replace:
            tris, o = replace[f]
            out.extend(tris)
            origin.extend([o] * len(tris))
        else:
            out.append(face)
            origin.append(o)
    return out, np.asarray(origin, dtype=np.int64), len(replace)


def _fan_boundary(u: int, fan: list) -> list | None:
    """The loop around vertex ``u`` of its faces ``fan`` (counter-clockwise lists, a closed
    fan), or None when it is not one simple loop."""
    nxt = {}
    for face in fan:
        k = face.index(u)
        path = face[k + 1 :] + face[:k]  # from the vertex after u round to the one before
        if path[0] in nxt:
            return None
        for a, b in itertools.pairwise(path):
            if a in nxt:
                return None
            nxt[a] = b
    start = next(iter(nxt))
    loop, x = [start], nxt.get(start)
    while x is not None and x != start and len(loop) <= len(nxt):
        loop.append(x)
        x = nxt.get(x)
    if x != start or len(loop) != len(nxt) or len(loop) < 3:
        return None
    return loop


def _plane_axes_many(n: np.ndarray) -> np.ndarray:
    """(k, 2, 3) in-plane axes ``e1, e2`` (``e1 x e2 = n``) of unit normals ``n`` (k, 3), as
    :func:`~filletfold.mesh.repair.plane_axes` gives them one at a time."""
    pick = np.eye(3)[np.argmin(np.abs(n), axis=1)]
    e1 = np.cross(n, pick)
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    return np.stack([e1, np.cross(n, e1)], axis=1)


def _diameter(p: np.ndarray) -> float:
    """Diagonal of the bounding box of points (k, 3): at least their diameter, at most
    sqrt(3) times it."""
    return float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))


def _convex_ends(merged: list, loop_a: list, loop_b: list, pts: list, axes) -> bool:
    """Whether the corners of ``merged`` where ``loop_a`` and ``loop_b`` meet (the two ends
    of their shared chain: the only vertices of both) are convex seen along ``e1 x e2`` of
    ``axes``, and not within ``tol.straight`` of straight unless straight within
    ``tol.collinear``."""
    k = len(merged)
    both = set(loop_a).intersection(loop_b)
    (e10, e11, e12), (e20, e21, e22) = axes.tolist()
    for i, x in enumerate(merged):
        if x not in both:
            continue  # a corner of one of the two, unchanged
        p, q, r = pts[merged[i - 1]], pts[x], pts[merged[(i + 1) % k]]
        u = (q[0] - p[0], q[1] - p[1], q[2] - p[2])
        w = (r[0] - q[0], r[1] - q[1], r[2] - q[2])
        ux, uy = u[0] * e10 + u[1] * e11 + u[2] * e12, u[0] * e20 + u[1] * e21 + u[2] * e22
        wx, wy = w[0] * e10 + w[1] * e11 + w[2] * e12, w[0] * e20 + w[1] * e21 + w[2] * e22
        turn = math.atan2(ux * wy - uy * wx, ux * wx + uy * wy)
        if turn < -tol.collinear or tol.collinear < turn < tol.straight:
            return False
    return True


def _splice(loop: list, face: list) -> list | None:
    """The loop of a region and a face merged along the one chain of edges they share
    (counter-clockwise, both), or None when they share no edge, several chains, or the
    merged loop would visit a vertex twice."""
    n, k = len(loop), len(face)
    f_edges = {(face[j], face[(j + 1) % k]) for j in range(k)}
    shared = [(loop[(i + 1) % n], loop[i]) in f_edges for i in range(n)]
    m = sum(shared)
    if m == 0 or m >= n or m >= k:
        return None
    starts = [i for i in range(n) if shared[i] and not shared[i - 1]]
    if len(starts) != 1:
        return None
    s = starts[0]
    a, b = loop[s], loop[(s + m) % n]
    part = [loop[(s + m + t) % n] for t in range(n - m + 1)]  # b ... a along the region
    j, jb = (face.index(a) + 1) % k, face.index(b)
    while j != jb:  # the face from a on to b, ends excluded
        part.append(face[j])
        j = (j + 1) % k
    if len(part) != n + k - 2 * m or len(set(part)) != len(part):
        return None
    return part


def _remove_straight_corners(face_list, v) -> list[np.ndarray]:
    fl = _Flat.of(face_list)
    is_straight = np.abs(_corner_angles(fl, v) - np.pi) <= tol.collinear
    if not is_straight.any():  # nothing to remove (the usual case)
        return [np.asarray(f, dtype=np.int64) for f in face_list]
    faces = [f.tolist() for f in face_list]
    straight = fl.split(is_straight)
    incident: dict[int, list[int]] = {}
    edges: set[tuple[int, int]] = set()
    for i, f in enumerate(faces):
        for a, b in zip(f, f[1:] + f[:1], strict=True):
            incident.setdefault(a, []).append(i)
            edges.add((min(a, b), max(a, b)))
    candidates = []
    for u, fs in incident.items():
        if len(fs) > 2 or not all(straight[i][faces[i].index(u)] for i in fs):
            continue
        nbrs = set()
        for i in fs:
            f = faces[i]
            j = f.index(u)
            nbrs.update((f[j - 1], f[(j + 1) % len(f)]))
        if len(nbrs) == 2:  # exactly two edges: 2 faces inside, or 1 face on the boundary
            candidates.append(u)
    for u in sorted(candidates):
        fs = incident[u]
        f0 = faces[fs[0]]
        j = f0.index(u)
        a, b = f0[j - 1], f0[(j + 1) % len(f0)]
        if (min(a, b), max(a, b)) in edges or any(len(faces[i]) <= 3 for i in fs):
            continue
        for i in fs:
            faces[i].remove(u)
        edges.discard((min(a, u), max(a, u)))
        edges.discard((min(u, b), max(u, b)))
        edges.add((min(a, b), max(a, b)))
    return [np.array(f, dtype=np.int64) for f in faces]


def _split_straight_corners(face_list, face_origin, v, vert_orig, coplanar_deg, log: RepairLog):
    """Split every polygon at each corner within ``tol.straight`` of straight where one of the
    corner's two edges is bent (its faces differ by ``coplanar_deg`` or more, so it is
    rounded): a diagonal from that corner to the opposite one, since the two tangent lines
    there would cross far away or not at all."""
    he = _HalfEdges(face_list, len(v))
    normal = _face_newell(_Flat.of(face_list), v)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    two = he.edge_count == 2
    f0 = he.face[he.edge_he0]
    f1 = he.face[np.maximum(he.edge_he1, 0)]
    bent = two & (np.einsum("ij,ij->i", normal[f0], normal[f1]) < np.cos(np.radians(coplanar_deg)))
    edge_bent = {
        tuple(e): bool(b) for e, b in zip(he.edge_ends.tolist(), bent.tolist(), strict=True)
    }
    out, origin = [], []
    base = len(v)
    used = None  # the edges, as edge_keys gives them: made when a corner is to be split
    pending = deque(zip(face_list, face_origin.tolist(), strict=True))
    while pending:
        f, o = pending.popleft()
        if len(f) >= 4:
            axes = plane_axes(polygon_normal(v[f]))
            turn = corner_turns((v[f] - v[f[0]]) @ axes.T)
            k = len(f)
            fl = f.tolist()
            sides = [
                edge_bent.get((min(a, b), max(a, b)), True)
                for a, b in zip(fl, fl[1:] + fl[:1], strict=True)
            ]
            bad = [
                i for i in range(k) if abs(turn[i]) < tol.straight and (sides[i] or sides[i - 1])
            ]
            split = None
            if bad and used is None:
                used = edge_keys(face_list, base)
            for i in bad:
                # to the corner furthest from the straight line at i (both parts keep an area)
                # whose diagonal is no edge yet
                p = v[f]
                d = p[(i + 1) % k] - p[i - 1]
                off = np.linalg.norm(np.cross(p - p[i], d / np.linalg.norm(d)), axis=1)
                off[[i - 1, i, (i + 1) % k]] = -1.0
                for j in np.argsort(-off, kind="stable").tolist():
                    key = min(fl[i], fl[j]) * base + max(fl[i], fl[j])
                    if off[j] > 0 and key not in used:
                        split = i, j
                        used.add(key)
                        break
                if split is not None:
                    break
            if split is not None:
                i, j = split
                lo, hi = min(i, j), max(i, j)
                log.add(
                    "split-face",
                    f"face {o}",
                    f"its corner at vertex {_vertex_name(vert_orig, f[i])} is "
                    f"{np.degrees(abs(turn[i])):.2g} deg from straight (below "
                    f"{np.degrees(tol.straight):.2g}) next to a rounded edge: split there",
                    error="",
                )
                pending.extendleft(
                    [(np.concatenate([f[hi:], f[: lo + 1]]), o), (f[lo : hi + 1], o)]
                )
                continue
        out.append(f)
        origin.append(o)
    return out, np.asarray(origin, dtype=np.int64)


# ----------------------------------------------------------------------------- 7. planarity
def _check_planar(face_list, v, face_origin) -> None:
    dist, diam = _face_planarity(_Flat.of(face_list), v)
    bad = np.nonzero(dist > tol.planar * diam)[0]
    if len(bad):
        i = int(bad[0])
        k = int(face_origin[i])
        raise MeshError(
            f"face {k} is not planar: a vertex is {dist[i]:.3g} from its best plane, more than "
            f"{tol.planar:g} x its diameter {diam[i]:.3g}",
            face=k,
        )
