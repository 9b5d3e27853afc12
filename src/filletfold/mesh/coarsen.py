"""Coarsening a mesh before it is rounded: a scan of 100,000 triangles would give tens of
thousands of pieces, far too fine to fold by hand.

:func:`coarsen_mesh` triangulates the mesh's polygons and collapses edges by quadric error
(Garland-Heckbert, through ``fast-simplification``, the wrapper of Fast-Quadric-Mesh-
Simplification that PyVista maintains) down to about the number of triangles asked for, and
measures how far the surface moved: :class:`Coarsening` holds the largest distance from a
vertex of either mesh to the other's surface (:func:`surface_distance`), the one-sided
distances at the vertices of a symmetric Hausdorff distance. The caller cleans the result as
any input (:func:`~filletfold.mesh.load_mesh`), so coplanar triangles merge into polygons
again.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .polymesh import PolyMesh, mesh_size

__all__ = [
    "Coarsening",
    "coarse_target",
    "coarsen_and_clean",
    "coarsen_mesh",
    "surface_distance",
    "triangles_of",
]

#: Fewest triangles :func:`coarsen_mesh` takes as a target (a tetrahedron).
MIN_FACES = 4
#: Points, and point-triangle pairs, measured at once by :func:`surface_distance`.
POINT_CHUNK = 1024
PAIR_CHUNK = 1 << 19


@dataclass
class Coarsening:
    """What :func:`coarsen_mesh` did.

    Attributes
    ----------
    faces_before, faces_after : int
        Triangles before (the mesh's polygons triangulated) and after.
    vertices_before, vertices_after : int
    distance : float
        Largest distance from a vertex of either mesh to the other's surface (length units).
    size : float
        The input's size (bounding-box diagonal): ``distance / size`` is the relative figure.
    """

    faces_before: int
    faces_after: int
    vertices_before: int
    vertices_after: int
    distance: float
    size: float

    def as_dict(self) -> dict:
        """The report's ``coarsening`` record."""
        return {
            "faces_before": self.faces_before,
            "faces_after": self.faces_after,
            "vertices_before": self.vertices_before,
            "vertices_after": self.vertices_after,
            "hausdorff": self.distance,
            "relative_hausdorff": self.distance / self.size if self.size > 0 else 0.0,
        }

    def summary(self) -> str:
        """One line for the command's summary."""
        rel = 100.0 * self.distance / self.size if self.size > 0 else 0.0
        return (
            f"coarsened: {self.faces_before:,} -> {self.faces_after:,} triangles, "
            f"{self.vertices_before:,} -> {self.vertices_after:,} vertices; the surface moved "
            f"by at most {self.distance:.4g} ({rel:.2g} % of the size) at the vertices"
        )


def coarse_target(mesh: PolyMesh, faces=None, edge_length=None) -> int | None:
    """The triangle count :func:`coarsen_mesh` aims for: ``faces``, or the count of
    equilateral triangles of side ``edge_length`` (a length, or ``"300%"`` of the mean edge
    length) that cover the mesh's area; None when neither is given.

    Raises
    ------
    ParameterError
        Both given, or a length that is not a positive length.
    """
    if faces is not None and edge_length is not None:
        raise ParameterError(
            "give faces (--faces) or edge_length (--edge-length), not both", name="edge_length"
        )
    if edge_length is None:
        return faces
    from ..parameters import parse_length

    length = float(parse_length(edge_length, mesh.mean_edge_length, "edge length"))
    area = float(np.sum(mesh.face_area))
    return max(MIN_FACES, round(area / (math.sqrt(3.0) / 4.0 * length**2)))


def triangles_of(mesh: PolyMesh) -> np.ndarray:
    """(t, 3) int: every face of ``mesh`` as triangles: triangles as they are, larger polygons
    (a merged coplanar region may be concave) by
    :func:`~filletfold.mesh.repair.triangulate_polygon_3d`, which stays inside them."""
    from .repair import triangulate_polygon_3d

    out = []
    for f in mesh.faces:
        f = np.asarray(f, dtype=np.int64)
        if len(f) == 3:
            out.append(f[None])
        else:
            out.append(f[np.array(triangulate_polygon_3d(mesh.vertices[f]), dtype=np.int64)])
    if not out:
        return np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(out)


def coarsen_mesh(mesh: PolyMesh, faces: int) -> tuple[np.ndarray, np.ndarray, Coarsening]:
    """``mesh`` decimated to about ``faces`` triangles (quadric edge collapse).

    Parameters
    ----------
    mesh : PolyMesh
        A cleaned mesh.
    faces : int
        The number of triangles to aim for (at least :data:`MIN_FACES`); a mesh of no more
        triangles is returned as it is (triangulated).

    Returns
    -------
    vertices : (n, 3) float
    triangles : (t, 3) int
    coarsening : Coarsening

    Raises
    ------
    ParameterError
        ``faces`` is not a whole number of at least :data:`MIN_FACES`.
    """
    try:
        target = int(faces)
    except (TypeError, ValueError):
        raise ParameterError(f"faces must be a whole number, got {faces!r}", name="faces") from None
    if target != faces or target < MIN_FACES:
        raise ParameterError(
            f"faces must be a whole number of at least {MIN_FACES}, got {faces!r}", name="faces"
        )
    tri = triangles_of(mesh)
    v = np.asarray(mesh.vertices, dtype=np.float64)
    if len(tri) > target:
        import fast_simplification

        v_new, t_new = fast_simplification.simplify(
            np.ascontiguousarray(v), np.ascontiguousarray(tri, dtype=np.int32), target_count=target
        )
        v_new = np.asarray(v_new, dtype=np.float64)
        t_new = np.asarray(t_new, dtype=np.int64).reshape(-1, 3)
    else:
        v_new, t_new = v.copy(), tri
    used = np.unique(t_new)
    remap = np.full(len(v_new), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    v_new, t_new = v_new[used], remap[t_new]
    distance = max(surface_distance(v, v_new, t_new), surface_distance(v_new, v, tri))
    info = Coarsening(
        faces_before=len(tri),
        faces_after=len(t_new),
        vertices_before=len(v),
        vertices_after=len(v_new),
        distance=float(distance),
        size=float(mesh_size(mesh)),
    )
    return v_new, t_new, info


def coarsen_and_clean(mesh: PolyMesh, faces: int, **clean) -> tuple[PolyMesh, list, Coarsening]:
    """:func:`coarsen_mesh`, then the result cleaned as any input
    (:func:`~filletfold.mesh.load_mesh` with ``clean``: ``coplanar_deg``, ``strict``), so that
    coplanar triangles merge into polygons again.

    Returns
    -------
    mesh : PolyMesh
    repairs : list of Repair
        The cleaning's repairs, each naming its element "... of the coarsened mesh".
    coarsening : Coarsening
    """
    from dataclasses import replace

    from . import load_mesh

    v, t, info = coarsen_mesh(mesh, faces)
    coarse, log = load_mesh((v, t), **clean)
    repairs = [replace(r, where=f"{r.where} of the coarsened mesh") for r in log.repairs]
    return coarse, repairs, info


def surface_distance(points: np.ndarray, vertices: np.ndarray, triangles: np.ndarray) -> float:
    """Largest distance from any of ``points`` (k, 3) to the surface of the triangles
    ``triangles`` (t, 3) of ``vertices`` (exact: each point's candidates are the triangles
    that may hold a point as near as the nearest vertex, found with a k-d tree of the
    triangles' centres; 0 for no points, infinity for no triangles)."""
    from scipy.spatial import cKDTree

    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if not len(points):
        return 0.0
    if not len(triangles):
        return float("inf")
    corners = vertices[triangles]  # (t, 3, 3)
    centre = corners.mean(axis=1)
    reach = np.linalg.norm(corners - centre[:, None], axis=2).max(axis=1)  # bounding spheres
    near_vertex, _ = cKDTree(vertices[np.unique(triangles)]).query(points)
    # a triangle within near_vertex of the point has its centre within that plus its reach
    tree = cKDTree(centre)
    worst = 0.0
    for lo in range(0, len(points), POINT_CHUNK):
        p, bound = points[lo : lo + POINT_CHUNK], near_vertex[lo : lo + POINT_CHUNK]
        lists = tree.query_ball_point(p, bound + reach.max() * (1 + 1e-9) + 1e-300)
        counts = np.fromiter(map(len, lists), dtype=np.int64, count=len(lists))
        owner = np.repeat(np.arange(len(p)), counts)
        cand = np.fromiter(
            (t for lst in lists for t in lst), dtype=np.int64, count=int(counts.sum())
        )
        best = bound.copy()  # a vertex of the surface is on it
        for k in range(0, len(cand), PAIR_CHUNK):
            own = owner[k : k + PAIR_CHUNK]
            d = point_triangle_distance(p[own], corners[cand[k : k + PAIR_CHUNK]])
            np.minimum.at(best, own, d)
        worst = max(worst, float(best.max()))
    return worst


def point_triangle_distance(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(k,) distance from each point ``p`` (k, 3) to its triangle ``tri`` (k, 3, 3): to the
    plane where the foot of the perpendicular falls inside, else to the nearest side (a
    triangle of no area has its sides alone)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    area2 = np.linalg.norm(n, axis=1)
    side = [_segment_distance(p, a, b), _segment_distance(p, b, c), _segment_distance(p, c, a)]
    out = np.minimum(np.minimum(side[0], side[1]), side[2])
    scale = np.maximum(np.abs(tri).max(axis=(1, 2)), 1.0)
    flat = area2 > 1e-14 * scale**2
    if flat.any():
        nn = n[flat] / area2[flat, None]
        pp, aa, bb, cc = p[flat], a[flat], b[flat], c[flat]
        h = np.einsum("ij,ij->i", pp - aa, nn)
        foot = pp - h[:, None] * nn
        inside = np.ones(len(pp), dtype=bool)
        for u, w in ((aa, bb), (bb, cc), (cc, aa)):
            inside &= np.einsum("ij,ij->i", np.cross(w - u, foot - u), nn) >= 0
        sub = out[flat]
        sub[inside] = np.abs(h[inside])
        out[flat] = sub
    return out


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k,) distance from each point ``p`` to the segment ``a b`` (rows)."""
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(dd > 0, np.einsum("ij,ij->i", p - a, d) / dd, 0.0)
    t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1)
