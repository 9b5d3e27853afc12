"""Validation and repair of an input polygon mesh.

:func:`clean_mesh` turns raw ``(vertices, faces)`` into a :class:`~filletfold.mesh.PolyMesh`
that the rest of filletfold can trust: finite, no duplicate vertices, no degenerate faces,
edge- and vertex-manifold, consistently oriented (outward for closed shells), neighbouring
coplanar faces merged into single polygons, and every polygon planar.

Errors name the offending element by its index in the *input* (vertex, edge as a pair of input
vertex indices, or face).
"""

from __future__ import annotations

import logging
from collections import deque
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..errors import MeshError
from ..tolerances import tol
from .polymesh import PolyMesh

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
        Index in the cleaned mesh of each input vertex, ``-1`` where it was dropped.
    face_origin : (n_faces,) int
        For each cleaned face, the smallest input face index it was made from.
    """

    merged_vertices: int
    flipped_faces: int
    merged_faces: int
    removed_vertices: int
    vertex_map: np.ndarray = field(repr=False)
    face_origin: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64), repr=False)


def clean_mesh(
    vertices,
    faces,
    *,
    coplanar_deg: float = tol.coplanar_deg,
    merge_coplanar: bool = True,
) -> tuple[PolyMesh, CleanLog]:
    """Validate and repair a polygon mesh.

    Steps, in order: validate; merge duplicate vertices and reject degenerate faces; drop
    unreferenced vertices; reject non-manifold edges and vertices; orient faces consistently
    per connected component (outward on closed components); merge neighbouring coplanar faces
    and remove straight corners left by the merge; check every polygon is planar.

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

    Returns
    -------
    mesh : PolyMesh
    log : CleanLog

    Raises
    ------
    MeshError
        With ``vertex``, ``edge`` (pair of input vertex indices) or ``face`` (input index) set:
        non-finite coordinate, index out of range, no faces, degenerate or duplicate face,
        non-manifold edge or vertex, non-orientable component, non-planar face.

    Notes
    -----
    A merged coplanar region is kept as separate faces when its boundary is not one simple
    loop (a region with a hole, or one touching itself at a vertex) or when the merged polygon
    would not pass the planarity check. A straight corner is removed when it has exactly two
    edges (two faces inside the surface, or one face on the boundary) and its angle is pi
    within ``tol.angle`` in each of its faces.
    """
    v, face_list = _validate(vertices, faces)
    n_input = len(v)

    # 2. merge duplicate vertices, drop repeated indices, reject degenerate faces
    rep = _close_vertex_representatives(v)
    merged_vertices = n_input - len(np.unique(rep))
    face_list = _remap_faces(face_list, rep, v)

    # 3. drop unreferenced vertices
    used = np.unique(np.concatenate(face_list))
    new_of_rep = -np.ones(n_input, dtype=np.int64)
    new_of_rep[used] = np.arange(len(used))
    vertex_map = new_of_rep[rep]
    removed_vertices = int(n_input - merged_vertices - len(used))
    vert_orig = used.copy()  # input index of each current vertex
    v = v[used]
    face_list = [new_of_rep[f] for f in face_list]
    face_origin = np.arange(len(face_list), dtype=np.int64)

    # 4. manifold checks
    he = _HalfEdges(face_list, len(v))
    _check_manifold(he, vert_orig)

    # 5. orientation
    face_list, flipped = _orient(he, face_list, v, face_origin)

    # 6. coplanar merge, straight corners, unreferenced vertices
    merged_faces = 0
    if merge_coplanar and coplanar_deg > 0 and len(face_list) > 1:
        face_list, face_origin, merged_faces = _merge_coplanar(
            face_list, face_origin, v, coplanar_deg
        )
        face_list = _remove_straight_corners(face_list, v)
        used = np.unique(np.concatenate(face_list))
        if len(used) < len(v):
            compact = -np.ones(len(v), dtype=np.int64)
            compact[used] = np.arange(len(used))
            removed_vertices += int(len(v) - len(used))
            vertex_map = np.where(vertex_map >= 0, compact[np.maximum(vertex_map, 0)], -1)
            vert_orig = vert_orig[used]
            v = v[used]
            face_list = [compact[f] for f in face_list]

    # 7. planarity
    _check_planar(face_list, v, face_origin)

    mesh = PolyMesh(v, face_list)
    log = CleanLog(
        merged_vertices=int(merged_vertices),
        flipped_faces=int(flipped),
        merged_faces=int(merged_faces),
        removed_vertices=int(removed_vertices),
        vertex_map=vertex_map,
        face_origin=face_origin,
    )
    logger.debug("clean_mesh: %s", log)
    return mesh, log


# ------------------------------------------------------------------------------ 1. validate
def _validate(vertices, faces) -> tuple[np.ndarray, list[np.ndarray]]:
    try:
        v = np.asarray(vertices, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise MeshError(f"vertices cannot be read as a float array: {exc}") from exc
    if v.ndim != 2 or v.shape[1] != 3:
        raise MeshError(f"vertices must have shape (n, 3), got {v.shape}")
    bad = np.nonzero(~np.isfinite(v).all(axis=1))[0]
    if len(bad):
        i = int(bad[0])
        raise MeshError(f"vertex {i} has a non-finite coordinate {v[i].tolist()}", vertex=i)
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


# ------------------------------------------------------------------ 2. duplicates, degenerate
def _close_vertex_representatives(v: np.ndarray) -> np.ndarray:
    """(n,) int: for each vertex, the smallest index of the cluster of vertices it is close to."""
    n = len(v)
    if n < 2:
        return np.arange(n, dtype=np.int64)
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    pairs = cKDTree(v).query_pairs(tol.merge * diag, output_type="ndarray")
    if len(pairs) == 0:
        return np.arange(n, dtype=np.int64)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    first = np.full(labels.max() + 1, n, dtype=np.int64)
    np.minimum.at(first, labels, np.arange(n))
    return first[labels]


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
        start = np.concatenate([[0], np.cumsum(size)])
        index = np.concatenate(face_list).astype(np.int64)
        face = np.repeat(np.arange(len(face_list)), size)
        local = np.arange(len(index)) - start[face]
        nxt = start[face] + (local + 1) % size[face]
        prv = start[face] + (local - 1) % size[face]
        return cls(index, start, size, face, nxt, prv)

    def split(self, values: np.ndarray) -> list[np.ndarray]:
        return np.split(values, self.start[1:-1])


def _face_newell(fl: _Flat, v: np.ndarray) -> np.ndarray:
    """(n_faces, 3) float: Newell vectors (twice the vector areas), computed about each centroid."""
    p = v[fl.index]
    centroid = np.add.reduceat(p, fl.start[:-1], axis=0) / fl.size[:, None]
    p = p - centroid[fl.face]
    return np.add.reduceat(np.cross(p, p[fl.next]), fl.start[:-1], axis=0)


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


def _remap_faces(face_list, rep, v) -> list[np.ndarray]:
    fl = _Flat.of(face_list)
    g = rep[fl.index]
    n = len(v)
    # distinct vertices per face, and the face with consecutive repeats dropped
    pairs = np.unique(fl.face * n + g)
    distinct = np.bincount(pairs // n, minlength=len(fl.size))
    keep = g != g[fl.prev]
    kept = np.bincount(fl.face[keep], minlength=len(fl.size))
    few = np.nonzero(distinct < 3)[0]
    if len(few):
        i = int(few[0])
        raise MeshError(
            f"degenerate face {i}: it has {int(distinct[i])} distinct vertices after merging "
            f"duplicates (at least 3 needed)",
            face=i,
        )
    twice = np.nonzero(distinct < kept)[0]
    if len(twice):
        i = int(twice[0])
        face = g[keep][fl.face[keep] == i]
        raise MeshError(f"degenerate face {i}: it visits a vertex twice ({face.tolist()})", face=i)
    out = np.split(g[keep], np.cumsum(kept)[:-1])
    fl = _Flat.of(out)
    mean_edge = float(np.linalg.norm(v[fl.index[fl.next]] - v[fl.index], axis=1).mean())
    min_area = tol.area * mean_edge**2
    area = 0.5 * np.linalg.norm(_face_newell(fl, v), axis=1)
    small = np.nonzero(area <= min_area)[0]
    if len(small):
        i = int(small[0])
        raise MeshError(
            f"degenerate face {i}: its area {area[i]:.3g} is below {min_area:.3g} "
            f"(tol.area * mean_edge**2)",
            face=i,
        )
    twin = _first_duplicate(fl)
    if twin is not None:
        i, first = twin
        raise MeshError(
            f"degenerate face {i}: it uses the same vertices as face {first} (duplicate face)",
            face=i,
        )
    return out


def _first_duplicate(fl: _Flat) -> tuple[int, int] | None:
    """The first face (in order) with the same set of vertices as an earlier face, and that
    earlier face's index; None when every face has its own set."""
    best = None
    for k in np.unique(fl.size).tolist():
        rows = np.flatnonzero(fl.size == k)
        keys = np.sort(fl.index[fl.start[rows][:, None] + np.arange(k)], axis=1)
        _, first, inverse, count = np.unique(
            keys, axis=0, return_index=True, return_inverse=True, return_counts=True
        )
        inverse = inverse.reshape(-1)
        later = np.flatnonzero((count[inverse] > 1) & (np.arange(len(rows)) != first[inverse]))
        if len(later):
            j = int(later[0])  # rows are in face order: the first repeat of its size
            hit = (int(rows[j]), int(rows[first[inverse[j]]]))
            best = hit if best is None or hit[0] < best[0] else best
    return best


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


# ------------------------------------------------------------------------------ 5. orient
def _flip(f: np.ndarray) -> np.ndarray:
    return np.concatenate([f[:1], f[:0:-1]])


def _orient(he: _HalfEdges, face_list, v, face_origin) -> tuple[list[np.ndarray], int]:
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
    return out, int(parity.sum())


# ------------------------------------------------------------------------ 6. coplanar merge
def _merge_coplanar(face_list, face_origin, v, coplanar_deg):
    he = _HalfEdges(face_list, len(v))
    normal = _face_newell(_Flat.of(face_list), v)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    inner = np.nonzero(he.edge_count == 2)[0]
    fa = he.face[he.edge_he0[inner]]
    fb = he.face[he.edge_he1[inner]]
    cos_lim = np.cos(np.radians(coplanar_deg))
    flat = np.einsum("ij,ij->i", normal[fa], normal[fb]) > cos_lim
    n_faces = len(face_list)
    if not flat.any():
        return face_list, face_origin, 0
    graph = coo_matrix((np.ones(int(flat.sum())), (fa[flat], fb[flat])), shape=(n_faces, n_faces))
    _, group = connected_components(graph, directed=False)
    twin_face = -np.ones(len(he.frm), dtype=np.int64)
    h0, h1 = he.edge_he0[inner], he.edge_he1[inner]
    twin_face[h0] = he.face[h1]
    twin_face[h1] = he.face[h0]
    members: dict[int, list[int]] = {}
    for f, g in enumerate(group.tolist()):
        members.setdefault(g, []).append(f)
    loops: dict[int, np.ndarray] = {}  # group -> merged polygon
    for g, fs in members.items():
        if len(fs) < 2:
            continue
        loop = _group_boundary(fs, he, group, twin_face, g)
        if loop is None:
            logger.debug("coplanar faces %s kept: boundary is not one simple loop", fs)
            continue
        loops[g] = loop
    if loops:
        dist, diam = _face_planarity(_Flat.of(list(loops.values())), v)
        for g, d, size in zip(list(loops), dist, diam, strict=True):
            if d > tol.planar * size:
                logger.debug("coplanar faces %s kept: merged polygon not planar", members[g])
                del loops[g]
    replaced: dict[int, np.ndarray] = {}  # first face of a merged group -> merged polygon
    dropped: set[int] = set()
    removed = 0
    for g, loop in loops.items():
        fs = members[g]
        replaced[fs[0]] = loop
        dropped.update(fs[1:])
        removed += len(fs) - 1
    out, origin = [], []
    for f in range(n_faces):
        if f in dropped:
            continue
        if f in replaced:
            out.append(replaced[f])
            origin.append(min(int(face_origin[x]) for x in members[group[f]]))
        else:
            out.append(face_list[f])
            origin.append(int(face_origin[f]))
    return out, np.array(origin, dtype=np.int64), removed


def _group_boundary(fs, he, group, twin_face, g) -> np.ndarray | None:
    """The boundary of a group of faces as one CCW vertex loop, or None if not one simple loop."""
    hs = np.concatenate([np.arange(he.start[f], he.start[f + 1]) for f in fs])
    tw = twin_face[hs]
    outside = (tw < 0) | (group[np.maximum(tw, 0)] != g)
    hs = hs[outside]
    frm = he.frm[hs]
    if len(np.unique(frm)) != len(frm):
        return None
    nxt = dict(zip(frm.tolist(), he.to[hs].tolist(), strict=True))
    start = int(frm.min())
    loop = [start]
    u = nxt[start]
    while u != start:
        if u not in nxt or len(loop) > len(frm):
            return None
        loop.append(u)
        u = nxt[u]
    if len(loop) != len(frm) or len(loop) < 3:
        return None
    return np.array(loop, dtype=np.int64)


def _remove_straight_corners(face_list, v) -> list[np.ndarray]:
    fl = _Flat.of(face_list)
    is_straight = np.abs(_corner_angles(fl, v) - np.pi) <= tol.angle
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
