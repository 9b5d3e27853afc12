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


def shared_points(pieces: list[Piece], eps: float) -> dict[tuple[int, int], list]:
    """Points of one piece that are points of another in 3D (their common border).

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
    shared: dict[tuple[int, int], list] = {}
    for a, b in pairs:
        ka, kb = int(owner[a]), int(owner[b])
        shared.setdefault((ka, kb), []).append((int(local[a]), int(local[b])))
        shared.setdefault((kb, ka), []).append((int(local[b]), int(local[a])))
    return shared


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
    """The outlines of the pieces placed in one net, in a uniform grid of their bounding
    boxes: a piece that would join is tested against the placed ones whose boxes meet its own
    only, so growing a net of ``n`` modules costs about ``n`` small intersections, not ``n``
    unions of the whole net."""

    def __init__(self, cell: float):
        self.cell = cell
        self.shapes: list = []
        self.corners: list[tuple] = []
        self.boxes: list = []
        self.grid: dict[tuple[int, int], list[int]] = {}
        self.hull = np.zeros((0, 2))

    def _cells(self, box):
        lo = np.floor(np.asarray(box[:2]) / self.cell).astype(np.int64)
        hi = np.floor(np.asarray(box[2:]) / self.cell).astype(np.int64)
        return [(i, j) for i in range(lo[0], hi[0] + 1) for j in range(lo[1], hi[1] + 1)]

    def clashes(self, shapes, corners: list, overlap_tol: float, eps: float, thin: float) -> bool:
        """Whether any of ``shapes`` (the outlines of the pieces of a net that would join,
        placed) overlaps the placed outlines by more than ``overlap_tol`` of its area (summed
        over them: they overlap one another by no more than that), or its piece touches a
        placed piece at a point that is two points of the surface (a pinch: a cutter cuts it
        apart, Origami Simulator welds it). ``corners`` are each piece's border points,
        placed, (k, 2) and (k, 3); points within ``eps`` are one. Any overlap wider than
        ``thin`` (twice its area over its perimeter, for each part of it) clashes too. The
        pairs of a new and a placed outline whose boxes meet are tested all at once."""
        boxes = shapely.bounds(shapes)
        new, old = [], []
        for i, box in enumerate(boxes):
            near = np.fromiter(
                {k for c in self._cells(box) for k in self.grid.get(c, ())}, dtype=np.int64
            )
            b = np.array([self.boxes[k] for k in near.tolist()]).reshape(-1, 4)
            near = near[
                (b[:, 0] <= box[2] + eps) & (box[0] <= b[:, 2] + eps)
                & (b[:, 1] <= box[3] + eps) & (box[1] <= b[:, 3] + eps)
            ]  # fmt: skip
            new.append(np.full(len(near), i))
            old.append(near)
        new, old = np.concatenate(new), np.concatenate(old)
        if not len(new):
            return False
        mine = shapes[new]
        theirs = np.empty(len(old), dtype=object)
        theirs[:] = [self.shapes[k] for k in old.tolist()]
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
        close = shapely.dwithin(theirs, mine, eps)
        for i, k in zip(new[close].tolist(), old[close].tolist(), strict=True):
            (p2, p3), (q2, q3) = corners[i], self.corners[k]
            flat = np.linalg.norm(p2[:, None] - q2[None], axis=-1) <= eps
            if (np.linalg.norm(p3[:, None] - q3[None], axis=-1)[flat] > eps).any():
                return True
        return False

    def add(self, shape, corners: tuple, hull: np.ndarray) -> None:
        box = shapely.bounds(shape)
        k = len(self.shapes)
        self.shapes.append(shape)
        self.corners.append(corners)
        self.boxes.append(box)
        for c in self._cells(box):
            self.grid.setdefault(c, []).append(k)
        self.hull = hull


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

    Returns
    -------
    nets : list of Piece
        One piece per net (``vertex = -1``), the most pieces first (ties: by first piece).
    members : list of list of int
        The input pieces in each net, ascending.
    """
    shared = shared_points(pieces, eps)
    arrays = [p.arrays()[0] for p in pieces]
    shapes = np.array([_outline(p) for p in pieces], dtype=object)  # placed: moved with nets
    spans = [np.ptp(a, axis=0).max() for a in arrays if len(a)]
    cell = float(np.median(spans)) if spans else 1.0
    n = len(pieces)
    net_of = np.arange(n)
    members = {k: [k] for k in range(n)}
    place = np.tile(np.eye(3), (n, 1, 1))
    nets = {}
    border = [_border_points(p) for p in pieces]
    corners = [(p2[i], p.arrays()[1][i]) for p, p2, i in zip(pieces, arrays, border, strict=True)]
    for k in range(n):
        nets[k] = _Placed(cell)
        nets[k].add(shapes[k], corners[k], _hull(shapely.get_coordinates(shapes[k])))
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
        now = len(members[na]) + len(members[nb])
        if now != size:  # a net grew since: back in line at its size
            heapq.heappush(heap, (now, longer, a, b))
            continue
        if (len(members[na]), -na) < (len(members[nb]), -nb):  # move the smaller net
            a, b, na, nb = b, a, nb, na
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
        moving = members[nb]
        moved = _moved(shapes[moving], m)
        target = nets[na]
        placed = [(_apply(m, corners[k][0]), corners[k][1]) for k in moving]
        if target.clashes(moved, placed, overlap_tol, 1e3 * eps, 16 * exact):
            continue
        hull = _hull(np.vstack([target.hull, _apply(m, nets[nb].hull)]))
        if sheet is not None and not fits_sheet(hull, sheet):
            continue
        place[moving] = m @ place[moving]
        shapes[moving] = moved
        for k, s, c in zip(moving, moved, placed, strict=True):
            corners[k] = c
            target.add(s, c, hull)
        net_of[moving] = na
        members[na].extend(members.pop(nb))
        del nets[nb]
    groups = sorted((sorted(v) for v in members.values()), key=lambda v: (-len(v), v[0]))
    out = []
    for ids in groups:  # the glued points, merged at the round-off of where they lie
        reach = max((np.abs(corners[i][0]).max() for i in ids if len(corners[i][0])), default=0)
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
