"""Nets: vertex modules joined into few flat pieces (issue 4's fabrication layout).

Neighbouring modules share a border (the midpoint base curve of their common edge and the
face-piece dividers beside it). A net grows breadth first from a seed module: a neighbour is
glued on by the rigid motion that matches its copy of the shared border points to the copy
already placed, if it then overlaps nothing already in the net and the net still fits the
sheet. Modules that cannot join start new nets. Each cone keeps its angle-defect cut, since
the border a module shares with one neighbour never includes its own cut; choosing each
module's cut by :func:`cut_edges_for_nets` lets every other border be glued.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.spatial import cKDTree

from ..surface.faces import FaceLists, face_polygons, flat_faces
from ..surface.piece import Piece
from ..tolerances import tol


def rigid_fit(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """3x3 homogeneous rotation + translation taking points ``src`` (k, 2) onto ``dst``."""
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    h = (src - cs).T @ (dst - cd)
    u, _, vt = np.linalg.svd(h)
    r = (u @ vt).T
    if np.linalg.det(r) < 0:  # a reflection cannot glue orientation-preserving pieces
        vt[-1] *= -1
        r = (u @ vt).T
    m = np.eye(3)
    m[:2, :2] = r
    m[:2, 2] = cd - r @ cs
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


def _outline(piece: Piece, m: np.ndarray):
    p2, _ = piece.arrays()
    polys = face_polygons(p2 @ m[:2, :2].T + m[:2, 2], piece.faces)
    return shapely.union_all(shapely.make_valid(polys)).buffer(0)


def _fits(shape, sheet) -> bool:
    if sheet is None:
        return True
    rect = shapely.minimum_rotated_rectangle(shape)
    xy = np.asarray(rect.exterior.coords)[:4]
    sides = sorted([np.linalg.norm(xy[1] - xy[0]), np.linalg.norm(xy[2] - xy[1])])
    return sides[0] <= min(sheet) and sides[1] <= max(sheet)


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

    Parameters
    ----------
    pieces : list of Piece
        Vertex modules (each a valid flat piece).
    eps : float
        Distance under which two points are one.
    sheet : (float, float), optional
        Width and height a net must fit in (pattern units, any rotation).
    overlap_tol : float
        Overlap area allowed between a new module and the net, relative to the module's area.

    Returns
    -------
    nets : list of Piece
        One piece per net (``vertex = -1``), in the order they were grown.
    members : list of list of int
        The input pieces in each net.
    """
    shared = shared_points(pieces, eps)
    arrays = [p.arrays() for p in pieces]
    neighbours: dict[int, list[tuple[int, int]]] = {}
    for (a, b), matches in shared.items():
        if len(matches) >= 2:
            neighbours.setdefault(a, []).append((len(matches), b))
    for a in neighbours:
        neighbours[a].sort(key=lambda t: (-t[0], t[1]))
    # seeds: the modules with the most neighbours first (central ones grow the best nets)
    order = sorted(range(len(pieces)), key=lambda k: (-len(neighbours.get(k, [])), k))
    free = set(range(len(pieces)))
    nets, members = [], []
    for seed in order:
        if seed not in free:
            continue
        free.discard(seed)
        placed = {seed: np.eye(3)}
        shape = _outline(pieces[seed], placed[seed])
        queue = [seed]
        while queue:
            k = queue.pop(0)
            for _, n in neighbours.get(k, []):
                if n not in free:
                    continue
                matches = shared[(k, n)]
                src = arrays[n][0][[j for _, j in matches]]
                dst = arrays[k][0][[i for i, _ in matches]] @ placed[k][:2, :2].T
                dst = dst + placed[k][:2, 2]
                m = rigid_fit(src, dst)
                if np.abs(src @ m[:2, :2].T + m[:2, 2] - dst).max() > eps * 1e3:
                    continue
                out = _outline(pieces[n], m)
                if shape.intersection(out).area > overlap_tol * out.area:
                    continue
                grown = shapely.union(shape, out)
                if not _fits(grown, sheet):
                    continue
                placed[n], shape = m, grown
                free.discard(n)
                queue.append(n)
        ids = sorted(placed)
        nets.append(merge_pieces([pieces[i] for i in ids], [placed[i] for i in ids], eps))
        members.append(ids)
    return nets, members
