"""Vertex modules: the flat piece(s) of one vertex, in 2D and folded in 3D (paper sec. 2).

A vertex module is made of one *sector* per incident face ``f_i``: the half-cylinder of side
``i`` (from its midpoint base curve up to the crease), the vertex's share of face ``f_i`` (bounded
by the two tangent lines, the face piece's centre and, near the vertex, the straight crease), and
the cone fanned from the apex over the crease (curved on the cylinder, straight on the face).

A closed ring is cut along the transition line between face ``f_{n-1}`` and cylinder 0 (and the
cone ruling to its crease point): the development is then the chain ``tau -> ... -> tau'`` with
the angle-defect wedge open at the apex. Vertices without a cone (saddle, infeasible,
developable, boundary) end at a *hole border* instead: on each cylinder the cross-section at
``z = h`` (half of the shorter ``l_max``), joined by straight segments across the faces.

A module whose development overlaps itself (cone angle above 2 pi, or a saddle's ring) is split
into runs of consecutive sectors, each its own piece.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import shapely
from scipy.spatial import cKDTree

from .errors import MeshError
from .mesh.polymesh import PolyMesh
from .rounding import EdgeRounding
from .vertex.apex import crease_length
from .vertex.frame import VertexFrame, apply, to_chart


@dataclass
class Piece:
    """One flat piece: points in 2D (piece frame) and 3D, polygon faces, patch names.

    Attributes
    ----------
    vertex : int
        The mesh vertex of the module.
    points_2d : (k, 2) float
    points_3d : (k, 3) float
    faces : list of list of int
        Counter-clockwise in 2D.
    patches : list of str
    apex_index : int or None
        Index of the apex point (cone modules).
    """

    vertex: int
    points_2d: list = field(default_factory=list)
    points_3d: list = field(default_factory=list)
    faces: list = field(default_factory=list)
    patches: list = field(default_factory=list)
    apex_index: int | None = None
    _keys: dict = field(default_factory=dict)

    def point(self, key, p2, p3) -> int:
        """Index of the point with ``key``, adding it on first use."""
        if key not in self._keys:
            self._keys[key] = len(self.points_2d)
            self.points_2d.append(np.asarray(p2, dtype=float).reshape(2))
            self.points_3d.append(np.asarray(p3, dtype=float).reshape(3))
        return self._keys[key]

    def face(self, idx, patch: str, min_area: float = 0.0):
        """Add a polygon (duplicate consecutive indices dropped), made counter-clockwise.

        A polygon with fewer than 3 distinct corners or twice-area ``<= 2 min_area`` is dropped.
        """
        out = []
        for i in idx:
            if not out or out[-1] != i:
                out.append(i)
        if len(out) > 1 and out[0] == out[-1]:
            out.pop()
        if len(out) < 3:
            return
        area = 0.0
        for j in range(len(out)):
            x0, y0 = self.points_2d[out[j - 1]]
            x1, y1 = self.points_2d[out[j]]
            area += x0 * y1 - x1 * y0
        if abs(area) <= 2 * min_area:
            return
        if area < 0:
            out = out[::-1]
        self.faces.append(out)
        self.patches.append(patch)

    def merge_coincident(self, eps: float) -> None:
        """Merge points that coincide in 2D and 3D (within ``eps``); drop faces that vanish.

        This happens where a crease runs exactly through a tangent-line crossing T
        (``l = l_max``, METHOD-NOTES 11): the straight crease on the face has zero length.
        """
        p2, p3 = self.arrays()
        pairs = cKDTree(p2).query_pairs(eps, output_type="ndarray")
        if len(pairs) == 0:
            return
        pairs = pairs[np.linalg.norm(p3[pairs[:, 0]] - p3[pairs[:, 1]], axis=1) < eps]
        root = np.arange(len(p2))
        for a, b in sorted(map(tuple, pairs)):
            ra, rb = root[a], root[b]
            while root[ra] != ra:
                ra = root[ra]
            while root[rb] != rb:
                rb = root[rb]
            root[max(ra, rb)] = min(ra, rb)
        for i in range(len(root)):
            r = i
            while root[r] != r:
                r = root[r]
            root[i] = r
        faces, patches = self.faces, self.patches
        self.faces, self.patches = [], []
        for f, patch in zip(faces, patches, strict=True):
            self.face([int(root[i]) for i in f], patch, min_area=eps * eps)
        used = sorted({i for f in self.faces for i in f})
        new = {old: k for k, old in enumerate(used)}
        self.points_2d = [self.points_2d[i] for i in used]
        self.points_3d = [self.points_3d[i] for i in used]
        self.faces = [[new[i] for i in f] for f in self.faces]
        self._keys = {k: new[root[i]] for k, i in self._keys.items() if root[i] in new}
        if self.apex_index is not None:
            self.apex_index = new.get(int(root[self.apex_index]))

    def arrays(self):
        """(points_2d (k, 2), points_3d (k, 3))."""
        return np.array(self.points_2d).reshape(-1, 2), np.array(self.points_3d).reshape(-1, 3)

    def overlaps(self, rel: float = 1e-9) -> bool:
        """True when faces of the piece overlap in 2D (or one is not a valid polygon)."""
        p2, _ = self.arrays()
        polys = face_polygons(p2, self.faces)
        if not shapely.is_valid(polys).all():
            return True
        total = shapely.area(polys).sum()
        union = shapely.union_all(polys).area
        return union < total * (1 - rel)


def piece_area(piece: Piece) -> float:
    """Area of a flat piece (sum of its faces' areas)."""
    p2, _ = piece.arrays()
    return float(shapely.area(face_polygons(p2, piece.faces)).sum())


def face_polygons(points_2d: np.ndarray, faces) -> np.ndarray:
    """(n_faces,) shapely Polygons of faces given as index lists into ``points_2d`` (k, 2)."""
    sizes = np.array([len(f) for f in faces])
    idx = np.concatenate(faces)
    rings = shapely.linearrings(points_2d[idx], indices=np.repeat(np.arange(len(faces)), sizes))
    return shapely.polygons(rings)


def face_piece_centres(mesh: PolyMesh, rounding: EdgeRounding) -> np.ndarray:
    """Centre of every flat face piece, from which the whole piece is visible.

    The face piece of a face is bounded by the tangent lines of its edges (the edge itself for a
    boundary or flat edge); its corners are the crossing points T. Each vertex's share of the
    piece is cut off by straight segments from the edge midpoints to this centre, so the centre
    must see the whole piece: it is the centroid of the piece's kernel (the piece itself when
    convex).

    Returns
    -------
    centre : (n_faces, 3) float

    Raises
    ------
    MeshError
        If a face piece is not star-shaped (no point sees all of it).
    """
    half = 0.5 * rounding.strip_width
    out = np.empty((mesh.n_faces, 3))
    for fi, face in enumerate(mesh.faces):
        n = mesh.face_normal[fi]
        p = mesh.vertices[face]
        q = np.roll(p, -1, axis=0)
        u = q - p
        u /= np.linalg.norm(u, axis=1)[:, None]
        he = np.arange(mesh.face_start[fi], mesh.face_start[fi + 1])
        d = half[mesh.halfedge_edge[he]]
        base = p + d[:, None] * np.cross(n, u)  # a point of each edge's tangent line
        T = np.empty_like(p)
        for j in range(len(face)):  # corner j: lines of edge j-1 and edge j
            a = np.stack([u[j - 1], -u[j]], axis=1)
            z, *_ = np.linalg.lstsq(a, base[j] - base[j - 1], rcond=None)
            T[j] = base[j - 1] + z[0] * u[j - 1]
        e1 = u[0]
        e2 = np.cross(n, e1)
        xy = np.stack([(T - p[0]) @ e1, (T - p[0]) @ e2], axis=1)
        centre = _kernel_centroid(xy)
        if centre is None:
            raise MeshError(
                f"face {fi} is not star-shaped after rounding: no point of it sees the whole "
                "face piece; split it into convex polygons or use a smaller radius",
                face=fi,
            )
        out[fi] = p[0] + centre[0] * e1 + centre[1] * e2
    return out


def _kernel_centroid(xy: np.ndarray) -> np.ndarray | None:
    """Centroid of the kernel of a counter-clockwise polygon (k, 2), or None if it is empty."""
    poly = shapely.Polygon(xy)
    if poly.is_valid and poly.exterior.is_ccw and _is_convex(xy):
        c = poly.centroid
        return np.array([c.x, c.y])
    size = float(np.ptp(xy, axis=0).max()) * 4 + 1.0
    kernel = poly if poly.is_valid else shapely.convex_hull(poly)
    for a, b in zip(xy, np.roll(xy, -1, axis=0), strict=True):
        t = b - a
        nrm = np.array([-t[1], t[0]]) / np.linalg.norm(t) * size  # left of a -> b is inside
        t = t / np.linalg.norm(t) * size
        half = shapely.Polygon([a - t, b + t, b + t + nrm, a - t + nrm])
        kernel = kernel.intersection(half)
    if kernel.is_empty or kernel.area <= 1e-12 * poly.area:
        return None
    c = kernel.centroid
    return np.array([c.x, c.y])


def _is_convex(xy: np.ndarray) -> bool:
    d = np.roll(xy, -1, axis=0) - xy
    cross = d[:, 0] * np.roll(d[:, 1], -1) - d[:, 1] * np.roll(d[:, 0], -1)
    return bool(np.all(cross >= 0))


def hole_heights(frame: VertexFrame) -> np.ndarray:
    """(n_sides,) height of the hole border above the midpoint cross-section on each side."""
    lm = np.fmin(frame.lmax_start, frame.lmax_end)
    return 0.5 * lm


def build_module(
    mesh: PolyMesh,
    frame: VertexFrame,
    centres: np.ndarray,
    n_samples: int,
    apex: np.ndarray | None = None,
    dev_apex: np.ndarray | None = None,
    runs=None,
) -> list[Piece]:
    """The flat piece(s) of one vertex.

    Parameters
    ----------
    mesh : PolyMesh
    frame : VertexFrame
    centres : (n_faces, 3) float
        Face piece centres (:func:`face_piece_centres`).
    n_samples : int
        Points per cylinder arc (both ends included).
    apex : (3,) float, optional
        Spatial apex; when given the module has a cone, otherwise a hole border.
    dev_apex : (2,) float, optional
        Developed apex (required with ``apex``).
    runs : list of (int, int), optional
        Sector ranges ``[j0, j1]`` (inclusive), each one piece; default one run over all
        sectors, split in halves while a piece overlaps itself.

    Returns
    -------
    list of Piece
    """
    nf = len(frame.ring.faces)
    if runs is not None:
        return [
            _build_run(mesh, frame, centres, n_samples, apex, dev_apex, j0, j1) for j0, j1 in runs
        ]
    pending = [(0, nf - 1)]
    pieces = []
    while pending:
        j0, j1 = pending.pop(0)
        piece = _build_run(mesh, frame, centres, n_samples, apex, dev_apex, j0, j1)
        if j1 > j0 and piece.overlaps():
            mid = (j0 + j1) // 2
            pending[:0] = [(j0, mid), (mid + 1, j1)]
            continue
        pieces.append(piece)
    return pieces


def _side_curves(frame: VertexFrame, i: int, n_samples: int, apex, dev_apex, heights):
    """Base points and crease (or hole) points of rounded side ``i``.

    Returns (s, base_3d (k, 3), top_3d (k, 3), top_z (k,)) with ``top`` the crease or the
    hole border.
    """
    side = frame.sides[i]
    s = np.linspace(0.0, side.arc, n_samples if side.arc > 0 else 1)
    C = side.base(s)
    if apex is not None:
        z, _ = crease_length(frame, i, apex, dev_apex, s)
    else:
        z = np.full(len(s), heights[i])
    return s, C, C + z[:, None] * side.R, z


def _build_run(mesh, frame: VertexFrame, centres, n_samples, apex, dev_apex, j0, j1) -> Piece:
    u = frame.vertex
    ring = frame.ring
    ne = len(frame.sides)
    heights = hole_heights(frame)
    piece = Piece(vertex=u)
    top_name = "cr" if apex is not None else "hole"
    if apex is not None:
        piece.apex_index = piece.point(("apex",), dev_apex, apex)
    curves = {}

    def curves_of(i):
        if i not in curves:
            curves[i] = _side_curves(frame, i, n_samples, apex, dev_apex, heights)
        return curves[i]

    def line_points(i, face_i, start: bool, end_copy: bool = False):
        """(base, top) point indices of side ``i`` where it meets ring face ``face_i``.

        ``end_copy`` asks for the start of side ``i`` as reached from face ``face_i`` at the end
        of the run (across the cut: same 3D points, the 2D chart after ``face_i``).
        """
        side = frame.sides[i]
        if side.rounded:
            s, C, F, z = curves_of(i)
            k = 0 if start else len(s) - 1
            if end_copy:
                m = frame.face_map[face_i] @ frame.gluing_start(i)
                key = ("end", i)
            else:
                m = frame.cyl_map[i]
                key = ("side", i)
            b = piece.point((*key, "bs", k), apply(m, [s[k], 0.0]), C[k])
            t = piece.point((*key, top_name, k), apply(m, [s[k], z[k]]), F[k])
            return b, t
        # unrounded boundary side: points on the edge line, in the chart of face_i
        h = 0.5 * (frame.lmax_start[i] if start else frame.lmax_end[i])
        m3 = side.M
        t3 = side.M + h * side.R
        fr = frame.face_frames[face_i]
        mp = frame.face_map[face_i]
        tag = "start" if start else "end"
        b = piece.point(("line", i, tag, "bs"), apply(mp, to_chart(fr, m3)), m3)
        t = piece.point(("line", i, tag, "top"), apply(mp, to_chart(fr, t3)), t3)
        return b, t

    for i in range(j0, j1 + 1):
        side = frame.sides[i]
        # the half-cylinder of side i and the cone over its crease
        if side.rounded:
            s, C, F, z = curves_of(i)
            m = frame.cyl_map[i]
            bs = [
                piece.point(("side", i, "bs", k), apply(m, [s[k], 0.0]), C[k])
                for k in range(len(s))
            ]
            tp = [
                piece.point(("side", i, top_name, k), apply(m, [s[k], z[k]]), F[k])
                for k in range(len(s))
            ]
            patch = f"cylinder {side.edge}"
            for k in range(len(s) - 1):
                piece.face([bs[k], bs[k + 1], tp[k + 1], tp[k]], patch)
                if apex is not None:
                    piece.face([piece.apex_index, tp[k], tp[k + 1]], f"cone {u}")
        # the share of face f_i, between side i (end) and side i + 1 (start)
        face = int(ring.faces[i])
        b0, t0 = line_points(i, i, start=False)
        nxt = (i + 1) % ne
        b1, t1 = line_points(nxt, i, start=True, end_copy=(i == j1))
        fr = frame.face_frames[i]
        c = piece.point(
            ("centre", face), apply(frame.face_map[i], to_chart(fr, centres[face])), centres[face]
        )
        corner = [t0, b0, c, b1, t1]
        if apex is None and frame.corner_angle[i] > np.pi:
            # at a reflex corner the straight hole border would leave the face: go through T
            T3 = frame.T_end[i]
            corner.append(piece.point(("T", i), apply(frame.face_map[i], to_chart(fr, T3)), T3))
        piece.face(corner, f"face {face}")
        if apex is not None:
            piece.face([piece.apex_index, t0, t1], f"cone {u}")
    piece.merge_coincident(1e-9 * min(s.length for s in frame.sides))
    return piece
