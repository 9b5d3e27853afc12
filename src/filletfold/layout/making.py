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
from typing import NamedTuple

import numpy as np
import shapely

from ..arrays import run_next
from ..mesh.measures import newell_vectors
from ..surface.bend import cone_tip_zones
from ..surface.faces import face_polygons
from ..surface.patch import kind_indices
from ..surface.pattern import face_arrays

__all__ = [
    "MAKING_KINDS",
    "Fan",
    "MakingPath",
    "cone_fans",
    "cone_kerfs",
    "cylinder_kerfs",
    "fillet_ends",
    "making_paths",
    "outside_turn",
    "relief_cuts",
    "relief_polygons",
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


def fillet_ends(ends: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(sharp end, other end)`` of a tapering fillet's edge, its ``ends`` (2, 3): the one
    that is a point of the fillet (its ``points`` (k, 3), folded), where it narrows to 0."""
    d = np.linalg.norm(points[:, None, :] - ends[None], axis=2)  # (k, 2)
    tip = int(np.argmin(d.min(axis=0)))
    return ends[tip], ends[1 - tip]


def relief_polygons(making: list) -> dict:
    """The reliefs of ``making`` (:class:`MakingPath`) as shapely polygons, by patch name."""
    out: dict = {}
    for m in making:
        if m.kind == "relief" and len(m.points) >= 3:
            out.setdefault(m.patch, []).append(shapely.Polygon(m.points))
    return out


def relief_cuts(
    pattern, apex: np.ndarray, floor: float, least: float, mesh, rounding
) -> list[MakingPath]:
    """The reliefs of a design: where the sheet bends tighter than ``floor`` (pattern units).

    * A **cone** bends tighter than the floor within ``floor / rate`` of its apex along each
      ruling (its tip zone, :func:`~filletfold.surface.bend.cone_tip_zones`): its relief is
      the circle
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
    v2, v3 = pattern.vertices_2d, pattern.vertices_3d
    apex = np.asarray(apex, dtype=np.float64)
    cone = kind_indices(pattern.face_patch, "cone")
    reach = np.nan_to_num(cone_tip_zones(pattern, apex, floor))  # 0: no cone, or never tight
    for vertex in np.flatnonzero(reach > 0).tolist():
        for part, idx in _parts(pattern, np.flatnonzero(cone == vertex)):
            near = idx[np.argmin(np.linalg.norm(v3[idx] - apex[vertex], axis=1))]
            disc = _circle(v2[near], max(float(reach[vertex]), least))
            out += _outlines("relief", f"cone {vertex}", part.intersection(disc))
    fillet = kind_indices(pattern.face_patch, "fillet")
    for edge in np.unique(fillet[fillet >= 0]).tolist():
        faces = np.flatnonzero(fillet == edge)
        idx = np.unique(np.concatenate([pattern.faces[f] for f in faces.tolist()]))
        s_end, other = fillet_ends(mesh.vertices[mesh.edges[edge]], v3[idx])
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
    cyl = kind_indices(pattern.face_patch, "cylinder")
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
                    if isinstance(g, shapely.LineString) and g.length > 1e-9 * pad:
                        out.append(
                            MakingPath(kind, f"cylinder {edge}", np.asarray(g.coords), False)
                        )
    return out


def cone_fans(pattern, apex: np.ndarray) -> list:
    """Every cone's parts as fans about their apex: per part (a cone may lie in several pieces
    and places), a :class:`Fan`: ``psi`` the developed angles of its rulings about the apex,
    increasing (the rulings that bound its faces, and its two ends), ``turn`` (len(psi) - 1,)
    the turn of the surface's normal over each interval between two rulings (a faceted cone
    turns at its rulings; half of each ruling's turn is given to each interval beside it),
    ``valley`` whether the cone bends toward the front (the sum of its signed turns, FOLD's
    sign), and ``part`` the part's polygon."""
    cone = kind_indices(pattern.face_patch, "cone")
    v2, v3 = pattern.vertices_2d, pattern.vertices_3d
    apex = np.asarray(apex, dtype=np.float64)
    flat, start = face_arrays(pattern.faces)
    normal = newell_vectors(v3[flat], start, run_next(start))  # every face's front normal
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    out = []
    for vertex in np.unique(cone[cone >= 0]).tolist():
        if not np.isfinite(apex[vertex]).all():
            continue
        faces = np.flatnonzero(cone == vertex)
        for part, idx in _parts(pattern, faces):
            c2 = v2[idx[np.argmin(np.linalg.norm(v3[idx] - apex[vertex], axis=1))]]
            rows = []  # (angles of its corners, normal) per face of the part
            for f in faces.tolist():
                corners = np.asarray(pattern.faces[f])
                if not part.buffer(1e-9 * (1 + part.length)).covers(
                    shapely.Point(v2[corners].mean(axis=0))
                ):
                    continue
                rel = v2[corners] - c2
                far = np.linalg.norm(rel, axis=1) > 1e-12 * (1 + np.abs(c2).max())
                if far.sum() < 2:
                    continue
                rows.append((np.arctan2(rel[far, 1], rel[far, 0]), normal[f]))
            if len(rows) < 2:
                continue
            # angles from the start of the fan: just past the widest gap between its rulings
            # (a cut module's wedge opening), so that no face straddles the branch cut
            every = np.sort(np.concatenate([ang for ang, _ in rows]) % (2 * math.pi))
            gaps = np.diff(np.r_[every, every[0] + 2 * math.pi])
            ref = every[(int(np.argmax(gaps)) + 1) % len(every)]
            spans = []
            for ang, n in rows:
                a = (ang - ref) % (2 * math.pi)
                a = np.where(a > 2 * math.pi - 1e-12, 0.0, a)  # the first ruling itself
                spans.append((a.min() + ref, a.max() + ref, n))
            # the fan's rulings: every face's two bounding angles; between two neighbouring
            # ones the surface is one face's (a cone's faces may also be split across its
            # rulings, near the apex and beyond: any face over the interval gives its normal)
            lo = np.array([t[0] for t in spans])
            hi = np.array([t[1] for t in spans])
            bounds = np.unique(np.round(np.r_[lo, hi], 12))
            mids = 0.5 * (bounds[:-1] + bounds[1:])
            cover = (lo[None, :] <= mids[:, None]) & (mids[:, None] <= hi[None, :])
            has = cover.any(axis=1)
            if has.sum() < 2:
                continue
            normals = np.array([t[2] for t in spans])[np.argmax(cover, axis=1)][has]
            psi = np.r_[bounds[:-1][has][0], bounds[1:][has]]
            cross = np.cross(normals[:-1], normals[1:])
            # at the ruling between intervals i and i + 1; atan2, not arccos of the dot product,
            # which turned two parallel normals by 1e-8 (a flat cone got a groove)
            step = np.arctan2(
                np.linalg.norm(cross, axis=1), np.einsum("ij,ij->i", normals[:-1], normals[1:])
            )
            ruling = np.stack([np.cos(psi[1:-1]), np.sin(psi[1:-1])], axis=1)  # in 2D
            sign = np.sign(
                np.einsum(
                    "ij,ij->i",
                    cross,
                    _lift(pattern, idx, c2, apex[vertex], ruling),
                )
            )
            turn = np.zeros(len(normals))
            turn[:-1] += 0.5 * step
            turn[1:] += 0.5 * step
            out.append(Fan(vertex, c2, psi, turn, float((sign * step).sum()) >= 0, part))
    return out


class Fan(NamedTuple):
    """One part of a cone as a fan about its apex (:func:`cone_fans`)."""

    vertex: int
    apex_2d: np.ndarray
    psi: np.ndarray
    turn: np.ndarray
    valley: bool
    part: object


def outside_turn(fan: Fan, hole, size: float) -> np.ndarray:
    """(len(fan.turn),) the turn of each face span of ``fan`` that the relief ``hole`` (a
    shapely geometry) does not wholly cover (0 where it does: a relieved face needs no
    groove)."""
    out = np.zeros(len(fan.turn))
    for j in range(len(fan.turn)):
        arc = np.linspace(fan.psi[j], fan.psi[j + 1], 4)
        wedge = shapely.Polygon(
            [fan.apex_2d, *(fan.apex_2d + 4 * size * np.stack([np.cos(arc), np.sin(arc)], axis=1))]
        )
        if not hole.covers(fan.part.intersection(wedge)):
            out[j] = fan.turn[j]
    return out


def _lift(pattern, idx, c2, apex3, dirs2):
    """3D directions from the apex of the 2D directions ``dirs2`` (k, 2) about ``c2``: the
    pattern's isometry of the cone's fan, fitted on its points ``idx``."""
    v2, v3 = pattern.vertices_2d[idx] - c2, pattern.vertices_3d[idx] - apex3
    # the linear map taking the developed fan onto the folded cone near each ruling is not
    # one map; the ruling's own 3D direction is that of its points: the nearest point of the
    # fan in angle, far from the apex
    ang = np.arctan2(v2[:, 1], v2[:, 0])
    far = np.linalg.norm(v2, axis=1) > 1e-12
    out = np.zeros((len(dirs2), 3))
    for k, d in enumerate(dirs2):
        a = math.atan2(d[1], d[0])
        gap = np.abs(np.angle(np.exp(1j * (ang - a))))
        gap[~far] = np.inf
        j = int(np.argmin(gap))
        out[k] = v3[j] / max(np.linalg.norm(v3[j]), 1e-300)
    return out


def cone_kerfs(pattern, apex: np.ndarray, kerf, land: float, reliefs: list) -> list[MakingPath]:
    """The kerf grooves of every cone: rays from its apex along its rulings, ``n =
    ceil(T / turn_max)`` of them for a cone part turning by ``T``, at the developed angles
    where its normal has turned by ``(j + 1/2) T / n`` (each groove takes ``T / n``), on the
    cone's inner side, from the circle of its relief (or the apex) -- or farther, where two
    grooves ``d psi`` apart are ``land`` (pattern units: the groove's width and land) apart --
    to its border. A cone part too tight for that (a groove that would have nothing left) is
    relieved whole instead: the material cannot bend it.

    Parameters
    ----------
    pattern : CreasePattern
    apex : (n_vertices, 3) float
    kerf : Kerf
    land : float
        The least distance between two grooves' centre lines (pattern units).
    reliefs : list of MakingPath
        The reliefs, whose cones' grooves start outside them.
    """
    out: list[MakingPath] = []
    turn_max = kerf.turn_max()
    holes = relief_polygons(reliefs)
    size = float(np.ptp(pattern.vertices_2d, axis=0).max()) if len(pattern.vertices_2d) else 1.0
    for fan in cone_fans(pattern, apex):
        c2 = fan.apex_2d
        hole = shapely.union_all(holes.get(f"cone {fan.vertex}", []))
        turn = outside_turn(fan, hole, size)  # the relieved spans take no groove
        total = float(turn.sum())
        if not total > 0:
            continue
        n = max(1, math.ceil(total / turn_max - 1e-9))
        cum = np.r_[0.0, np.cumsum(turn)]
        at = np.interp((np.arange(n) + 0.5) * total / n, cum, fan.psi)
        gaps = np.diff(at)
        start = land / (2 * np.sin(0.5 * gaps.min())) if len(gaps) and gaps.min() > 0 else 0.0
        reach = 2.0 * float(np.abs(shapely.get_coordinates(fan.part) - c2).max()) + 1.0
        kind = "kerf-front" if fan.valley else "kerf-back"
        grooves = []
        for a in at.tolist():
            d = np.array([math.cos(a), math.sin(a)])
            ray = shapely.LineString([c2 + start * d, c2 + reach * d])
            cut = fan.part.intersection(ray).difference(hole)
            found = [
                g
                for g in getattr(cut, "geoms", [cut])
                if isinstance(g, shapely.LineString) and g.length > 1e-9 * reach
            ]
            if not found:  # the cone is too tight there for grooves a land apart
                grooves = None
                break
            grooves += [MakingPath(kind, f"cone {fan.vertex}", np.asarray(g.coords), False)
                        for g in found]  # fmt: skip
        if grooves is None:  # it cannot be grooved as it bends: relieved whole
            out += _outlines("relief", f"cone {fan.vertex}", fan.part.difference(hole))
        else:
            out += grooves
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
    kerf = material.kerf
    if material.making == "kerf" and kerf is not None:
        land = (kerf.width_mm + kerf.land_mm) / mm_per_unit
        out += cylinder_kerfs(pattern, design_mesh, rounding, kerf)
        out += cone_kerfs(pattern, apex, kerf, land, list(out))
    return out
