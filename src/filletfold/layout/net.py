"""Nets: vertex modules joined into few flat pieces (issue 4's fabrication layout).

Neighbouring modules share a border (the midpoint base curve of their common edge and the
face-piece dividers beside it). Every module starts as a net of its own; two nets are joined
across a shared border by the rigid motion that matches the smaller net's copy of the border
points to the larger's, if the moved net then overlaps nothing of the other and the two still
fit the sheet, the smallest pairs first (:func:`build_nets`). Each cone keeps its angle-defect
cut, since the border a module shares with one neighbour never includes its own cut; choosing
each module's cut by :func:`cut_edges_for_nets` lets every other border be glued.
"""

from __future__ import annotations

import heapq

import numpy as np
import shapely
from scipy.sparse import csr_matrix
from scipy.spatial import cKDTree

from ..arrays import run_next, run_starts
from ..surface.faces import FaceLists, face_polygons, flat_faces
from ..surface.piece import Piece
from ..tolerances import tol


def rigid_fit(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """3x3 homogeneous rotation + translation taking points ``src`` (k, 2) onto ``dst`` (least
    squares; never a reflection, which cannot glue orientation-preserving pieces). In the
    plane the best rotation has the angle of the summed cross and dot products of the centred
    point pairs (the 2D Kabsch solution in closed form)."""
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - cs, dst - cd
    angle = np.arctan2(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]), np.sum(a * b))
    c, s = np.cos(angle), np.sin(angle)
    m = np.eye(3)
    m[:2, :2] = [[c, -s], [s, c]]
    m[:2, 2] = cd - m[:2, :2] @ cs
    return m


def shared_points(pieces: list[Piece], eps: float, mesh=None) -> dict[tuple[int, int], list]:
    """Points of one piece that are points of another in 3D (their common border).

    With ``mesh``, only pieces of one vertex, or of two vertices of one face, share points:
    two modules that touch in space without a face between them (the copies of a split
    vertex, a triangle lying back to back on another part of the surface) have no border to
    glue, and a net joined there would fold flat (by 180 degrees) along it. Pieces of no
    vertex (``vertex < 0``) are not filtered.

    Returns
    -------
    dict
        ``(a, b) -> [(index in a, index in b), ...]`` for every ordered pair of pieces.
    """
    arrays = [p.arrays() for p in pieces]
    owner = np.concatenate([np.full(len(a[0]), k) for k, a in enumerate(arrays)])
    local = np.concatenate([np.arange(len(a[0])) for a in arrays])
    p3 = np.vstack([a[1] for a in arrays])
    pairs = cKDTree(p3).query_pairs(eps, output_type="ndarray")
    pairs = pairs[owner[pairs[:, 0]] != owner[pairs[:, 1]]]
    if mesh is not None and len(pairs):
        vertex = np.array([p.vertex for p in pieces], dtype=np.int64)
        u, w = vertex[owner[pairs[:, 0]]], vertex[owner[pairs[:, 1]]]
        pairs = pairs[share_face(mesh, u, w) | (u < 0) | (w < 0)]
    shared: dict[tuple[int, int], list] = {}
    for a, b in pairs:
        ka, kb = int(owner[a]), int(owner[b])
        shared.setdefault((ka, kb), []).append((int(local[a]), int(local[b])))
        shared.setdefault((kb, ka), []).append((int(local[b]), int(local[a])))
    return shared


def share_face(mesh, u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(k,) bool: whether mesh vertices ``u[i]`` and ``w[i]`` are one vertex or lie on a
    common face (a negative index: False)."""
    u, w = np.asarray(u, dtype=np.int64), np.asarray(w, dtype=np.int64)
    ok = (u >= 0) & (w >= 0)
    incidence = csr_matrix(
        (np.ones(len(mesh.halfedge_from)), (mesh.halfedge_from, mesh.halfedge_face)),
        shape=(mesh.n_vertices, max(mesh.n_faces, 1)),
    )
    common = np.zeros(len(u), dtype=bool)
    if ok.any():
        a, b = incidence[u[ok]], incidence[w[ok]]
        common[ok] = np.asarray(a.multiply(b).sum(axis=1)).ravel() > 0
    return ok & ((u == w) | common)


def merge_pieces(
    pieces: list[Piece], placement: list[np.ndarray], eps: float, vertex: int = -1
) -> Piece:
    """One piece from placed pieces, with coincident points (2D and 3D) merged."""
    p2s, p3s, flats, sizes, patches = [], [], [], [], []
    base = 0
    for piece, m in zip(pieces, placement, strict=True):
        p2, p3 = piece.arrays()
        flat, size = flat_faces(piece.faces)
        p2s.append(p2 @ m[:2, :2].T + m[:2, 2])
        p3s.append(p3)
        flats.append(flat + base)
        sizes.append(size)
        patches.extend(piece.patches)
        base += len(p2)
    out = Piece(
        vertex=vertex,
        points_2d=np.concatenate([np.zeros((0, 2)), *p2s]),
        points_3d=np.concatenate([np.zeros((0, 3)), *p3s]),
        faces=FaceLists.of_sizes(
            np.concatenate([np.zeros(0, np.int64), *flats]),
            np.concatenate([np.zeros(0, np.int64), *sizes]),
        ),
        patches=patches,
    )
    out.merge_coincident(eps)
    return out


def _outline(piece: Piece):
    """The union of the piece's faces in its own frame (one shape, holes kept)."""
    p2, _ = piece.arrays()
    polys = face_polygons(p2, piece.faces)
    # faces that share their edges exactly (a module's do) unite as a coverage, fast; the
    # general union where that is not what they are (its area not their sum, or invalid)
    shape = shapely.coverage_union_all(polys)
    area = float(shapely.area(polys).sum())
    if shape.is_valid and abs(shape.area - area) <= tol.relative * area:
        return shape
    return shapely.union_all(shapely.make_valid(polys)).buffer(0)


def _moved(shapes, m: np.ndarray):
    """A shape (or an array of them) moved by the homogeneous rigid motion ``m``."""
    return shapely.transform(shapes, lambda xy: _apply(m, xy))


def fits_sheet(points: np.ndarray, sheet) -> bool:
    """Whether points (k, 2) fit a ``sheet`` (width, height) in some rotation (their smallest
    rotated bounding rectangle does)."""
    if sheet is None:
        return True
    rect = shapely.minimum_rotated_rectangle(shapely.multipoints(points))
    xy = np.asarray(rect.exterior.coords)[:4]
    sides = sorted([np.linalg.norm(xy[1] - xy[0]), np.linalg.norm(xy[2] - xy[1])])
    return sides[0] <= min(sheet) and sides[1] <= max(sheet)


class _Placed:
    """The outlines of the pieces placed in one net and their bounding boxes: a net that would
    join is tested against the placed pieces whose boxes meet its own pieces' boxes only
    (all pairs of boxes compared at once), so growing a net costs a few small intersections
    per piece, not unions of the whole net. The pieces' border points stay in their own
    frames; ``place`` (shared by all nets) places them."""

    def __init__(self, ids, shapes, boxes):
        self.ids = np.asarray(ids, dtype=np.int64)
        self.shapes = shapes
        self.boxes = boxes
        self.hull = np.zeros((0, 2))

    def near(self, boxes: np.ndarray, eps: float) -> tuple[np.ndarray, np.ndarray]:
        """The pairs (index into ``boxes``, index of a placed piece) whose boxes meet within
        ``eps``, by the first then the second."""
        lo, hi = self.boxes[None, :, :2], self.boxes[None, :, 2:]
        return np.nonzero(
            ((lo <= boxes[:, None, 2:] + eps) & (boxes[:, None, :2] <= hi + eps)).all(axis=-1)
        )

    def clashes(self, moving: _Moving, overlap_tol: float, eps: float, thin: float) -> bool:
        """Whether any piece of ``moving`` (a net that would join, placed) overlaps the placed
        outlines by more than ``overlap_tol`` of its area (summed over them: they overlap one
        another by no more than that), or touches a placed piece at a point that is two points
        of the surface (a pinch: a cutter cuts it apart, Origami Simulator welds it). Points
        within ``eps`` are one. Any overlap wider than ``thin`` (twice its area over its
        perimeter, for each part of it) clashes too. The pairs of a moving and a placed
        outline whose boxes meet are tested all at once."""
        shapes = moving.shapes
        new, old = self.near(shapely.bounds(shapes), eps)
        if not len(new):
            return False
        mine, theirs = shapes[new], self.shapes[old]
        close = shapely.dwithin(theirs, mine, eps)  # only these can overlap
        new, old, mine, theirs = new[close], old[close], mine[close], theirs[close]
        both = shapely.intersection(theirs, mine)
        area = shapely.area(both)
        overlap = np.bincount(new, weights=area, minlength=len(shapes))
        if (overlap > overlap_tol * shapely.area(shapes)).any():
            return True
        # a small overlap still clashes unless it is a sliver along a border that glues (two
        # copies of it apart by round-off): a small face beside a large face piece overlapped
        # is far less than the tolerance of the whole piece (pyvista airplane)
        parts = shapely.get_parts(both[area > 0])
        if len(parts) and (2 * shapely.area(parts) > thin * shapely.length(parts)).any():
            return True
        for i, k in zip(new.tolist(), self.ids[old].tolist(), strict=True):
            p2, p3 = moving.corners(i)
            q2, q3 = moving.placed_corners(k)
            flat = np.linalg.norm(p2[:, None] - q2[None], axis=-1) <= eps
            if (np.linalg.norm(p3[:, None] - q3[None], axis=-1)[flat] > eps).any():
                return True
        return False

    def add(self, other: _Placed, shapes, hull: np.ndarray) -> None:
        """The pieces of ``other`` placed in this net, with their outlines ``shapes`` moved."""
        self.ids = np.concatenate([self.ids, other.ids])
        self.shapes = np.concatenate([self.shapes, shapes])
        self.boxes = np.concatenate([self.boxes, shapely.bounds(shapes)])
        self.hull = hull


class _Moving:
    """A net's pieces moved by the rigid motion ``m``: their outlines, and their border points
    (2D placed, 3D) on demand."""

    def __init__(self, ids, shapes, m, place, border):
        self.ids, self.shapes, self.m, self.place, self.border = ids, shapes, m, place, border

    def placed_corners(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Border points of piece ``k`` where it is placed: (k, 2) and (k, 3)."""
        p2, p3 = self.border[k]
        return _apply(self.place[k], p2), p3

    def corners(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Border points of the ``i``-th moving piece, moved."""
        k = int(self.ids[i])
        p2, p3 = self.border[k]
        return _apply(self.m @ self.place[k], p2), p3


def _border_points(piece: Piece) -> np.ndarray:
    """The indices of a piece's points on its border (on a side of one face only)."""
    flat, size = flat_faces(piece.faces)
    if not len(flat):
        return np.zeros(0, dtype=np.int64)
    sides = np.sort(np.c_[flat, flat[run_next(run_starts(size))]], axis=1)
    key = sides[:, 0] * (int(flat.max()) + 1) + sides[:, 1]
    _, inverse, count = np.unique(key, return_inverse=True, return_counts=True)
    return np.unique(sides[count[inverse] == 1])


def _hull(points: np.ndarray) -> np.ndarray:
    """The corners of the convex hull of points (k, 2)."""
    hull = shapely.convex_hull(shapely.multipoints(points))
    return shapely.get_coordinates(hull)


def cut_edges_for_nets(mesh, root: int | None = None) -> np.ndarray:
    """For every vertex, the incident edge its module is cut along, so that one net can form.

    Modules are glued across the edges of a spanning tree of the mesh's vertices (a
    shortest-path tree, by edge length, from the vertex nearest the centroid); every other
    edge is a seam to cut. The seams then form a spanning tree of the dual graph and, with each
    cone's angle-defect cut running into one of its own seams, the cut graph is a tree: the
    surface minus the cuts is one disk. Each vertex is therefore cut along an incident edge
    that is not in the glue tree (if it has none, along any edge: its net splits there).

    Parameters
    ----------
    mesh : PolyMesh
    root : int, optional
        Root of the glue tree (default: the vertex nearest the centroid).

    Returns
    -------
    (n_vertices,) int
        The edge each vertex's module is cut along.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import shortest_path

    n = mesh.n_vertices
    a, b = mesh.edges[:, 0], mesh.edges[:, 1]
    w = mesh.edge_length
    g = coo_matrix((np.r_[w, w], (np.r_[a, b], np.r_[b, a])), shape=(n, n)).tocsr()
    if root is None:
        centre = mesh.vertices.mean(axis=0)
        root = int(np.argmin(np.linalg.norm(mesh.vertices - centre, axis=1)))
    _, pred = shortest_path(g, indices=root, return_predecessors=True)
    edge_of = {(int(x), int(y)): e for e, (x, y) in enumerate(mesh.edges)}
    glue = np.zeros(mesh.n_edges, dtype=bool)
    for v in range(n):
        p = int(pred[v])
        if p >= 0:
            glue[edge_of[(min(v, p), max(v, p))]] = True
    cut = np.full(n, -1, dtype=np.int64)
    for e in np.argsort(glue, kind="stable"):  # seams first
        for v in mesh.edges[e]:
            if cut[v] < 0:
                cut[v] = e
    return cut


def build_nets(
    pieces: list[Piece],
    eps: float,
    sheet: tuple[float, float] | None = None,
    overlap_tol: float = tol.relative,
    mesh=None,
) -> tuple[list[Piece], list[list[int]]]:
    """Join pieces into nets that overlap nothing and fit the sheet.

    Every piece starts as a net of its own. Two nets are joined across a border their pieces
    share by the rigid motion that matches the smaller net's copy of the border points to the
    larger's, if the two copies are congruent to round-off, the smaller net, moved so,
    overlaps nothing of the larger (see :meth:`_Placed.clashes`: a sliver along the glued
    border aside), no two of their pieces meet at a place that is two points of the surface,
    and the two still fit the sheet. The joins are tried smallest pair first (the sum of the
    two nets' pieces, then the longer border): nets grow side by side instead of one net
    winding around the object and leaving its gaps to single pieces (a 2,904-vertex scan's
    modules, cut at their ring starts: 355 nets, 13 of one piece, instead of 565, 260 of one
    piece, grown from one seed at a time). Each border is tried once; a join that fails is
    not tried again. The glued points of a net are merged.

    Parameters
    ----------
    pieces : list of Piece
        Vertex modules (each a valid flat piece).
    eps : float
        Distance under which two points are one.
    sheet : (float, float), optional
        Width and height a net must fit in (pattern units, any rotation).
    overlap_tol : float
        Overlap area allowed between a moved piece and the net it joins, relative to the
        piece's area.
    mesh : PolyMesh, optional
        The mesh of the pieces' vertices: borders only between modules of one face
        (:func:`shared_points`).

    Returns
    -------
    nets : list of Piece
        One piece per net (``vertex = -1``), the most pieces first (ties: by first piece).
    members : list of list of int
        The input pieces in each net, ascending.
    """
    shared = shared_points(pieces, eps, mesh)
    arrays = [p.arrays()[0] for p in pieces]
    shapes = np.array([_outline(p) for p in pieces], dtype=object)  # placed: moved with nets
    n = len(pieces)
    net_of = np.arange(n)
    place = np.tile(np.eye(3), (n, 1, 1))
    border = []  # each piece's border points in its own frame, (k, 2) and (k, 3)
    for p, p2 in zip(pieces, arrays, strict=True):
        i = _border_points(p)
        border.append((p2[i], p.arrays()[1][i]))
    boxes = shapely.bounds(shapes)
    nets = {k: _Placed([k], shapes[k : k + 1], boxes[k : k + 1]) for k in range(n)}
    if sheet is not None:
        for k in range(n):
            nets[k].hull = _hull(shapely.get_coordinates(shapes[k]))
    heap = [
        (2, -len(matches), a, b)
        for (a, b), matches in shared.items()
        if a < b and len(matches) >= 2
    ]
    heapq.heapify(heap)
    while heap:
        size, longer, a, b = heapq.heappop(heap)
        na, nb = int(net_of[a]), int(net_of[b])
        if na == nb:
            continue
        target, source = nets[na], nets[nb]
        now = len(target.ids) + len(source.ids)
        if now != size:  # a net grew since: back in line at its size
            heapq.heappush(heap, (now, longer, a, b))
            continue
        if (len(target.ids), -na) < (len(source.ids), -nb):  # move the smaller net
            a, b, na, nb, target, source = b, a, nb, na, source, target
        matches = shared[(a, b)]
        src = _apply(place[b], arrays[b][[j for _, j in matches]])
        dst = _apply(place[a], arrays[a][[i for i, _ in matches]])
        m = rigid_fit(src, dst)
        # a border glues where its two copies are congruent to round-off of where they lie: a
        # border that is only nearly so (two sharp modules' developments apart by 3e-10 of
        # the edge, compas mesh.obj) would move the points of one module and stretch its
        # edges, folded against flat, past the certificate's contraction limit
        exact = _round_off(dst)
        if np.abs(_apply(m, src) - dst).max() > exact:
            continue
        moving = _Moving(source.ids, _moved(source.shapes, m), m, place, border)
        if target.clashes(moving, overlap_tol, 1e3 * eps, 16 * exact):
            continue
        hull = target.hull
        if sheet is not None:
            hull = _hull(np.vstack([target.hull, _apply(m, source.hull)]))
            if not fits_sheet(hull, sheet):
                continue
        place[source.ids] = m @ place[source.ids]
        target.add(source, moving.shapes, hull)
        net_of[source.ids] = na
        del nets[nb]
    members = [sorted(net.ids.tolist()) for net in nets.values()]
    groups = sorted(members, key=lambda v: (-len(v), v[0]))
    out = []
    for ids in groups:  # the glued points, merged at the round-off of where they lie
        placed = [_apply(place[i], border[i][0]) for i in ids if len(border[i][0])]
        reach = max((np.abs(q).max() for q in placed), default=0)
        exact = _round_off(np.array([reach]))
        out.append(merge_pieces([pieces[i] for i in ids], list(place[ids]), exact))
    return out, groups


def _round_off(points: np.ndarray) -> float:
    """64 units in the last place of the largest coordinate of ``points``: how far apart two
    computations of one point may lie there."""
    return 64 * float(np.spacing(np.abs(points).max())) if points.size else 0.0


def _apply(m: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points (k, 2) moved by the homogeneous rigid motion ``m``."""
    return points @ m[:2, :2].T + m[:2, 2]
