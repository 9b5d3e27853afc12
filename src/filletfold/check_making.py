"""The certificate's checks of a sheet material's making (:mod:`filletfold.layout.making`).

Measured again from the pattern and its making paths (as ``annotations.json`` holds them),
never from what made them:

* ``relief`` (a ``"relief"`` or ``"kerf"`` material) -- wherever the sheet would bend tighter
  than the floor, it is cut away: along every bent ruling of a cone
  (:func:`~filletfold.surface.bend.cone_rulings`) the stretch within ``floor / rate`` of the
  apex (its nearer end, and the point where the radius reaches the floor) lies inside a
  relief of that cone; every corner of a tapering fillet nearer its sharp corner (along the
  edge) than ``floor L / (2 r)`` lies inside a relief of that fillet; and no relief cuts
  anything but its own patch (its area outside the patch's faces in its piece within
  :data:`RELIEF_TOL` of its own). The value is the number of points or reliefs that fail.
* ``kerfs`` (a ``"kerf"`` material) -- every cylinder of the pattern is grooved so as to bend
  as it must (:class:`~filletfold.materials.Kerf`): in each piece its grooves run along its
  rulings (parallel to its faces' ruling edges within :data:`KERF_ANGLE_TOL`), there are ``n``
  distinct ones with ``n * turn_max >= phi`` (the turn ``phi = 2 gamma`` of the cylinder's
  normal), they are evenly ``s`` apart with ``n s`` the arc ``r phi`` (the grooves' turns add
  up to the bend: the kerf-bending relation ``s = R theta``), and ``s`` leaves the land
  between two grooves. The value is the number of cylinders that fail.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import shapely

from .layout.making import cone_fans, fillet_ends, outside_turn, relief_polygons
from .surface.bend import cone_rulings
from .surface.faces import face_polygons

__all__ = ["KERF_ANGLE_TOL", "RELIEF_TOL", "kerf_check", "relief_check"]

#: The share of a relief's area that may lie outside its patch (its circle's chords).
RELIEF_TOL = 1e-6
#: A groove's largest angle (radians) from its cylinder's rulings in the pattern.
KERF_ANGLE_TOL = 1e-4
#: Relative round-off of positions along a cylinder's arc (spacing, coverage).
POSITION_RTOL = 1e-6


def _patch_faces(g, kind: int, index: int) -> np.ndarray:
    return np.flatnonzero((g.kind == kind) & (g.index == index))


def _union(g, faces: np.ndarray):
    if not len(faces):
        return shapely.Polygon()
    lists = [g.flat[g.start[f] : g.start[f + 1]] for f in faces.tolist()]
    return shapely.union_all(face_polygons(g.v2, lists))


def relief_check(g, making: list, floor: float, kinds) -> tuple:
    """``(ok, value, detail, worst)`` of the ``relief`` check (module docstring).

    Parameters
    ----------
    g : the certificate's data (:class:`filletfold.check._Data`)
    making : list of MakingPath
    floor : float
        The bend floor (mesh units).
    kinds : (cone, cylinder, face, fillet) int
        The certificate's patch kind codes.
    """
    cone_k, _, _, fillet_k = kinds
    tol = POSITION_RTOL * g.size + 4 * g.q
    reliefs = relief_polygons(making)
    covers = {p: shapely.union_all(polys).buffer(tol) for p, polys in reliefs.items()}
    bad, where = 0, None
    # cones: the stretch of every ruling tighter than the floor
    face_cone = np.where(g.kind == cone_k, g.index, -1)
    apex = np.where(np.isfinite(g.apex), g.apex, 0.0)
    r = cone_rulings(g.v3, g.flat, g.start, face_cone, apex)
    tight = np.flatnonzero(r.radius < floor * (1 - 1e-9))
    n_tight = len(tight)
    if n_tight:
        u = r.cone[tight]
        sa = np.linalg.norm(g.v3[r.a[tight]] - apex[u], axis=1)
        sb = np.linalg.norm(g.v3[r.b[tight]] - apex[u], axis=1)
        reach = floor / r.rate[tight]
        t = np.clip((reach - sa) / np.maximum(sb - sa, 1e-300), 0.0, 1.0)
        pa, pb = g.v2[r.a[tight]], g.v2[r.b[tight]]
        ends = pa + t[:, None] * (pb - pa)
        for k in range(n_tight):
            cover = covers.get(f"cone {int(u[k])}")
            pts = shapely.points(np.stack([pa[k], ends[k]]))
            if cover is None or not shapely.covers(cover, pts).all():
                bad += 1
                where = where or f"cone {int(u[k])}"
    # tapering fillets: their corners nearer the sharp corner than the floor allows
    n_fillet = 0
    for e in np.unique(g.index[g.kind == fillet_k]).tolist():
        faces = _patch_faces(g, fillet_k, e)
        idx = np.unique(np.concatenate([g.flat[g.start[f] : g.start[f + 1]] for f in faces]))
        s_end, other = fillet_ends(g.mv[g.edge_vertices[e]], g.v3[idx])
        length = float(np.linalg.norm(other - s_end))
        if not (length > 0 and g.radius[e] > 0):
            continue
        axis = (other - s_end) / length
        x_floor = floor * length / (2.0 * g.radius[e]) * (1 - 1e-9)
        # along each ruling of each face, from its corner at S to where the radius is the floor
        pts = []
        for f in faces.tolist():
            corners = g.flat[g.start[f] : g.start[f + 1]]
            dist = np.linalg.norm(g.v3[corners] - s_end, axis=1)
            if dist.min() > tol:  # a face of the wide half: no corner at S
                continue
            at_s = corners[np.argmin(dist)]
            for c in corners.tolist():
                x = float((g.v3[c] - s_end) @ axis)
                if x > tol:
                    t = min(1.0, x_floor / x)
                    pts.append(g.v2[at_s] + t * (g.v2[c] - g.v2[at_s]))
        n_fillet += len(pts)
        if not pts:
            continue
        cover = covers.get(f"fillet {e}")
        if cover is None or not shapely.covers(cover, shapely.points(np.array(pts))).all():
            bad += 1
            where = where or f"fillet {e}"
    # no relief cuts another patch
    outside = 0
    codes = {"cone": cone_k, "fillet": fillet_k}
    for patch, polys in reliefs.items():
        kind, index = patch.split(" ")
        faces = _patch_faces(g, codes.get(kind, -1), int(index))
        own = _union(g, faces).buffer(tol)
        for poly in polys:
            if shapely.difference(poly, own).area > RELIEF_TOL * max(poly.area, 1e-300):
                outside += 1
                where = where or patch
    n = sum(len(p) for p in reliefs.values())
    detail = (
        f"{n} reliefs; {n_tight} cone ruling(s) and {n_fillet} tapering-fillet corner(s) "
        f"tighter than the floor {floor:.6g} (mesh units): {bad} patch(es) not relieved; "
        f"{outside} relief(s) cutting another patch"
    )
    worst = {"patch": where} if where else {}
    return bad + outside == 0, float(bad + outside), detail, worst


def kerf_check(g, pattern, making: list, kerf, mm_per_unit: float, kinds) -> tuple:
    """``(ok, value, detail, worst)`` of the ``kerfs`` check (module docstring).

    Parameters
    ----------
    g : the certificate's data
    making : list of MakingPath
    kerf : Kerf
    mm_per_unit : float
    kinds : (cone, cylinder, face, fillet) int
        The certificate's patch kind codes.
    """
    cylinder = kinds[1]
    turn = kerf.turn_max()
    land = (kerf.width_mm + kerf.land_mm) / mm_per_unit
    grooves: dict[int, list] = {}
    for m in making:
        if m.kind.startswith("kerf") and m.patch.startswith("cylinder "):
            grooves.setdefault(int(m.patch.split(" ")[1]), []).append(m)
    bad, where, n_grooves = 0, None, 0
    edges = np.unique(g.index[g.kind == cylinder])
    edges = edges[g.rounded[edges]]
    for e in edges.tolist():
        faces = _patch_faces(g, cylinder, e)
        phi = 2.0 * float(g.half_angle[e])
        arc = float(g.radius[e]) * phi
        need = int(np.ceil(phi / turn - 1e-9))
        for shape, mine in _parts(g, faces):
            ruling = _ruling_direction(g, mine, e)
            if ruling is None:
                continue
            across = np.array([-ruling[1], ruling[0]])
            lines = [
                m
                for m in grooves.get(e, [])
                if shapely.covers(shape.buffer(1e-6 * g.size), shapely.LineString(m.points))
            ]
            n_grooves += len(lines)
            ok = True
            for m in lines:
                d = m.points[-1] - m.points[0]
                n = np.linalg.norm(d)
                if n > 0 and abs(d[0] * across[0] + d[1] * across[1]) / n > KERF_ANGLE_TOL:
                    ok = False
            pos = np.sort([float(m.points.mean(axis=0) @ across) for m in lines])
            tol = POSITION_RTOL * max(arc, 1e-300) + 4 * g.q
            distinct = pos[np.r_[True, np.diff(pos) > tol]] if len(pos) else pos
            count = len(distinct)
            if count < need or count * turn < phi * (1 - 1e-9):
                ok = False
            if count >= 2:
                gaps = np.diff(distinct)
                spacing = float(gaps.mean())
                even = np.abs(gaps - spacing).max() <= 2 * tol
                if not even or abs(count * spacing - arc) > 2 * count * tol + 1e-9 * arc:
                    ok = False
                if spacing < land * (1 - 1e-9):
                    ok = False
            if not ok:
                bad += 1
                where = where or f"cylinder {e}"
    cones, cone_grooves, cone_bad, cone_where = _cone_kerfs(g, pattern, making, turn, land)
    where = where or cone_where
    detail = (
        f"{len(edges)} cylinders, {n_grooves} grooves; {cones} cone fans, {cone_grooves} "
        f"grooves (each turning at most {np.degrees(turn):.4g} deg, at least {land:.6g} "
        f"apart in mesh units): {bad} cylinder part(s) and {cone_bad} cone part(s) not "
        "grooved as they bend"
    )
    bad += cone_bad
    return bad == 0, float(bad), detail, ({"patch": where} if where else {})


def _cone_kerfs(g, pattern, making: list, turn_max: float, land: float) -> tuple:
    """``(cone parts, grooves, parts failing, first failing patch)`` of the cones: in every
    part of a cone (a fan about its apex, :func:`~filletfold.layout.making.cone_fans`) the
    grooves are rays from the apex, outside its reliefs, at least ``land`` apart at their
    inner ends, and as many as its turn outside the reliefs needs (``ceil(T / turn_max)``);
    every groove of a cone lies on a ray of one of its fans."""
    tol = POSITION_RTOL * g.size + 4 * g.q
    reliefs = relief_polygons(making)
    grooves: dict = {}
    for m in making:
        if m.kind != "relief" and m.patch.startswith("cone "):
            grooves.setdefault(m.patch, []).append(m)
    fans = cone_fans(pattern, g.apex)
    bad, where, count = 0, None, 0
    placed: dict = {}
    for fan in fans:
        patch, c2 = f"cone {fan.vertex}", fan.apex_2d
        hole = shapely.union_all(reliefs.get(patch, []))
        outside = float(outside_turn(fan, hole.buffer(tol), g.size).sum())
        need = math.ceil(outside / turn_max - 1e-9) if outside > 1e-12 else 0
        part = fan.part.buffer(tol)
        mine = [
            m
            for m in grooves.get(patch, [])
            if _on_ray(m.points, c2, tol) and part.covers(shapely.LineString(m.points))
        ]
        placed[patch] = placed.get(patch, 0) + len(mine)
        count += len(mine)
        inner: dict = {}
        for m in mine:  # angles from the fan's first ruling: neighbours never across its cut
            a = round((_angle(m.points, c2) - float(fan.psi[0])) % (2 * math.pi), 9)
            r = float(np.linalg.norm(m.points - c2, axis=1).min())
            inner[a] = min(inner.get(a, np.inf), r)
        ok = len(inner) >= need
        shrunk = hole.buffer(-2 * tol)
        ok &= not any(shrunk.intersects(shapely.LineString(m.points)) for m in mine)
        keys = sorted(inner)
        for a, b in itertools.pairwise(keys):
            if 2 * min(inner[a], inner[b]) * math.sin(0.5 * (b - a)) < land * (1 - 1e-6) - tol:
                ok = False
        if not ok:
            bad += 1
            where = where or patch
    for patch, lines in grooves.items():  # a groove on no fan: not along the cone's rulings
        if placed.get(patch, 0) < len(lines):
            bad += 1
            where = where or patch
    return len(fans), count, bad, where


def _on_ray(points: np.ndarray, c2: np.ndarray, tol: float) -> bool:
    """Whether a groove's centre line lies on a ray from ``c2``."""
    d = points[-1] - points[0]
    n = np.linalg.norm(d)
    if n == 0:
        return False
    r = points[0] - c2
    return abs(d[0] * r[1] - d[1] * r[0]) / n <= max(tol, 1e-9 * np.linalg.norm(r))


def _angle(points: np.ndarray, c2: np.ndarray) -> float:
    far = points[np.argmax(np.linalg.norm(points - c2, axis=1))] - c2
    return math.atan2(far[1], far[0])


def _parts(g, faces: np.ndarray) -> list:
    """The connected parts of the union of ``faces`` in each piece: (polygon, its faces)."""
    out = []
    for piece in np.unique(g.piece[faces]).tolist():
        mine = faces[g.piece[faces] == piece]
        shape = _union(g, mine)
        parts = [p for p in getattr(shape, "geoms", [shape]) if p.area > 0]
        if len(parts) == 1:
            out.append((parts[0], mine))
            continue
        lists = [g.flat[g.start[f] : g.start[f + 1]] for f in mine.tolist()]
        inner = shapely.point_on_surface(face_polygons(g.v2, lists))
        for part in parts:
            out.append((part, mine[shapely.covers(part.buffer(1e-9 * g.size), inner)]))
    return out


def _ruling_direction(g, faces: np.ndarray, e: int):
    """The unit 2D direction of cylinder ``e``'s rulings among ``faces`` (the pattern side of
    a face that is parallel in 3D to the edge), None when no side is."""
    best, longest = None, 0.0
    for f in faces.tolist():
        idx = g.flat[g.start[f] : g.start[f + 1]]
        p3, p2 = g.v3[idx], g.v2[idx]
        d3 = np.roll(p3, -1, axis=0) - p3
        d2 = np.roll(p2, -1, axis=0) - p2
        n3 = np.linalg.norm(d3, axis=1)
        par = np.abs(d3 @ g.axis_dir[e]) >= (1 - 1e-9) * n3
        for k in np.flatnonzero(par & (n3 > longest)).tolist():
            best, longest = d2[k] / np.linalg.norm(d2[k]), float(n3[k])
    return best
