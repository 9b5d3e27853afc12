"""Making the bends in a real sheet: relief cuts and kerf grooves, drawn on the pattern.

A sheet material (:mod:`filletfold.materials`) is made one of three ways (its ``making``):

* ``"score"`` (paper, card, polypropylene): the creases are scored, mountains on the front,
  valleys on the back; the cut files name their layers so (:func:`score_layers`). Nothing is
  added to the pattern: the sheet bends its fillets and cones freely and creases itself at a
  cone's tip.
* ``"relief"`` (sheet metal): the bends are rolled or braked; where a bend would be tighter
  than the material bends -- a cone near its apex (its *tip zone*,
  :func:`~filletfold.surface.bend.cone_tip_zones`), a tapering fillet near its sharp corner --
  the sheet is cut away: a **relief** (:func:`relief_cuts`), at least the sheet's thickness
  across.
* ``"kerf"`` (plywood): every cylinder is grooved along its rulings on its inner side
  (:func:`cylinder_kerfs`, the model of :class:`~filletfold.materials.Kerf`), and the tips
  relieved as for metal.

Each path is a :class:`MakingPath` in pattern coordinates: its kind (``"relief"``,
``"kerf-front"``, ``"kerf-back"``; a front groove is cut into the side of the sheet the pattern
shows, a back one into the other: a valley bends toward the front, a mountain toward the back),
the patch it makes (``"cone 12"``, ``"fillet 40"``, ``"cylinder 7"``) and its points. The
certificate re-measures them (:func:`filletfold.check.certify`: ``relief`` and ``kerfs``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from ..surface.bend import cone_bend_radii
from ..surface.faces import face_polygons
from ..surface.pattern import face_arrays

__all__ = [
    "MAKING_KINDS",
    "MakingPath",
    "cylinder_kerfs",
    "making_paths",
    "patch_indices",
    "relief_cuts",
    "score_layers",
]

#: The kinds of making paths, in drawing order.
MAKING_KINDS = ("relief", "kerf-front", "kerf-back")
#: Corners of a relief's circle.
RELIEF_CORNERS = 48


@dataclass(frozen=True)
class MakingPath:
    """One path of a sheet's making, in pattern coordinates.

    Attributes
    ----------
    kind : str
        Of :data:`MAKING_KINDS`.
    patch : str
        The patch it makes (``"cone 12"``, ``"fillet 40"``, ``"cylinder 7"``).
    points : (k, 2) float
    closed : bool
        A relief is a closed outline (cut out); a groove an open centre line (cut ``width``
        wide and ``depth`` deep).
    """

    kind: str
    patch: str
    points: np.ndarray
    closed: bool


def score_layers(making: str) -> dict[str, str] | None:
    """The cut files' layer names of the mountain and valley lines of a ``"score"`` material
    (``{"mountain": "SCORE_FRONT", "valley": "SCORE_BACK"}``), else None: a mountain is
    scored on the front (it folds away from it), a valley on the back."""
    if making != "score":
        return None
    return {"mountain": "SCORE_FRONT", "valley": "SCORE_BACK"}


def patch_indices(face_patch, kind: str) -> np.ndarray:
    """(n_faces,) int: the index of each face's patch of ``kind`` (``"cone"``, ...), -1 for
    the faces of other patches."""
    prefix = kind + " "
    return np.array(
        [int(str(p)[len(prefix) :]) if str(p).startswith(prefix) else -1 for p in face_patch],
        dtype=np.int64,
    )


def _components(pattern, faces: np.ndarray) -> list:
    """The union of ``faces`` of the pattern, per piece, as (piece, shapely geometry)."""
    out = []
    if not len(faces):
        return out
    polys = face_polygons(pattern.vertices_2d, [pattern.faces[f] for f in faces.tolist()])
    piece = np.asarray(pattern.face_piece)[faces]
    for k in np.unique(piece).tolist():
        out.append((k, shapely.make_valid(shapely.union_all(polys[piece == k]))))
    return out


def _parts(pattern, faces: np.ndarray) -> list:
    """The connected parts of the union of ``faces`` (a patch may lie in several pieces, and
    in one net in several places: a module split into runs), each as (polygon, the pattern
    vertices of ``faces`` on it)."""
    idx = np.unique(np.concatenate([pattern.faces[f] for f in faces.tolist()]))
    pts = shapely.points(pattern.vertices_2d[idx])
    out = []
    for _, shape in _components(pattern, faces):
        for part in getattr(shape, "geoms", [shape]):
            if isinstance(part, shapely.Polygon) and part.area > 0:
                on = shapely.dwithin(part, pts, 1e-9 * (1.0 + part.length))
                if on.any():
                    out.append((part, idx[on]))
    return out


def _circle(centre: np.ndarray, radius: float) -> shapely.Polygon:
    """A polygon of :data:`RELIEF_CORNERS` corners about the circle (which it holds: its
    sides touch it)."""
    t = np.linspace(0.0, 2 * math.pi, RELIEF_CORNERS, endpoint=False)
    out = radius / math.cos(math.pi / RELIEF_CORNERS)
    return shapely.Polygon(centre + out * np.stack([np.cos(t), np.sin(t)], axis=1))


def _outlines(kind: str, patch: str, shape) -> list[MakingPath]:
    """The outer rings of the polygons of ``shape`` as closed paths (a relief's outline)."""
    out = []
    for g in getattr(shape, "geoms", [shape]):
        if isinstance(g, shapely.Polygon) and not g.is_empty and g.area > 0:
            ring = np.asarray(g.exterior.coords)[:-1]
            out.append(MakingPath(kind, patch, ring, True))
    return out


def relief_cuts(
    pattern, apex: np.ndarray, floor: float, least: float, mesh, rounding
) -> list[MakingPath]:
    """The reliefs of a design: where the sheet bends tighter than ``floor`` (pattern units).

    * A **cone** bends tighter than the floor within ``floor / rate`` of its apex along each
      ruling (:func:`~filletfold.surface.bend.cone_bend_radii`): its relief is the circle
      about the apex (in the pattern) of the largest such distance, at least ``least``
      across in radius (a relief narrower than the sheet is thick cannot be cut), clipped to
      the cone's faces (nothing else is cut).
    * A **tapering fillet** (``fillet <edge>``), whose radius grows from 0 at its sharp
      corner ``S`` to ``r`` at the edge's midpoint, is tighter than the floor within
      ``x = floor L / (2 r)`` of ``S`` along the edge (``L`` the edge's length): its relief
      is the circle about ``S`` that holds every point of the fillet so near, at least
      ``least``, clipped to the fillet's faces.

    Parameters
    ----------
    pattern : CreasePattern
    apex : (n_vertices, 3) float
        Each vertex's cone apex (NaN without a cone).
    floor, least : float
        Pattern units.
    mesh : PolyMesh
    rounding : EdgeRounding
        A fillet's ``radius`` is its radius at the edge's midpoint.

    Returns
    -------
    list of MakingPath
    """
    out: list[MakingPath] = []
    flat, start = face_arrays(pattern.faces)
    v2, v3 = pattern.vertices_2d, pattern.vertices_3d
    apex = np.asarray(apex, dtype=np.float64)
    cone = patch_indices(pattern.face_patch, "cone")
    radius, u, rate = cone_bend_radii(v3, flat, start, cone, np.where(np.isfinite(apex), apex, 0))
    tight = radius < floor
    reach = np.zeros(len(apex))
    np.maximum.at(reach, u[tight], floor / rate[tight])
    for vertex in np.flatnonzero(reach > 0).tolist():
        for part, idx in _parts(pattern, np.flatnonzero(cone == vertex)):
            near = idx[np.argmin(np.linalg.norm(v3[idx] - apex[vertex], axis=1))]
            disc = _circle(v2[near], max(float(reach[vertex]), least))
            out += _outlines("relief", f"cone {vertex}", part.intersection(disc))
    fillet = patch_indices(pattern.face_patch, "fillet")
    for edge in np.unique(fillet[fillet >= 0]).tolist():
        faces = np.flatnonzero(fillet == edge)
        idx = np.unique(np.concatenate([pattern.faces[f] for f in faces.tolist()]))
        a, b = mesh.edges[edge]
        ends = mesh.vertices[[a, b]]
        d = np.linalg.norm(v3[idx][:, None, :] - ends[None], axis=2)  # (k, 2)
        tip = int(np.argmin(d.min(axis=0)))  # the sharp end: a point of the fillet
        s_end, other = ends[tip], ends[1 - tip]
        length = float(np.linalg.norm(other - s_end))
        axis = (other - s_end) / length
        x = (v3[idx] - s_end) @ axis  # distance along the edge from S
        r_mid = float(rounding.radius[edge])
        if not r_mid > 0:
            continue
        x_floor = floor * length / (2.0 * r_mid)
        # every point of the fillet within x_floor of S along the edge lies within the circle
        # of x_floor times the widest ratio of a point's distance from S to its x
        slant = np.linalg.norm(v3[idx] - s_end, axis=1)
        spread = float(np.max(slant[x > 0] / x[x > 0])) if (x > 0).any() else 1.0
        for part, on in _parts(pattern, faces):
            dist = np.linalg.norm(v3[on] - s_end, axis=1)
            if dist.min() > 1e-9 * length:  # the half at the wide end: no sharp corner in it
                continue
            disc = _circle(v2[on[int(np.argmin(dist))]], max(x_floor * spread, least))
            out += _outlines("relief", f"fillet {edge}", part.intersection(disc))
    return out


def cylinder_kerfs(pattern, mesh, rounding, kerf) -> list[MakingPath]:
    """The kerf grooves of every cylinder: ``n = ceil(phi / turn_max)`` centre lines along its
    rulings, ``A / n`` apart across its arc of length ``A = r phi`` (``phi = 2 gamma``, the
    turn of its normal), the first and last half a spacing from its ends, on the bend's inner
    side (``kerf-back`` for a mountain, ``kerf-front`` for a valley), clipped to the
    cylinder's faces in each piece.

    Parameters
    ----------
    pattern : CreasePattern
    mesh : PolyMesh
    rounding : EdgeRounding
    kerf : Kerf
        Only its :meth:`~filletfold.materials.Kerf.turn_max` counts here (the grooves are
        centre lines; the certificate holds their spacing to its width and land).
    """
    out: list[MakingPath] = []
    cyl = patch_indices(pattern.face_patch, "cylinder")
    v2, v3 = pattern.vertices_2d, pattern.vertices_3d
    turn = kerf.turn_max()
    for edge in np.unique(cyl[cyl >= 0]).tolist():
        r = float(rounding.radius[edge])
        phi = 2.0 * float(rounding.half_angle[edge])
        if not (r > 0 and phi > 0):
            continue
        n = max(1, math.ceil(phi / turn - 1e-9))
        a, b = mesh.edges[edge]
        axis = mesh.vertices[b] - mesh.vertices[a]
        axis /= np.linalg.norm(axis)
        centre = rounding.axis_point[edge]
        t0 = rounding.tangent_point[edge, 0] - centre
        t0 /= np.linalg.norm(t0)
        t1 = rounding.tangent_point[edge, 1] - centre
        t1 = t1 - (t1 @ t0) * t0
        t1 /= np.linalg.norm(t1)
        kind = "kerf-back" if rounding.kappa[edge] > 0 else "kerf-front"
        for shape, idx in _parts(pattern, np.flatnonzero(cyl == edge)):
            rel = v3[idx] - centre
            along = rel @ axis
            arc = r * np.arctan2(rel @ t1, rel @ t0)  # from the tangent point on face 0
            m = _fit_plane_map(np.stack([along, arc], axis=1), v2[idx])
            lo, hi = along.min(), along.max()
            pad = hi - lo + r
            for j in range(n):
                u = (j + 0.5) * r * phi / n
                ends = np.array([[lo - pad, u], [hi + pad, u]])
                line = shapely.LineString(_apply(m, ends))
                cut = shape.intersection(line)
                for g in getattr(cut, "geoms", [cut]):
                    if isinstance(g, shapely.LineString) and g.length > 0:
                        out.append(
                            MakingPath(kind, f"cylinder {edge}", np.asarray(g.coords), False)
                        )
    return out


def _fit_plane_map(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """The 2x3 isometry (a rotation, or a reflection, and a shift) taking ``src`` (k, 2) onto
    ``dst`` (k, 2) in least squares."""
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    h = (src - cs).T @ (dst - cd)
    u, _, vt = np.linalg.svd(h)
    rot = (u @ vt).T  # may be a reflection: a developed strip keeps or flips its side
    return np.hstack([rot, (cd - rot @ cs)[:, None]])


def _apply(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    return pts @ m[:, :2].T + m[:, 2]


def making_paths(pattern, design_mesh, rounding, apex, material, mm_per_unit: float) -> list:
    """The making paths of a design in ``material`` at ``mm_per_unit`` millimetres per
    pattern unit: none for a ``"score"`` material (its layers are named instead,
    :func:`score_layers`), the reliefs for ``"relief"``, the reliefs and the cylinders' kerfs
    for ``"kerf"``."""
    if material is None or material.making == "score" or not mm_per_unit > 0:
        return []
    floor = material.bend_floor_mm() / mm_per_unit
    least = material.thickness_mm / mm_per_unit
    out = relief_cuts(pattern, apex, floor, least, design_mesh, rounding)
    if material.making == "kerf" and material.kerf is not None:
        out += cylinder_kerfs(pattern, design_mesh, rounding, material.kerf)
    return out
