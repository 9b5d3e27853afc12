"""The crease pattern: flat pieces with their folded positions, creases and patches.

A :class:`CreasePattern` is what every export reads. Each pattern vertex has a 2D position (in
the flat layout) and a 3D position (in the folded form); faces are polygons counter-clockwise in
2D, and the same polygons are front-facing in 3D.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..arrays import run_owners, run_starts, split_runs
from ..mesh.measures import dihedral_turns
from ..tolerances import tol
from .patch import patch_ids, patch_indices, patch_kinds

#: Faces whose folded normals are computed together (bounds the temporaries).
NORMAL_CHUNK = 16_384


class Rows(Sequence):
    """A sequence whose items are made from arrays when asked for (:class:`FaceRows`,
    :class:`PointRows`, :class:`LabelRows`, :class:`~filletfold.layout.tabs.Seams`): an int
    (negative from the end) gives :meth:`_row` of it, a slice a list, an index out of range an
    IndexError naming :attr:`_what` ("face 7 out of range (5 faces)")."""

    __slots__ = ()
    #: What a row is called in the IndexError.
    _what = "row"

    def _row(self, i: int):
        """Row ``i`` (``0 <= i < len(self)``)."""
        raise NotImplementedError

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self._row(k) for k in range(*i.indices(len(self)))]
        n = len(self)
        if not -n <= i < n:
            raise IndexError(f"{self._what} {i} out of range ({n} {self._what}s)")
        return self._row(int(i) % n)


class FlatFaces(Sequence):
    """Polygons held as one flat index array and their offsets: no object per face until one
    is asked for. The base of :class:`FaceRows` (faces read as (k,) int64 arrays) and
    :class:`~filletfold.surface.faces.FaceLists` (faces read as lists of int); :func:`face_arrays`
    hands their arrays out as they are.

    Parameters
    ----------
    flat : (h,) int
        The faces' vertex indices, one face after the other.
    start : (n_faces + 1,) int
        Face ``i`` is ``flat[start[i]:start[i + 1]]``.
    """

    __slots__ = ("flat", "start")

    def __init__(self, flat: np.ndarray, start: np.ndarray):
        self.flat = np.asarray(flat, dtype=np.int64)
        self.start = np.asarray(start, dtype=np.int64)

    @classmethod
    def of_sizes(cls, flat: np.ndarray, size: np.ndarray):
        """The faces of ``size`` (n_faces,) corners each, their corners ``flat``."""
        return cls(flat, run_starts(size))

    def __len__(self) -> int:
        return len(self.start) - 1


class FaceRows(Rows, FlatFaces):
    """:class:`FlatFaces` read as (k,) int64 arrays (views of ``flat``): what
    :func:`~filletfold.surface.assemble.assemble_pattern` gives a pattern."""

    __slots__ = ()
    _what = "face"

    def _row(self, i: int):
        return self.flat[self.start[i] : self.start[i + 1]]

    def __iter__(self):
        return iter(split_runs(self.flat, self.start[1:-1]) if len(self) else [])


class PointRows(Rows):
    """Point lists (glue-tab outlines, tab hinges) held as one (k, 2) array and offsets: no
    object per row until one is asked for (a design of modules has one tab per cut border,
    tens of thousands: as a list of arrays they cost ten times their numbers).

    Parameters
    ----------
    points : (k, 2) float
        Every row's points, one row after the other.
    start : (n_rows + 1,) int
        Row ``i`` is ``points[start[i]:start[i + 1]]`` (a view).
    """

    __slots__ = ("points", "start")

    def __init__(self, points: np.ndarray, start: np.ndarray):
        self.points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        self.start = np.asarray(start, dtype=np.int64)

    @classmethod
    def of_blocks(cls, blocks: np.ndarray):
        """The rows of a (n, k, 2) array, ``k`` points each."""
        blocks = np.asarray(blocks, dtype=np.float64)
        n, k = blocks.shape[:2]
        return cls(blocks.reshape(-1, 2), np.arange(n + 1, dtype=np.int64) * k)

    def __len__(self) -> int:
        return len(self.start) - 1

    def _row(self, i: int):
        return self.points[self.start[i] : self.start[i + 1]]

    def __iter__(self):
        return iter(split_runs(self.points, self.start[1:-1]) if len(self) else [])


class LabelRows(Rows):
    """Labels held as parallel arrays (positions, angles, heights) and lists (texts, kinds):
    a :class:`Label` is made when one is asked for.

    Parameters
    ----------
    position : (n, 2) float
    text, kind : sequence of str
    angle, height : (n,) float
    """

    __slots__ = ("angle", "height", "kind", "position", "text")
    _what = "label"

    def __init__(self, position, text, angle, height, kind):
        self.position = np.asarray(position, dtype=np.float64).reshape(-1, 2)
        n = len(self.position)
        self.text = list(text)
        self.angle = np.broadcast_to(np.asarray(angle, dtype=np.float64), (n,)).copy()
        self.height = np.broadcast_to(np.asarray(height, dtype=np.float64), (n,)).copy()
        self.kind = list(kind) if not isinstance(kind, str) else [kind] * n
        if len(self.text) != n or len(self.kind) != n:
            raise ValueError(
                f"labels: {n} positions, {len(self.text)} texts, {len(self.kind)} kinds"
            )

    @classmethod
    def of(cls, labels) -> LabelRows:
        """The rows of a sequence of :class:`Label` (or a :class:`LabelRows`, as it is)."""
        if isinstance(labels, LabelRows):
            return labels
        labels = list(labels)
        return cls(
            np.array(
                [np.asarray(lb.position, dtype=np.float64).reshape(2) for lb in labels]
            ).reshape(-1, 2),
            [lb.text for lb in labels],
            [float(lb.angle) for lb in labels],
            [float(lb.height) for lb in labels],
            [lb.kind for lb in labels],
        )

    def __add__(self, other) -> LabelRows:
        other = LabelRows.of(other)
        return LabelRows(
            np.concatenate([self.position, other.position]),
            self.text + other.text,
            np.concatenate([self.angle, other.angle]),
            np.concatenate([self.height, other.height]),
            self.kind + other.kind,
        )

    def __len__(self) -> int:
        return len(self.position)

    def _row(self, i: int):
        return Label(
            self.position[i].copy(),
            self.text[i],
            float(self.angle[i]),
            float(self.height[i]),
            self.kind[i],
        )

    def __iter__(self):
        return map(self._row, range(len(self)))


def face_arrays(faces) -> tuple[np.ndarray, np.ndarray]:
    """Faces as one flat index array and their offsets.

    Parameters
    ----------
    faces : FlatFaces, or list of (k,) int

    Returns
    -------
    flat : (h,) int
        The faces' vertex indices, one face after the other.
    start : (n_faces + 1,) int
        Face ``i`` is ``flat[start[i]:start[i + 1]]``.
    """
    if isinstance(faces, FlatFaces):
        return faces.flat, faces.start
    sizes = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
    start = np.zeros(len(faces) + 1, dtype=np.int64)
    np.cumsum(sizes, out=start[1:])
    if len(faces) == 0:
        return np.zeros(0, dtype=np.int64), start
    flat = np.concatenate(faces)
    if np.issubdtype(flat.dtype, np.integer):
        flat = flat.astype(np.int64, copy=False)
    return flat, start


def edge_faces_of(edges: np.ndarray, faces, n_vertices: int) -> np.ndarray:
    """(m, 2) int: the face on each edge's ``a -> b`` side, then the one on its ``b -> a``
    side (-1 where there is none): the faces beside given edges, as
    :attr:`CreasePattern.edge_faces` holds them (a pattern read from a file is given its own so).

    Parameters
    ----------
    edges : (m, 2) int
    faces : FlatFaces, or list of (k,) int
    n_vertices : int
    """
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    ef = -np.ones((len(edges), 2), dtype=np.int64)
    if not len(faces) or not len(edges):
        return ef
    a, start = face_arrays(faces)
    nxt = np.arange(len(a)) + 1
    nxt[start[1:] - 1] = start[:-1]
    b = a[nxt]
    face_of = run_owners(np.diff(start))
    n = n_vertices
    lo, hi = np.minimum(edges[:, 0], edges[:, 1]), np.maximum(edges[:, 0], edges[:, 1])
    keys = lo * n + hi
    order = np.argsort(keys)
    hkey = np.minimum(a, b) * n + np.maximum(a, b)
    pos = np.clip(np.searchsorted(keys[order], hkey), 0, len(keys) - 1)
    found = keys[order][pos] == hkey
    e = order[pos[found]]
    side = (a[found] != edges[e, 0]).astype(np.int64)
    ef[e, side] = face_of[found]
    return ef


def edge_dihedrals(pattern: CreasePattern) -> np.ndarray:
    """(m,) the folded form's dihedral at every pattern edge, in FOLD's sign (valley positive).

    The angle between the 3D normals of the edge's two faces, signed as
    :class:`~filletfold.surface.pattern.CreasePattern` signs its creases; NaN on an edge with
    fewer than two faces. On M and V edges it is ``pattern.edge_fold_angle``; on F edges it is
    the small bend of a sampled cylinder or cone between two of its facets (the pattern itself
    keeps 0 there).

    Parameters
    ----------
    pattern : CreasePattern

    Returns
    -------
    (m,) float
    """
    edges = np.asarray(pattern.edges, dtype=np.int64).reshape(-1, 2)
    ef = pattern.faces_beside_edges()
    out = np.full(len(edges), np.nan)
    inner = (ef >= 0).all(axis=1)
    if not inner.any():
        return out
    normals = pattern.face_normal_3d()
    # an edge lo -> hi is traversed forward by its first face, as CreasePattern orders them
    na, nb = normals[ef[inner, 0]], normals[ef[inner, 1]]
    d = pattern.vertices_3d[edges[inner, 1]] - pattern.vertices_3d[edges[inner, 0]]
    out[inner] = -dihedral_turns(na, nb, d)
    return out


@dataclass
class Label:
    """A text placed on the flat layout (part numbers, glue-tab matches, fold angles).

    Attributes
    ----------
    position : (2,) float
        Anchor (centre of the text) in pattern coordinates.
    text : str
    angle : float
        Direction of the text baseline, degrees counter-clockwise from +x.
    height : float
        Text height in pattern length units.
    kind : str
        ``"part"``, ``"tab"`` (the matching label of a glue seam) or ``"angle"``.
    """

    position: np.ndarray
    text: str
    angle: float = 0.0
    height: float = 0.05
    kind: str = "part"


@dataclass
class Annotations:
    """What a cut file shows besides the pattern's own edges.

    Attributes
    ----------
    tabs : list of (k, 2) float, or PointRows
        Glue-tab outlines (closed polygons, counter-clockwise) in pattern coordinates; each is
        cut along its outline except the side it shares with its piece, which is folded.
    tab_hinges : list of (2, 2) float, or PointRows
        For each tab, the segment it shares with its piece (folded, not cut).
    labels : list of Label, or LabelRows
    sheets : (n_sheets, 4) float
        ``(xmin, ymin, xmax, ymax)`` of each sheet of material, in pattern coordinates (empty
        when the pieces were not placed on sheets).
    seams : Seams or None
        The numbered cut borders the labels name: the two pieces each joins and which one
        carries its tab (:class:`~filletfold.layout.tabs.Seams`; None without glue tabs).
    making : list of MakingPath
        How a sheet material's bends are made: reliefs and kerf grooves
        (:mod:`~filletfold.layout.making`; none without a material, or for one that is scored).
    """

    tabs: list = field(default_factory=list)
    tab_hinges: list = field(default_factory=list)
    labels: list = field(default_factory=list)
    sheets: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    seams: object = None
    making: list = field(default_factory=list)


@dataclass
class CreasePattern:
    """Flat pieces, folded positions, and crease data.

    Attributes
    ----------
    vertices_2d : (n, 2) float
        Positions in the flat layout (same length unit as the mesh).
    vertices_3d : (n, 3) float
        Positions in the folded form.
    faces : list of (k,) int, or FaceRows
        Polygons, counter-clockwise in 2D.
    face_patch : list of str
        The surface patch of each face by its name (:class:`~filletfold.surface.patch.Patch`):
        ``"cone <vertex>"``, ``"cylinder <edge>"``, ``"fillet <edge>"`` or ``"face <face>"``
        (indices into the cleaned mesh and its edge list).
    face_piece : (n_faces,) int
        The flat piece (vertex module) each face belongs to.
    piece_vertex : (n_pieces,) int
        The mesh vertex whose module each piece is.
    edges : (m, 2) int
        Pattern edges, ``a < b``, sorted.
    edge_assignment : (m,) str
        ``"M"``, ``"V"``, ``"B"`` (piece border or cut) or ``"F"`` (inside a smooth patch, or the
        tangent-continuous join between a cylinder and a face).
    edge_fold_angle : (m,) float
        Fold angle in degrees, FOLD's sign convention: valley positive, mountain negative, 0 for
        B and F.
    edge_faces : (m, 2) int
        The one or two faces beside each edge (-1 where there is none).
    annotations : Annotations
        Glue tabs, labels and sheet outlines for the cut files (empty by default).
    """

    vertices_2d: np.ndarray
    vertices_3d: np.ndarray
    faces: list
    face_patch: list
    face_piece: np.ndarray
    piece_vertex: np.ndarray
    edges: np.ndarray = field(default=None)
    edge_assignment: np.ndarray = field(default=None)
    edge_fold_angle: np.ndarray = field(default=None)
    edge_faces: np.ndarray = field(default=None)
    annotations: Annotations = field(default_factory=Annotations)

    def __post_init__(self):
        self.vertices_2d = np.asarray(self.vertices_2d, dtype=np.float64).reshape(-1, 2)
        self.vertices_3d = np.asarray(self.vertices_3d, dtype=np.float64).reshape(-1, 3)
        self.face_piece = np.asarray(self.face_piece, dtype=np.int64)
        self.piece_vertex = np.asarray(self.piece_vertex, dtype=np.int64)
        if self.edges is None:
            self._derive_edges()

    @property
    def n_pieces(self) -> int:
        return len(self.piece_vertex)

    def cut_mask(self, decimals: int = 9) -> np.ndarray:
        """(m,) bool: border edges that are cuts, i.e. seams: their folded segment is the
        folded segment of another border edge too (the two sides of one cut).

        Border edges that are not cuts lie on the outline of the sheet.
        """
        b = np.nonzero(self.edge_assignment == "B")[0]
        ends = np.round(self.vertices_3d[self.edges[b]], decimals) + 0.0  # (k, 2, 3), no -0.0
        mask = np.zeros(len(self.edges), dtype=bool)
        if len(b) == 0:
            return mask
        if not np.isfinite(ends).all():  # NaN is equal to nothing: compare as values
            ends = np.sort(ends.view([("", ends.dtype)] * 3).reshape(len(b), 2), axis=1)
            _, inv, counts = np.unique(ends, axis=0, return_inverse=True, return_counts=True)
            mask[b] = counts[inv.ravel()] > 1
            return mask
        # number the rounded points (equal values, equal bytes), then the unordered pairs
        points = np.ascontiguousarray(ends.reshape(-1, 3)).view(np.dtype((np.void, 24)))
        _, point = np.unique(points.ravel(), return_inverse=True)
        point = point.reshape(-1, 2)
        key = point.min(axis=1) * (int(point.max()) + 1) + point.max(axis=1)
        _, inv, counts = np.unique(key, return_inverse=True, return_counts=True)
        mask[b] = counts[inv] > 1
        return mask

    def face_normal_3d(self) -> np.ndarray:
        """(n_faces, 3) float: unit front normals of the folded faces (Newell's method)."""
        return self._face_normal_3d(*self._halfedges())

    def _face_normal_3d(self, a, b, start, nxt) -> np.ndarray:
        """:meth:`face_normal_3d` from :meth:`_halfedges`, ``NORMAL_CHUNK`` faces at a time
        (the corners' temporaries of a large pattern would take hundreds of MB at once)."""
        n_faces = len(start) - 1
        n = np.empty((n_faces, 3))
        for lo in range(0, n_faces, NORMAL_CHUNK):
            hi = min(lo + NORMAL_CHUNK, n_faces)
            h0, h1 = start[lo], start[hi]
            p = self.vertices_3d[a[h0:h1]]
            first = start[lo:hi] - h0
            size = np.diff(start[lo : hi + 1])
            q = p - np.repeat(np.add.reduceat(p, first) / size[:, None], size, axis=0)
            q_next = q[nxt[h0:h1] - h0]  # the next corner of the same face
            n[lo:hi] = np.add.reduceat(np.cross(q, q_next), first, axis=0)
        return n / np.linalg.norm(n, axis=1)[:, None]

    def crease_sharp_rulings(
        self, vertex_apex, mesh_vertices, mesh_edges, unrounded, eps: float
    ) -> int:
        """Make every ``F`` edge inside one cone that is the ruling from its apex to a mesh
        edge left unrounded a crease (M or V, with its fold angle), in place; returns how many.

        A cone whose vertex has an edge left sharp is not smooth along the ruling that ends on
        that edge: the cone's triangles on its two sides meet there at the edge's dihedral, a
        crease the sheet must be scored for. A ruling that folds by no more than
        ``tol.coplanar_deg`` stays ``F``.

        Parameters
        ----------
        vertex_apex : (n_vertices, 3) float
            The cone apex of every mesh vertex (NaN without one).
        mesh_vertices : (n_vertices, 3) float
        mesh_edges : (n_edges, 2) int
        unrounded : (n_edges,) bool
            The mesh edges without a cylinder or fillet.
        eps : float
            Distance within which a point is the apex, or on an edge.
        """
        ef = self.edge_faces
        patch = patch_ids(self.face_patch)
        kind = patch_kinds(self.face_patch)
        cand = np.flatnonzero((self.edge_assignment == "F") & (ef >= 0).all(axis=1))
        fa, fb = ef[cand, 0], ef[cand, 1]
        keep = (patch[fa] == patch[fb]) & (kind[fa] == "cone")
        cand, fa, fb = cand[keep], fa[keep], fb[keep]
        sharp = np.flatnonzero(np.asarray(unrounded, dtype=bool))
        if not len(cand) or not len(sharp):
            return 0
        u = patch_indices(self.face_patch)[fa]
        apex = np.asarray(vertex_apex, dtype=float)[u]
        a, b = self.vertices_3d[self.edges[cand, 0]], self.vertices_3d[self.edges[cand, 1]]
        at_a = np.linalg.norm(a - apex, axis=1) <= eps
        at_b = np.linalg.norm(b - apex, axis=1) <= eps
        far = np.where(at_a[:, None], b, a)
        ruling = at_a ^ at_b
        order = np.argsort(u, kind="stable")
        u_sorted = u[order]  # once: sorting per edge made this quadratic on large meshes
        mv = np.asarray(mesh_vertices, dtype=float)
        on = np.zeros(len(cand), dtype=bool)
        for e in sharp.tolist():
            p, q = mv[mesh_edges[e, 0]], mv[mesh_edges[e, 1]]
            for end in mesh_edges[e].tolist():
                lo, hi = np.searchsorted(u_sorted, [end, end + 1])
                j = order[lo:hi]
                j = j[ruling[j] & ~on[j]]
                if len(j):
                    d = q - p
                    t = np.clip((far[j] - p) @ d / (d @ d), 0.0, 1.0)
                    on[j] |= np.linalg.norm(far[j] - p - t[:, None] * d, axis=1) <= eps
        k = np.flatnonzero(on)
        if not len(k):
            return 0
        normals = self.face_normal_3d()
        theta = self._convexity(normals[fa[k]], normals[fb[k]], self.edges[cand[k]])
        fold = np.abs(theta) > tol.coplanar_deg
        e = cand[k[fold]]
        self.edge_assignment[e] = np.where(theta[fold] > 0, "M", "V")
        self.edge_fold_angle[e] = -theta[fold]
        return len(e)

    def faces_beside_edges(self) -> np.ndarray:
        """(n_edges, 2) int: :attr:`edge_faces`, or (a pattern made without them) the faces
        beside :attr:`edges` found from the faces (:func:`edge_faces_of`)."""
        if self.edge_faces is not None:
            return np.asarray(self.edge_faces, dtype=np.int64).reshape(-1, 2)
        return edge_faces_of(self.edges, self.faces, len(self.vertices_2d))

    def _convexity(self, na: np.ndarray, nb: np.ndarray, edges: np.ndarray) -> np.ndarray:
        """(k,) the signed angle (degrees) from the folded normal ``na`` of the face holding
        each edge ``a -> b`` (``a < b``) to ``nb`` of the other, about the edge: > 0 where the
        surface is convex from the front (a mountain)."""
        d = self.vertices_3d[edges[:, 1]] - self.vertices_3d[edges[:, 0]]
        return dihedral_turns(na, nb, d)

    def _halfedges(self):
        """(from (h,), to (h,), face_start (n_faces + 1,), next (h,)) of the faces'
        half-edges; ``next`` is the following half-edge of the same face."""
        a, start = face_arrays(self.faces)
        a = a.astype(np.int64, copy=False)
        nxt = np.arange(len(a)) + 1
        nxt[start[1:] - 1] = start[:-1]
        return a, a[nxt], start, nxt

    def _derive_edges(self):
        """Edges from faces; assignment and fold angle from the folded geometry.

        An edge with one face is a border or cut (B). An edge between two faces of one patch,
        between a cylinder or conical fillet and a face piece (tangent continuous by
        construction), or between
        two face pieces meeting within ``tol.coplanar_deg`` (across a flat, unrounded edge) is F
        with fold angle 0. Any other edge is a crease: M where the surface is convex seen from the
        front, V otherwise, with the fold angle between the two faces' 3D normals.
        """
        a, b, start, _ = halfedges = self._halfedges()
        face_of = run_owners(np.diff(start))
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        n = len(self.vertices_2d)
        key = lo * n + hi
        uniq, inv = np.unique(key, return_inverse=True)
        edges = np.stack([uniq // n, uniq % n], axis=1)
        ef = -np.ones((len(uniq), 2), dtype=np.int64)
        forward = a < b
        ef[inv[forward], 0] = face_of[forward]
        ef[inv[~forward], 1] = face_of[~forward]
        normals = self._face_normal_3d(*halfedges)
        assign = np.full(len(uniq), "B", dtype="<U1")
        angle = np.zeros(len(uniq))
        inner = (ef >= 0).all(axis=1)
        fa, fb = ef[inner, 0], ef[inner, 1]
        theta = self._convexity(normals[fa], normals[fb], edges[inner])
        ids = dict.fromkeys(self.face_patch)  # each patch, in order of its first face
        patch = patch_ids(self.face_patch)
        kind = patch_kinds(list(ids))
        cyl = ((kind == "cylinder") | (kind == "fillet"))[patch]  # tangent to the faces
        face = (kind == "face")[patch]
        tangent = (cyl[fa] & face[fb]) | (face[fa] & cyl[fb])
        coplanar = face[fa] & face[fb] & (np.abs(theta) < tol.coplanar_deg)
        smooth = (patch[fa] == patch[fb]) | tangent | coplanar
        a_in = np.where(smooth, "F", np.where(theta > 0, "M", "V"))
        assign[inner] = a_in
        angle[inner] = np.where(smooth, 0.0, -theta)
        self.edges = edges
        self.edge_faces = ef
        self.edge_assignment = assign
        self.edge_fold_angle = angle
