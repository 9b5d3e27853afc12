"""A coarse, triangulated copy of a crease pattern for Origami Simulator (``simulator.fold``).

A surface operation (the exports only write what it gives: ``export/cutfiles.py`` writes
``simulator.fold`` and ``simulator.svg`` from it).

Origami Simulator (https://origamisimulator.org) folds a FOLD file with a bar-and-hinge
solver on the GPU. ``design.fold`` samples every cylinder arc finely, which the simulator
reads badly: its shader takes ``acos`` of triangle angles unclamped (a sliver turns into NaN),
reads at most 100 beams and creases per vertex (a cone apex has one ruling per sample), and
re-triangulates polygons with flat diagonals.

:func:`simulator_pattern` keeps a subset of the same vertices (same flat and folded
positions): it drops whole rulings of the cylinders, so each coarse cylinder cell turns about
``max_turn`` degrees but stays at least ``min_angle`` wide (its ruling length times
``tan(min_angle)``), merges the cone triangles on the dropped points into wider fan triangles
(bounding the apex valence), and triangulates every polygon with the diagonals that keep the
smallest angle largest. Cylinders and cones are ruled, and the strip between two rulings is
planar, so the coarse faces are still planar; their flat edges across a dropped stretch are
chords of the developed arc while the folded ones are chords of the 3D arc, shorter by about
``turn**2 / 24`` of the cell width (2.6 % for 45 degrees). Along the creases and borders of
the cones where no cylinder runs beside them (a collapsed cylinder, an edge left sharp), the
points are thinned the same way.

Every step is checked where it is made, and what would break is not done: a collapsed strip
that would turn a face over, make it degenerate or leave it visiting a point twice stays; a
merged group of faces that is not a disc, or whose triangles would turn over, be degenerate
(flat or folded) or stretch a side by more than ``SIM_MAX_STRETCH`` of it or
``SIM_MAX_SHIFT`` of its piece, keeps its points; a sliver move is taken only under the same
conditions. So a real mesh's pattern (sharp vertices, skinny faces) gives a valid file: only
where its own faces are too narrow for it are a few triangles left under ``min_angle``.

:func:`simulator_svg_pattern` gives the same coarse pattern as ``simulator.svg`` draws it for
the simulator's SVG import, which reads a target angle only from a mountain or valley line's
opacity and holds every facet (yellow) line flat: the bent ``F`` edges are drawn as mountain
or valley lines of their folded dihedral, the unbent ones as facets, and, as in
``simulator.fold``, there are no tabs or labels.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ..arrays import round_significant, run_next, run_owners, run_starts, split_runs
from ..errors import ParameterError
from .patch import RULED_KINDS, patch_ids, patch_kinds
from .pattern import Annotations, CreasePattern, edge_dihedrals, face_arrays

__all__ = [
    "SIM_MAX_TURN",
    "SIM_MIN_ANGLE",
    "SIM_SVG_FLAT",
    "SIM_SVG_WELD",
    "simulator_pattern",
    "simulator_svg_pattern",
    "triangle_min_angles",
]

#: Largest turn (degrees) of one coarse cylinder cell.
SIM_MAX_TURN = 45.0
#: Smallest corner angle (degrees) a coarse cylinder cell is made wide enough for.
SIM_MIN_ANGLE = 5.0
#: Largest relative change of length, flat to folded, of a side the coarse copy makes (a
#: chord across dropped points): a chord of an arc turning 1.5 ``SIM_MAX_TURN`` is 5.7 %
#: shorter than the arc, one turning ``SIM_MAX_TURN`` 2.6 %.
SIM_MAX_STRETCH = 0.05
#: Largest change of length, flat to folded, of a side the coarse copy makes, as a share of
#: the flat diameter of its piece: a long chord may not take the whole ``SIM_MAX_STRETCH``
#: (a cube's 45-degree cylinder cells change by 0.2 % of their module).
SIM_MAX_SHIFT = 0.005
#: Most rounds of sliver moves (see ``_clean_slivers``); the corpus's meshes stop after 5.
SIM_CLEAN_ROUNDS = 40
#: Pairs of corners times sides that :func:`_diagonals` looks at in one go (a temporary of
#: 8 MB per array).
DIAGONAL_CHUNK = 1 << 20
#: A triangle with a corner under this angle (degrees), flat or folded, is degenerate: its
#: folded normal, and the fold angles beside it, are round-off.
SIM_DEGENERATE = 1e-3
#: Sides made by sliver moves that are looked at one by one before the search tree of the
#: pattern's sides is made again (see ``_FlatSides``).
SIDES_REBUILD = 1024
#: An ``F`` edge whose folded dihedral is under this (degrees) is drawn flat (a facet line) in
#: ``simulator.svg``: the SVG's opacity, ``|angle| / 180`` to 6 decimals, has no smaller step.
SIM_SVG_FLAT = 1e-4
#: Points of ``simulator.svg`` closer than this share of the drawing's size, flat and folded,
#: are welded into one (see :func:`simulator_svg_pattern`): two points left that close flat
#: are apart folded, and any two farther apart flat are at least 10 user units apart (the
#: drawing is 1e6 user units or more wide when such points set its scale), over three times
#: the simulator's merge tolerance.
SIM_SVG_WELD = 1e-5


def triangle_min_angles(points: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(n_faces,) the smallest corner angle (degrees) of each triangle.

    Parameters
    ----------
    points : (n, d) float
    faces : (n_faces, 3) int
    """
    p = np.asarray(points, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]
    u = p[:, [1, 2, 0]] - p  # at each corner, to the next corner and to the one before
    w = p[:, [2, 0, 1]] - p
    if p.shape[2] == 2:
        cross = np.abs(u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0])
    else:
        c = u[..., [1, 2, 0]] * w[..., [2, 0, 1]] - u[..., [2, 0, 1]] * w[..., [1, 2, 0]]
        cross = np.sqrt((c * c).sum(axis=2))
    corner = np.arctan2(cross, (u * w).sum(axis=2))
    return np.degrees(corner.min(axis=1)) if len(p) else np.zeros(0)


def _triangulate(loop: list[int], p: np.ndarray) -> list[list[int]] | None:
    """Counter-clockwise triangles of a simple counter-clockwise flat polygon whose smallest
    angle is the largest of all its triangulations (dynamic programming over diagonals; of
    equal ones, the split at the earliest corner); None when there is none (the polygon is
    not simple, or not counter-clockwise)."""
    k = len(loop)
    if k == 3:
        return [list(loop)]
    q = p[np.asarray(loop)]
    ok = _diagonals(q)
    best = np.full((k, k), -math.inf)
    split = -np.ones((k, k), dtype=np.int64)
    for i in range(k - 1):
        best[i, i + 1] = math.inf
    for gap in range(2, k):  # the chords (i, i + gap) all at once, each from shorter ones
        i = np.arange(k - gap)[:, None]  # (c, 1)
        j = i + gap
        m = i + np.arange(1, gap)[None, :]  # (c, gap - 1): the corners between
        use = ok[i, j] & ok[i, m] & ok[m, j]
        corners = np.stack(np.broadcast_arrays(i, m, j), axis=-1).reshape(-1, 3)
        angle = triangle_min_angles(q, corners).reshape(m.shape)  # each triangle alone
        value = np.where(use, np.minimum(np.minimum(best[i, m], best[m, j]), angle), -math.inf)
        at = np.argmax(value, axis=1)  # the first best: the split at the earliest corner
        top = value[np.arange(len(at)), at]
        found = top > -math.inf
        best[i[found, 0], j[found, 0]] = top[found]
        split[i[found, 0], j[found, 0]] = m[found, at[found]]
    return _split_triangles(loop, split)


def _split_triangles(loop: list[int], split: np.ndarray) -> list[list[int]] | None:
    """The triangles of :func:`_triangulate`'s programme: ``split[i, j]`` (k, k) the corner
    that chord ``(i, j)`` of ``loop`` is split at (-1: none); None when the whole polygon has
    no split (it is not simple)."""
    if split[0, len(loop) - 1] < 0:
        return None
    tris, stack = [], [(0, len(loop) - 1)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        m = int(split[i, j])
        tris.append([loop[i], loop[m], loop[j]])
        stack += [(i, m), (m, j)]
    return tris


def _diagonals(q: np.ndarray) -> np.ndarray:
    """(k, k) bool: which pairs of corners of the counter-clockwise polygon ``q`` (k, 2) the
    triangulation may join: its sides, and the segments inside it (crossing no side, touching
    none between its ends, their midpoint inside)."""
    k = len(q)
    ok = np.zeros((k, k), dtype=bool)
    side = np.arange(k)
    ok[side, (side + 1) % k] = ok[(side + 1) % k, side] = True
    i, j = np.triu_indices(k, 2)
    keep = ~((i == 0) & (j == k - 1))
    i, j = i[keep], j[keep]
    chunk = max(1, DIAGONAL_CHUNK // k)  # pairs at a time: (chunk, k) temporaries
    for lo in range(0, len(i), chunk):
        ii, jj = i[lo : lo + chunk], j[lo : lo + chunk]
        ok[ii, jj] = ok[jj, ii] = _inside(q, ii, jj)
    return ok


def _inside(q: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """(P,) bool: whether the segments from corners ``i`` (P,) to ``j`` (P,) of the
    counter-clockwise polygon ``q`` (k, 2) lie inside it (see :func:`_diagonals`)."""
    k = len(q)
    side = np.arange(k)
    scale = float(np.abs(q).max()) or 1.0
    eps = 1e-12 * scale * scale
    a, b = q[i][:, None, :], q[j][:, None, :]  # (P, 1, 2)
    c, d = q[None, :, :], np.roll(q, -1, axis=0)[None, :, :]  # (1, k, 2)

    def cross(o, u, w):
        return (u[..., 0] - o[..., 0]) * (w[..., 1] - o[..., 1]) - (u[..., 1] - o[..., 1]) * (
            w[..., 0] - o[..., 0]
        )

    d1, d2, d3, d4 = cross(a, b, c), cross(a, b, d), cross(c, d, a), cross(c, d, b)
    ab = b - a
    t = ((c - a) * ab).sum(axis=2) / np.maximum((ab * ab).sum(axis=2), 1e-300)
    near = ((d1 > eps) != (d2 > eps)) & ((d3 > eps) != (d4 > eps))
    near |= (np.abs(d1) <= eps) & (t > 0) & (t < 1)
    s, e = side[None, :], (side[None, :] + 1) % k
    apart = (s != i[:, None]) & (s != j[:, None]) & (e != i[:, None]) & (e != j[:, None])
    inside = ~(near & apart).any(axis=1)
    # the midpoint inside: an odd number of sides cross the ray to its right
    mid = (q[i] + q[j]) / 2
    x, y = q[:, 0][None, :], q[:, 1][None, :]
    xn, yn = np.roll(q[:, 0], -1)[None, :], np.roll(q[:, 1], -1)[None, :]
    crossing = (y > mid[:, 1:2]) != (yn > mid[:, 1:2])
    xs = x + (mid[:, 1:2] - y) * (xn - x) / np.where(yn == y, 1.0, yn - y)
    return inside & (np.count_nonzero(crossing & (xs > mid[:, 0:1]), axis=1) % 2 == 1)


def _components(n_faces: int, pairs: np.ndarray) -> np.ndarray:
    """(n_faces,) component label of each face (or point), joined by the (k, 2) ``pairs``:
    the least index in its component."""
    parent = np.arange(n_faces)

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for a, b in pairs.tolist():
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    return np.array([find(i) for i in range(n_faces)], dtype=np.int64)


def _split_faces(pattern: CreasePattern) -> list[np.ndarray]:
    """The faces of ``pattern`` as a list of int arrays."""
    flat, start = face_arrays(pattern.faces)
    return [flat[a:b].astype(np.int64) for a, b in itertools.pairwise(start)]


def _loop_sides(loops: list) -> np.ndarray:
    """(k, 2) int: every side of the polygons ``loops`` (each a sequence of points), from
    each corner to the next, the last back to the first; the polygons one after another."""
    if not loops:
        return np.zeros((0, 2), dtype=np.int64)
    flat = np.concatenate([np.asarray(f, dtype=np.int64).reshape(-1) for f in loops])
    start = run_starts([len(f) for f in loops])
    return np.stack([flat, flat[run_next(start)]], axis=1)


def _ruled_strips(pattern: CreasePattern, faces: list[np.ndarray], edge_faces: np.ndarray):
    """Each connected cylinder or conical fillet strip, as a tuple: its faces, its points, each
    point's place along the rulings (flat), its rulings (k, 2) (sides of its faces along the
    rulings: developed, a cylinder's rulings are parallel and a fillet's meet at one point),
    which of them are inner edges, each ruling's place across the strip (0 to 1), the strip's
    width across the rulings and their mean length."""
    kind = patch_kinds(pattern.face_patch)
    patch = patch_ids(pattern.face_patch)
    inner = (edge_faces >= 0).all(axis=1)
    fa, fb = edge_faces[:, 0], edge_faces[:, 1]
    ruled = np.isin(kind, ["cylinder", "fillet"])
    same = inner & (patch[fa] == patch[fb]) & ruled[fa]
    label = _components(len(faces), edge_faces[same])
    v2 = pattern.vertices_2d
    key = pattern.edges[:, 0] * len(v2) + pattern.edges[:, 1]  # sorted
    order = np.argsort(label, kind="stable")  # each component's faces, ascending
    cut = np.nonzero(np.diff(label[order]))[0] + 1
    for members in split_runs(order, cut):
        if not len(members) or not ruled[members[0]]:  # a strip's faces are all ruled
            continue
        sides = _loop_sides([faces[f] for f in members.tolist()])
        sides = np.unique(np.sort(sides, axis=1), axis=0)
        pos = np.clip(np.searchsorted(key, sides[:, 0] * len(v2) + sides[:, 1]), 0, len(key) - 1)
        side_inner = same[pos]
        pool = side_inner if side_inner.any() else np.ones(len(sides), dtype=bool)
        a, b = v2[sides[:, 0]], v2[sides[:, 1]]
        d = b - a
        length = np.linalg.norm(d, axis=1)
        unit = d / np.maximum(length, 1e-300)[:, None]
        normal = np.c_[-unit[:, 1], unit[:, 0]]
        verts = np.unique(sides)
        centre = None
        if kind[members[0]] == "fillet" and side_inner.sum() >= 2:
            # the point the rulings meet: least squares over the inner sides' lines
            n_p = normal[pool]
            m = n_p.T @ n_p
            if np.linalg.cond(m) < 1e8:
                centre = np.linalg.solve(m, n_p.T @ np.einsum("ij,ij->i", n_p, a[pool]))
        elif kind[members[0]] == "fillet" and len(members) == 1 and len(verts) == 3:
            # a fillet of one triangle: its two rulings meet at the corner opposite its
            # shortest side (the fillet tapers to that corner)
            short = sides[int(np.argmin(length))]
            centre = v2[int(np.setdiff1d(verts, short)[0])]
        if centre is not None:
            mid = (a + b) / 2
            reach = np.linalg.norm(mid - centre, axis=1)
            off = np.abs(np.einsum("ij,ij->i", normal, centre - a)) < 1e-3 * np.maximum(
                reach, 1e-300
            )
            if not off.any():  # no side runs through it: taken as a strip of parallel rulings
                centre = None
        if centre is not None:
            heading = np.arctan2(*(mid - centre).T[::-1])
            ref = heading[off][0]
            turn = np.mod(heading - ref + np.pi, 2 * np.pi) - np.pi
            place = turn - turn[off].min()
            span = float(np.ptp(turn[off]))
            along = np.linalg.norm(v2[verts] - centre, axis=1)
            width = span * float(length[off].mean())
            at = place[off] / max(span, 1e-300)
        else:
            pick = np.nonzero(pool)[0]
            direction = np.mod(np.arctan2(d[:, 1], d[:, 0]), np.pi)
            parallel = np.abs(np.sin(direction[pick][:, None] - direction[pick][None, :])) < 1e-3
            angle = float(direction[pick[int(np.argmax(parallel.sum(axis=1)))]])
            axis = np.array([math.cos(angle), math.sin(angle)])
            across_axis = np.array([-axis[1], axis[0]])
            off = np.abs(np.sin(direction - angle)) < 1e-2
            across = v2[verts] @ across_axis
            width = float(np.ptp(across))
            along = v2[verts] @ axis
            at = ((a[off] + b[off]) / 2 @ across_axis - across.min()) / max(width, 1e-300)
        yield (
            members,
            verts,
            along,
            sides[off],
            side_inner[off],
            at,
            width,
            float(length[off].mean()),
        )


def _collapse_narrow(pattern: CreasePattern, min_angle: float) -> CreasePattern:
    """``pattern`` with its cylinders too thin for triangles of ``min_angle`` collapsed.

    A strip narrower than ``tan(min_angle)`` times its rulings becomes a single crease (the
    points of each line across the strip merged); a strip whose rulings are shorter than
    ``tan(min_angle)`` times the median side of the face polygons becomes a single curve (the
    two ends of each ruling merged). Merged points move to their mean (flat and folded); the
    strip's faces, and the faces left degenerate, are removed.

    A strip is left as it is where collapsing it would turn a face over, make it degenerate
    (flat or folded) or stretch a side beyond ``SIM_MAX_STRETCH`` or ``SIM_MAX_SHIFT`` when
    folded, leave a face that visits a point twice, or move a side across (or onto) a side it
    shares no point with: such strips are found face by face and the rest are collapsed again
    without them, until no face is broken.
    """
    faces = _split_faces(pattern)
    edge_faces = pattern.faces_beside_edges()
    n = len(pattern.vertices_2d)
    v2 = pattern.vertices_2d
    proposals = []  # per strip: the pairs of points that become one
    bound = math.tan(math.radians(min_angle))
    flat_sides = [
        np.linalg.norm(v2[f] - v2[np.roll(f, -1)], axis=1)
        for f, kind in zip(faces, patch_kinds(pattern.face_patch), strict=True)
        if kind == "face"
    ]
    scale = float(np.median(np.concatenate(flat_sides))) if flat_sides else 0.0
    strips = _ruled_strips(pattern, faces, edge_faces)
    for _, verts, along, rulings, _, _, width, length in strips:
        if width < length * bound:
            # each line of points across the strip (its ends, and any seam between rows of
            # cells) becomes one point
            order = np.argsort(along, kind="stable")
            cut = np.nonzero(np.diff(along[order]) > 0.1 * length)[0] + 1
            lines = np.split(verts[order], cut)
            proposals.append(np.concatenate([np.c_[line[:-1], line[1:]] for line in lines]))
        elif length < scale * bound:
            proposals.append(np.asarray(rulings, dtype=np.int64).reshape(-1, 2))
    active = np.ones(len(proposals), dtype=bool)
    proposed = np.concatenate([np.zeros((0, 2), dtype=np.int64), *proposals])
    proposer = run_owners([len(p) for p in proposals])  # (k,) the strip of each pair
    verdicts: dict[tuple, bool] = {}  # a merged polygon's place -> broken
    shift = _shift_bound(pattern)
    while True:
        pairs = [p for p, on in zip(proposals, active, strict=True) if on]
        rep = _components(n, np.concatenate([np.zeros((0, 2), dtype=np.int64), *pairs]))
        merged = _merged_faces(pattern, faces, rep, shift, verdicts)
        if merged[-1] is not None:
            broken = np.unique(rep[merged[-1]])
        else:  # the merged points' labels
            broken = _crossed(merged[0], merged[2], np.bincount(rep, minlength=n) > 1)
            if broken is None:
                break
        # the strips that merged a point of a broken face go back
        touched = np.isin(rep[proposed], broken).any(axis=1)
        hit = (np.bincount(proposer[touched], minlength=len(proposals)) > 0) & active
        if not hit.any():  # cannot happen: a broken face has a merged point
            break
        active &= ~hit
    v2, v3, out_faces, out_patch, out_piece, _ = merged
    if len(out_faces) == len(faces) and (rep == np.arange(n)).all():
        return pattern
    keep = np.unique(np.concatenate([np.asarray(f) for f in out_faces]))
    new_index = -np.ones(n, dtype=np.int64)
    new_index[keep] = np.arange(len(keep))
    return CreasePattern(
        v2[keep],
        v3[keep],
        [new_index[np.asarray(f)] for f in out_faces],
        out_patch,
        np.array(out_piece, dtype=np.int64),
        pattern.piece_vertex,
        annotations=pattern.annotations,
    )


def _crossed(v2: np.ndarray, loops: list, moved: np.ndarray):
    """The ends of the sides of ``loops`` (faces of merged points) at a ``moved`` point that
    cross or touch, flat, a side they share no point with, and of the sides they meet (a
    collapsed strip's crease cut across a thin notch of its piece: the slit between two
    modules glued in a net); None when none do."""
    import shapely

    if not loops:
        return None
    sides = np.unique(np.sort(_loop_sides(loops), axis=1), axis=0)
    mine = np.nonzero(moved[sides].any(axis=1))[0]
    if not len(mine):
        return None
    lines = shapely.linestrings(v2[sides])
    a, b = shapely.STRtree(lines).query(lines[mine], predicate="intersects")
    a = mine[a]
    apart = _apart(sides[a], sides[b])
    if not apart.any():
        return None
    return np.unique(sides[np.r_[a[apart], b[apart]]])


def _merged_faces(
    pattern: CreasePattern,
    faces: list[np.ndarray],
    rep: np.ndarray,
    shift: np.ndarray,
    verdicts: dict,
):
    """The points of ``pattern`` merged into their groups ``rep`` (n,) (each point moved to
    its group's mean, flat and folded): (flat positions, folded positions, faces, their
    patches, their pieces, and the points of the faces that broke, or None when none did).

    A face left with fewer than three distinct points is dropped; one that visits a point
    twice, or whose triangles (see :func:`_triangles`) are turned over, degenerate flat or
    folded, or stretched beyond ``SIM_MAX_STRETCH`` or ``shift`` (n,) at its first point (see
    :func:`_shift_bound`), is broken. ``verdicts`` keeps the verdict on each polygon of more
    than three points, by its points and their places, for the next call."""
    n = len(rep)
    count = np.bincount(rep, minlength=n)
    v2 = np.zeros((n, 2))
    v3 = np.zeros((n, 3))
    np.add.at(v2, rep, pattern.vertices_2d)
    np.add.at(v3, rep, pattern.vertices_3d)
    used = count > 0
    v2[used] /= count[used, None]
    v3[used] /= count[used, None]
    moved = count[rep] > 1
    loops: list[list[int] | None] = []  # per face: its loop, None when it is dropped
    broken = np.zeros(len(faces), dtype=bool)
    moved_tri = []  # the faces that are moved triangles, checked all at once below
    for f, face in enumerate(faces):
        loop = rep[face].tolist()
        if moved[face].any():
            loop = [v for i, v in enumerate(loop) if v != loop[i - 1]]  # cyclic duplicates
            if len(set(loop)) < 3:
                loop = None
            elif len(set(loop)) < len(loop):
                broken[f] = True
            elif len(loop) == 3:
                moved_tri.append(f)
            else:
                key = (tuple(loop), v2[loop].tobytes(), v3[loop].tobytes())
                if key not in verdicts:
                    tris = _triangles(loop, v2, v3, SIM_MAX_STRETCH, shift[loop[0]])
                    verdicts[key] = tris is None
                broken[f] = verdicts[key]
        loops.append(loop)
    if moved_tri:
        tri = np.array(moved_tri, dtype=np.int64)
        corners = np.array([loops[f] for f in moved_tri], dtype=np.int64)
        quality = _triangle_quality(v2[corners], v3[corners], SIM_MAX_STRETCH, shift[corners[:, 0]])
        broken[tri] = quality < SIM_DEGENERATE
    keep = [f for f, loop in enumerate(loops) if loop is not None and not broken[f]]
    out_faces = [loops[f] for f in keep]
    out_patch = [pattern.face_patch[f] for f in keep]
    out_piece = [int(pattern.face_piece[f]) for f in keep]
    bad = [faces[f] for f in np.nonzero(broken)[0].tolist()]
    return v2, v3, out_faces, out_patch, out_piece, np.concatenate(bad) if bad else None


def _triangles(
    loop: list[int],
    v2: np.ndarray,
    v3: np.ndarray,
    max_stretch: float = math.inf,
    max_shift: float = math.inf,
) -> list[list[int]] | None:
    """The triangles of the flat polygon ``loop`` (see :func:`_triangulate`), or None when it
    has none, or one of them is turned over or degenerate (a corner under ``SIM_DEGENERATE``
    degrees, flat or folded), or a side of them changes length when folded by more than
    ``max_stretch`` of its flat length or more than ``max_shift`` (its sides along ``loop``
    counted too)."""
    tris = _triangulate(loop, v2)
    if tris is None:
        return None
    t = np.asarray(tris, dtype=np.int64)
    if _triangle_quality(v2[t], v3[t], max_stretch, max_shift).min() < SIM_DEGENERATE:
        return None
    return tris


def _shift_bound(pattern: CreasePattern) -> np.ndarray:
    """(n,) the most a side at each point may change length, flat to folded:
    ``SIM_MAX_SHIFT`` times the flat diameter (bounding box diagonal) of the point's piece."""
    n = len(pattern.vertices_2d)
    flat, start = face_arrays(pattern.faces)
    piece = np.zeros(n, dtype=np.int64)
    piece[flat] = np.repeat(np.asarray(pattern.face_piece, dtype=np.int64), np.diff(start))
    k = int(piece.max()) + 1 if n else 0
    lo, hi = np.full((k, 2), np.inf), np.full((k, 2), -np.inf)
    np.minimum.at(lo, piece[flat], pattern.vertices_2d[flat])
    np.maximum.at(hi, piece[flat], pattern.vertices_2d[flat])
    return SIM_MAX_SHIFT * np.linalg.norm(hi - lo, axis=1)[piece]


def _triangle_quality(
    p2: np.ndarray, p3: np.ndarray, max_stretch: float, max_shift: float | np.ndarray = math.inf
) -> np.ndarray:
    """(k,) the smallest corner angle (degrees), flat or folded, of the triangles with
    corners ``p2`` (k, 3, 2) flat and ``p3`` (k, 3, 3) folded; -inf where one turns over in
    the flat layout (or has no area) or one of its sides changes length, flat to folded, by
    more than ``max_stretch`` of its flat length or by more than ``max_shift`` (a length, or
    (k,) one per triangle)."""
    u, w = p2[:, 1] - p2[:, 0], p2[:, 2] - p2[:, 0]
    corners = np.arange(3 * len(p2)).reshape(-1, 3)
    quality = np.minimum(
        triangle_min_angles(p2.reshape(-1, 2), corners),
        triangle_min_angles(p3.reshape(-1, 3), corners),
    )
    bad = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0] <= 0
    if max_stretch < math.inf:
        d2, d3 = p2[:, [1, 2, 0]] - p2, p3[:, [1, 2, 0]] - p3
        l2, l3 = np.sqrt((d2 * d2).sum(axis=2)), np.sqrt((d3 * d3).sum(axis=2))
        change = np.abs(l2 - l3)
        bad |= (change > max_stretch * l2).any(axis=1)
        bad |= change.max(axis=1) > max_shift
    return np.where(bad, -math.inf, quality)


def _dropped_rulings(
    pattern: CreasePattern,
    faces: list[np.ndarray],
    edge_faces: np.ndarray,
    dihedral: np.ndarray,
    droppable: np.ndarray,
    max_turn: float,
    min_angle: float,
) -> np.ndarray:
    """(n,) bool: the vertices of the cylinder rulings to drop (see :func:`simulator_pattern`).

    Each strip keeps the inner rulings nearest to ``cells - 1`` equal steps across it, with
    ``cells`` the fewest cells that turn at most ``max_turn`` each, but no more cells than
    keep each one ``tan(min_angle)`` times its ruling length wide.
    """
    v2 = pattern.vertices_2d
    gone = np.zeros(len(v2), dtype=bool)
    bound = math.tan(math.radians(min_angle))
    strips = _ruled_strips(pattern, faces, edge_faces)
    key = pattern.edges[:, 0] * len(v2) + pattern.edges[:, 1]  # sorted
    for _, _, _, rulings, is_inner, at, width, length in strips:
        if not is_inner.any():
            continue
        turn = _strip_turn(key, len(v2), rulings[is_inner], at[is_inner], dihedral)
        by_turn = math.ceil(turn / max_turn - 1e-9) if turn > 0 else 1
        by_width = math.floor(width / (1.5 * length * bound)) if bound > 0 else len(rulings) + 1
        cells = max(1, min(by_turn, by_width))
        inner_at = at[is_inner]
        chosen = {float(inner_at[np.argmin(np.abs(inner_at - k / cells))]) for k in range(1, cells)}
        near = np.abs(at[:, None] - np.array(sorted(chosen) or [np.inf])[None, :]) < 1e-6
        kept = ~is_inner | near.any(axis=1)
        # the strip's points: ``ends`` its rulings' ends among them
        points, ends = np.unique(rulings, return_inverse=True)
        ends = ends.reshape(rulings.shape)
        drop = np.zeros(len(points), dtype=bool)
        drop[ends[~kept].ravel()] = True
        drop[ends[kept].ravel()] = False
        # a ruling goes only when both its ends may go (a fillet's apex, on many rulings,
        # stays and does not count)
        hub = np.bincount(ends.ravel(), minlength=len(points)) >= 3
        drop[hub] = False
        free = droppable[points] | hub
        drop[ends[~free[ends].all(axis=1)].ravel()] = False
        half = (drop | hub)[ends].all(axis=1)
        drop[ends[drop[ends].any(axis=1) & ~half].ravel()] = False
        gone[points[drop]] = True
    return gone


def _strip_turn(
    key: np.ndarray, n: int, rulings: np.ndarray, at: np.ndarray, dihedral: np.ndarray
) -> float:
    """The total bend (degrees) of a strip across its inner ``rulings`` (at places ``at``
    across it): the sum of their dihedrals, one ruling per place (a strip may have rows).
    ``key`` (n_edges,) the pattern's edges as ``lo * n + hi`` (``n`` its points), ascending,
    and ``dihedral`` (n_edges,) theirs."""
    lo, hi = rulings.min(axis=1), rulings.max(axis=1)
    bends = np.abs(dihedral[np.searchsorted(key, lo * n + hi)])  # pattern edges are sorted
    order = np.argsort(at, kind="stable")
    first = order[np.r_[True, np.diff(at[order]) > 1e-6]]
    return float(bends[first].sum())


def _dropped_crease_points(
    pattern: CreasePattern, faces: list[np.ndarray], min_angle: float
) -> np.ndarray:
    """(n,) bool: points to drop along the creases and borders of the cones where no cylinder
    or fillet runs beside them (a cone meeting another cone, a face piece, or the border
    where a cylinder was collapsed or an edge left sharp): along each run of such points, the
    points nearest to equal steps of about ``tan(3 min_angle)`` times the distance to the
    nearer apex are kept."""
    n = len(pattern.vertices_2d)
    v2 = pattern.vertices_2d
    gone = np.zeros(n, dtype=bool)
    names = pattern.face_patch
    kind = patch_kinds(names)
    cone = kind == "cone"
    corners = np.concatenate(faces) if faces else np.zeros(0, dtype=np.int64)
    face_of = run_owners([len(f) for f in faces])
    on_cone = np.zeros(n, dtype=bool)
    on_cone[corners[cone[face_of]]] = True
    on_ruled = np.zeros(n, dtype=bool)
    on_ruled[corners[np.isin(kind, ["cylinder", "fillet"])[face_of]]] = True
    cones_at: dict[int, set[str]] = {}
    for v, f in zip(corners.tolist(), face_of.tolist(), strict=True):
        if cone[f]:
            cones_at.setdefault(v, set()).add(names[f])
    feature = np.isin(pattern.edge_assignment, ["M", "V", "B"])
    pairs = pattern.edges[feature]
    fdeg = np.bincount(pairs.ravel(), minlength=n)
    candidate = on_cone & ~on_ruled & (fdeg == 2)
    # the apex of each cone patch: the corner its faces share most
    members: dict[str, list[np.ndarray]] = {}
    for f in np.nonzero(cone)[0].tolist():
        members.setdefault(names[f], []).append(faces[f])
    apex = {name: int(np.bincount(np.concatenate(m)).argmax()) for name, m in members.items()}
    link = pairs[candidate[pairs].any(axis=1)]
    neighbours: dict[int, list[int]] = {}
    for a, b in link.tolist():
        neighbours.setdefault(a, []).append(b)
        neighbours.setdefault(b, []).append(a)
    seen = np.zeros(n, dtype=bool)
    tan = math.tan(math.radians(3 * min_angle))
    for start_v in np.nonzero(candidate)[0].tolist():
        if seen[start_v]:
            continue
        # the run through start_v: walk along its two feature edges to the ends of the run
        # (points that are not candidates), or around it back to start_v (a closed run)
        sides = []
        for first in neighbours[start_v][:2]:
            path, prev, v = [start_v], start_v, first
            while candidate[v] and v != start_v and len(path) <= n:
                path.append(v)
                prev, v = v, next(w for w in neighbours[v] if w != prev)
            sides.append([*path, v])
        closed = sides[0][-1] == start_v
        path = sides[0] if closed or len(sides) < 2 else sides[1][::-1] + sides[0][1:]
        inner = [w for w in path if candidate[w]]
        seen[inner] = True
        if len(inner) < 2:
            continue
        points = v2[path]
        step = np.linalg.norm(np.diff(points, axis=0), axis=1)
        at = np.concatenate([[0.0], np.cumsum(step)])
        total = float(at[-1])
        radius = min(
            float(np.linalg.norm(v2[inner[len(inner) // 2]] - v2[apex[name]]))
            for name in cones_at[inner[len(inner) // 2]]
        )
        cells = max(1, math.ceil(total / max(radius * tan, 1e-300)))
        keep = {int(np.argmin(np.abs(at - k * total / cells))) for k in range(1, cells)}
        for i, w in enumerate(path):
            if candidate[w] and i not in keep:
                gone[w] = True
    return gone


def _clean_slivers(
    pattern: CreasePattern, min_angle: float, rounds: int = SIM_CLEAN_ROUNDS
) -> CreasePattern:
    """``pattern`` (triangles) with its triangles under ``min_angle`` (flat or folded)
    improved where a local move does it: a short side collapsed (its end that is not on a
    crease or border, or any end along a crease or border through the side, moved onto the
    other end: every point keeps its exact flat and folded position) or, inside a smooth
    patch, the longest side flipped. A move is taken when the smallest angle of the triangles
    it changes grows, none turns over and no side of them changes length when folded by more
    than ``SIM_MAX_STRETCH`` of it or ``SIM_MAX_SHIFT`` of its piece. Each round tries every
    sliver, worst first, on the pattern as the moves before left it; the creases and borders
    are derived again between rounds, until a round makes no move or after ``rounds``
    rounds."""
    v2, v3 = pattern.vertices_2d.copy(), pattern.vertices_3d.copy()
    tri = np.array(list(pattern.faces), dtype=np.int64).reshape(-1, 3)
    patch = list(pattern.face_patch)
    piece = np.asarray(pattern.face_piece).copy()
    for _ in range(rounds):
        current = CreasePattern(v2, v3, tri, patch, piece, pattern.piece_vertex)
        quality = np.minimum(triangle_min_angles(v2, tri), triangle_min_angles(v3, tri))
        bad = np.nonzero(quality < min_angle)[0]
        if not len(bad):
            break
        feature = np.isin(current.edge_assignment, ["M", "V", "B"])
        n = len(v2)
        key = current.edges[:, 0] * n + current.edges[:, 1]
        fdeg = np.bincount(current.edges[feature].ravel(), minlength=n)
        is_feature = dict(zip(key.tolist(), feature.tolist(), strict=True))
        shift = _shift_bound(current)
        alive = np.ones(len(tri), dtype=bool)
        at: list[set[int]] = [set() for _ in range(n)]  # each point's live faces
        for f, corners in enumerate(tri.tolist()):
            for v in corners:
                at[v].add(f)
        moves = 0
        sides = _FlatSides(tri, v2, current.edges[current.edge_assignment == "B"], at)
        live = _Triangles(tri, alive, at, v2, v3, is_feature, fdeg, patch, shift, sides)
        for t in bad[np.argsort(quality[bad], kind="stable")].tolist():
            if not alive[t]:
                continue
            move = _best_move(live, t, min_angle)
            if move is None:
                continue
            moves += 1
            gone = _triangle_sides(tri[move[0]])  # the changed triangles' sides before
            _apply_move(live, move)
            sides.add(gone, _new_sides(tri, move), tri, alive)
        tri, patch = tri[alive], [p for p, a in zip(patch, alive, strict=True) if a]
        piece = piece[alive]
        if not moves:
            break
    used = np.unique(tri)
    new_index = -np.ones(len(v2), dtype=np.int64)
    new_index[used] = np.arange(len(used))
    return CreasePattern(
        v2[used],
        v3[used],
        new_index[tri],
        patch,
        piece,
        pattern.piece_vertex,
        annotations=pattern.annotations,
    )


@dataclass
class _Triangles:
    """The triangles of one round of :func:`_clean_slivers`, which its moves change in place.

    Attributes
    ----------
    tri : (m, 3) int
        The triangles (a removed one keeps its corners, and ``alive`` is False).
    alive : (m,) bool
    at : list of set of int
        Each point's live triangles.
    v2, v3 : (n, 2), (n, 3) float
        The points, flat and folded.
    is_feature : dict of int to bool
        Whether the edge keyed ``lo * n + hi`` is a crease or a border.
    fdeg : (n,) int
        How many creases and borders meet at each point.
    patch : list of str
        Each triangle's patch name.
    shift : (n,) float
        The most a side at each point may change length, flat to folded
        (:func:`_shift_bound`).
    flat : _FlatSides
        The pattern's sides in the flat layout, which no collapse may cross.
    """

    tri: np.ndarray
    alive: np.ndarray
    at: list
    v2: np.ndarray
    v3: np.ndarray
    is_feature: dict
    fdeg: np.ndarray
    patch: list
    shift: np.ndarray
    flat: _FlatSides | None = None


def _apply_move(live: _Triangles, move) -> None:
    """Make the move of :func:`_best_move` on the triangles and keep the faces at each point
    (``at``), the creases and borders (``is_feature``) and their count at each point
    (``fdeg``) up to date: an edge that a collapse makes of two is a crease or border when
    either of them was; a flip's new diagonal lies inside one smooth patch."""
    tri, alive, at, v2, v3 = live.tri, live.alive, live.at, live.v2, live.v3
    is_feature, fdeg, n = live.is_feature, live.fdeg, len(live.v2)
    changed, new, moved, collapse = move
    ring = {v for f in changed for v in tri[f].tolist()}
    if moved is not None:
        v, p2, p3 = moved
        v2[v], v3[v] = p2, p3
    for f, corners in zip(changed, new, strict=True):
        for v in tri[f].tolist():
            at[v].discard(f)
        if corners is None:
            alive[f] = False
        else:
            tri[f] = corners
            for v in tri[f].tolist():
                at[v].add(f)

    def edge(a: int, b: int) -> int:
        return min(a, b) * n + max(a, b)

    if collapse is not None:
        go, keep = collapse
        for x in ring - {go, keep}:
            merged = is_feature.pop(edge(go, x), False) or is_feature.get(edge(keep, x), False)
            is_feature[edge(keep, x)] = merged
        is_feature.pop(edge(go, keep), None)
        fdeg[go] = 0
        ring.discard(go)
    else:
        c = [tri[f].tolist() for f in changed]
        old = set(c[0]) & set(c[1])  # the new diagonal's ends
        is_feature[edge(*old)] = False
        a, b = ring - old
        is_feature.pop(edge(a, b), None)
    for v in ring:
        near = {x for f in at[v] for x in tri[f].tolist()} - {v}
        fdeg[v] = sum(is_feature.get(edge(v, x), False) for x in near)


def _triangle_sides(tri: np.ndarray) -> np.ndarray:
    """(3k, 2) the sides of the triangles ``tri`` (k, 3), each with its lower point first:
    the first sides of all triangles, then the second, then the third."""
    return np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)


def _apart(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k,) bool: which pairs of sides ``a`` (k, 2) and ``b`` (k, 2) share no point."""
    return (a[:, :, None] != b[:, None, :]).all(axis=(1, 2))


class _FlatSides:
    """The sides of a triangulation's flat layout, to look up which sides a new one crosses
    (a collapse along a border moves the border, which can then cut across a thin notch of
    its piece): the sides as they were when they were last taken (at the start and after
    every ``SIDES_REBUILD`` sides made), each where its ends were then, and a list of the
    sides made since.

    The sides taken are kept in two search trees: one of all the sides taken at some time,
    each with a flag saying whether it is still one of the sides taken last (a side no
    triangle has any more, or one whose end has moved since, is not: a side whose end moved
    is taken again where it is now), and a smaller one of the sides taken since the large
    tree was made, made again each time; the large one is made again, of the sides taken
    last alone, when the small one holds a quarter of its sides. Both give the sides that a
    single tree of the sides taken last gives, at a cost that grows with the sides made
    since instead of with all of them."""

    def __init__(self, tri: np.ndarray, v2: np.ndarray, border: np.ndarray, at: list):
        self.v2 = v2
        self.at = at  # each point's live triangles, as the moves keep them
        self.on_border = np.zeros(len(v2), dtype=bool)
        self.on_border[np.asarray(border, dtype=np.int64).ravel()] = True
        self.rebuild(tri)

    def rebuild(self, tri: np.ndarray) -> None:
        """Start again from the triangles ``tri`` (k, 3): every side in the large tree."""
        import shapely

        n = len(self.v2)
        ends = _triangle_sides(tri)
        key = np.unique(ends[:, 0] * n + ends[:, 1])
        self.sides = np.stack([key // n, key % n], axis=1)
        self.tree = shapely.STRtree(shapely.linestrings(self.v2[self.sides]))
        self.taken = np.ones(len(key), dtype=bool)  # per side of both trees: taken last
        self.entry = dict(zip(key.tolist(), range(len(key)), strict=True))  # key -> side
        self.recent = np.zeros((0, 2), dtype=np.int64)  # the small tree's sides
        self.recent_lines = np.zeros(0, dtype=object)
        self.recent_tree = None
        self.drawn = self.v2.copy()  # the points where the sides taken last have them
        self.touched: set[int] = set()  # keys of the sides made or unmade since
        self.added = np.zeros((0, 2), dtype=np.int64)

    def add(self, gone: np.ndarray, sides: np.ndarray, tri: np.ndarray, alive: np.ndarray):
        """The sides (k, 2) of the triangles a move changed, ``gone`` as they were and
        ``sides`` as they are now; ``tri`` (m, 3) the triangles and ``alive`` (m,) bool
        which of them are live, whose sides are taken again when the list is long."""
        sides = np.asarray(sides, dtype=np.int64).reshape(-1, 2)
        n = len(self.v2)
        self.touched.update((np.r_[gone.reshape(-1, 2), sides] @ [n, 1]).tolist())
        self.added = np.concatenate([self.added, sides])
        if len(self.added) > SIDES_REBUILD:
            self._retake(tri, alive)

    def _retake(self, tri: np.ndarray, alive: np.ndarray) -> None:
        """Take the sides of the live triangles again (the sides made or unmade since, and
        those at a point moved since, looked at one by one)."""
        import shapely

        n, at = len(self.v2), self.at
        moved = np.flatnonzero((self.v2 != self.drawn).any(axis=1))
        self.drawn[moved] = self.v2[moved]
        keys = self.touched
        for v in moved.tolist():  # every side at a moved point: taken where it is now
            keys.update(min(v, x) * n + max(v, x) for f in at[v] for x in tri[f].tolist())
        moved = set(moved.tolist())
        new = []
        for k in sorted(keys):
            a, b = divmod(k, n)
            live = a != b and bool(at[a] & at[b])  # a live triangle has both ends
            e = self.entry.get(k)
            if e is not None and (not live or a in moved or b in moved):
                self.taken[e] = False
                del self.entry[k]
                e = None
            if live and e is None:
                self.entry[k] = len(self.taken) + len(new)
                new.append(k)
        self.touched = set()
        self.added = np.zeros((0, 2), dtype=np.int64)
        if len(self.recent) + len(new) > max(16 * SIDES_REBUILD, len(self.sides) // 4):
            self.rebuild(tri[alive])
            return
        if not new:
            return
        key = np.array(new, dtype=np.int64)
        sides = np.stack([key // n, key % n], axis=1)
        self.taken = np.concatenate([self.taken, np.ones(len(new), dtype=bool)])
        self.recent = np.concatenate([self.recent, sides])
        self.recent_lines = np.concatenate([self.recent_lines, shapely.linestrings(self.v2[sides])])
        self.recent_tree = shapely.STRtree(self.recent_lines)

    def _taken_pairs(self, new: np.ndarray, lines) -> list:
        """(new side, side taken last) pairs whose lines meet, from both trees."""
        i, j = self.tree.query(lines, predicate="intersects")
        ok = self.taken[j]
        out = [(new[i[ok]], self.sides[j[ok]])]
        if self.recent_tree is not None:
            i, j = self.recent_tree.query(lines, predicate="intersects")
            ok = self.taken[len(self.sides) + j]
            out.append((new[i[ok]], self.recent[j[ok]]))
        return out

    def crossed(self, new: np.ndarray, gone: int, moved=None) -> bool:
        """Whether a side of ``new`` (k, 2) crosses or touches, flat, a side it shares no
        point with (sides at ``gone``, the point a collapse removes, do not count); with
        ``moved`` (vertex, flat position, folded position), the sides of ``new`` at that
        vertex are looked at with it in its new place."""
        import shapely

        p = self.v2[new]  # (k, 2, 2)
        if moved is not None:
            p = np.where((new == moved[0])[:, :, None], moved[1], p)
        lines = shapely.linestrings(p)
        others = self._taken_pairs(new, lines)
        if len(self.added):  # boxes first, then the segments whose boxes meet
            q = self.v2[self.added]  # (m, 2, 2)
            lo, hi, lo2, hi2 = p.min(axis=1), p.max(axis=1), q.min(axis=1), q.max(axis=1)
            box = (lo[:, None] <= hi2[None]).all(axis=2) & (lo2[None] <= hi[:, None]).all(axis=2)
            i, j = np.nonzero(box)
            hit = shapely.intersects(lines[i], shapely.linestrings(q[j]))
            others.append((new[i[hit]], self.added[j[hit]]))
        return any((_apart(a, b) & (b != gone).all(axis=1)).any() for a, b in others)


def _new_sides(tri: np.ndarray, move) -> np.ndarray:
    """(k, 2) the sides of the faces a move of :func:`_best_move` changed, as they are now."""
    changed, new, _, _ = move
    kept = [f for f, corners in zip(changed, new, strict=True) if corners is not None]
    return _triangle_sides(tri[kept].reshape(-1, 3))


def _best_move(live: _Triangles, t: int, min_angle: float):
    """The best collapse or flip for the sliver ``t`` (see :func:`_clean_slivers`): the
    changed faces, their new corners (None: removed), the point moved (None, or (vertex,
    flat, folded position)) and, for a collapse, the point removed and the one that takes
    its place (None for a flip); None when nothing improves.

    A side shorter than ``tan(min_angle)`` times the longest, whose ends both lie on creases
    or borders, may also be collapsed to its midpoint (the one move that moves a point). With
    ``live.flat`` (:class:`_FlatSides`), a collapse whose sides would cross a side of the
    pattern in the flat layout is not taken."""
    tri, at, v2, v3, shift = live.tri, live.at, live.v2, live.v3, live.shift
    is_feature, fdeg, patch, flat = live.is_feature, live.fdeg, live.patch, live.flat
    n = len(v2)
    corners = tri[t].tolist()
    around = {v: np.array(sorted(at[v]), dtype=np.int64) for v in corners}
    best, best_q = None, _move_quality(tri[[t]], v2, v3, None, None)
    sides = [(corners[i], corners[(i + 1) % 3]) for i in range(3)]
    lengths = [float(np.linalg.norm(v2[a] - v2[b])) for a, b in sides]
    short = math.tan(math.radians(min_angle)) * max(lengths)
    tries = []  # (keep, go, a, b, along a crease or border, side length)
    for (a, b), length in zip(sides, lengths, strict=True):
        edge_feature = is_feature.get(min(a, b) * n + max(a, b), False)
        for keep, go in ((a, b), (b, a), (min(a, b), -1)):
            tries.append((keep, go, a, b, edge_feature, length))
    for go in corners:  # a corner on a crease or border may slide along it off the sliver
        if fdeg[go] == 2:
            ring = {x for f in around[go].tolist() for x in tri[f].tolist()} - set(corners)
            for keep in sorted(ring):
                if is_feature.get(min(go, keep) * n + max(go, keep), False):
                    tries.append((keep, go, keep, go, True, 0.0))
    candidates = []  # (move, its triangles, moved): every collapse the link condition allows
    for keep, go, a, b, edge_feature, length in tries:
        moved = None
        if go == -1:  # both ends on features: the midpoint, for a short side only
            if not (fdeg[a] and fdeg[b] and length < short):
                continue
            go = max(a, b)
            moved = (keep, (v2[a] + v2[b]) / 2, (v3[a] + v3[b]) / 2)
        elif fdeg[go] and not edge_feature:
            continue
        faces = around[go]
        new = []
        for f in faces.tolist():
            c = tri[f]
            new.append(None if keep in c else np.where(c == go, keep, c))
        kept = [c for c in new if c is not None]
        if not kept:
            continue
        keep_faces = np.array(sorted(at[keep]), dtype=np.int64)
        if moved is not None:  # the faces of keep move too
            for f in keep_faces.tolist():
                if f not in faces:
                    faces = np.append(faces, f)
                    new.append(tri[f].copy())
            kept = [c for c in new if c is not None]
        k = np.array(kept)
        # the link condition: keep and go share exactly the corners of the faces removed
        ring_go = set(tri[around[go]].ravel().tolist()) - {go}
        ring_keep = set(tri[keep_faces].ravel().tolist()) - {keep}
        if len(ring_go & ring_keep) != sum(c is None for c in new):
            continue
        candidates.append(((faces.tolist(), new, moved, (go, keep)), k, moved))
    # the flip of the longest side inside one smooth patch, when there is one
    flip = None
    a, b = sides[int(np.argmax(lengths))]
    if not is_feature.get(min(a, b) * n + max(a, b), True):
        c = next(v for v in corners if v not in (a, b))
        other = [
            f
            for f in np.intersect1d(around[a], around[b]).tolist()
            if f != t and patch[f] == patch[t]
        ]
        if len(other) == 1:
            o = other[0]
            d = next(v for v in tri[o].tolist() if v not in (a, b))
            new = [np.array([c, a, d]), np.array([c, d, b])]
            i = corners.index(a)
            if corners[(i + 1) % 3] != b:  # keep the orientation of t
                new = [np.array([c, d, a]), np.array([c, b, d])]
            flip = ([t, o], new, None, None)
            candidates.append((flip, np.array(new), None))
    # every candidate's quality in one call (each triangle's is its own: the same numbers)
    qualities = _move_qualities([(k, moved) for _, k, moved in candidates], v2, v3, shift)
    if flip is not None:
        candidates, flip_q = candidates[:-1], qualities.pop()
    collapses = [  # (quality, move, its triangles), each better than the sliver
        (q, move, k) for q, (move, k, _) in zip(qualities, candidates, strict=True) if q > best_q
    ]
    # the best collapse whose sides cross none of the pattern's
    for q, move, k in sorted(collapses, key=lambda c: -c[0]):
        go, keep = move[3]
        if flat is None or not _crosses(flat, k, keep, go, move[2]):
            best, best_q = move, q
            break
    if flip is not None and flip_q > best_q:
        best, best_q = flip, flip_q
    return best


def _crosses(sides: _FlatSides, k: np.ndarray, keep: int, go: int, moved) -> bool:
    """Whether a collapse's triangles ``k`` (j, 3) have a side at ``keep`` that crosses a
    side of the pattern flat (see :class:`_FlatSides`); a moved ``keep`` is looked at in
    its new place. A point ``go`` inside its piece leaves its ring as it was, which the new
    triangles, all counter-clockwise, fill: only a collapse of a border point (or a move)
    can cross."""
    if moved is None and not sides.on_border[go]:
        return False
    e = _triangle_sides(k)
    return sides.crossed(np.unique(e[(e == keep).any(axis=1)], axis=0), go, moved)


def _move_quality(
    k: np.ndarray, v2: np.ndarray, v3: np.ndarray, moved: tuple | None, shift: np.ndarray | None
) -> float:
    """The smallest corner angle (degrees), flat or folded, of the triangles ``k`` (j, 3)
    with ``moved`` (None, or (vertex, flat, folded position)) in its new place; -inf when one
    of them turns over in the flat layout or one of their sides changes length, flat to
    folded, by more than ``SIM_MAX_STRETCH`` of its flat length or ``shift`` (n,) at its first
    corner (see :func:`_triangle_quality`; ``shift`` None: length changes are not looked at)."""
    return _move_qualities([(k, moved)], v2, v3, shift)[0]


def _move_qualities(
    moves: list, v2: np.ndarray, v3: np.ndarray, shift: np.ndarray | None
) -> list[float]:
    """:func:`_move_quality` of many moves at once: ``moves`` a list of (triangles (j, 3),
    moved); their triangles in one call of :func:`_triangle_quality` (each triangle's
    quality is computed alone, so the numbers are those of one call per move)."""
    if not moves:
        return []
    k = np.concatenate([m[0] for m in moves])
    p2, p3 = v2[k], v3[k]
    start = run_starts([len(m[0]) for m in moves])
    for (tris, moved), lo, hi in zip(moves, start[:-1].tolist(), start[1:].tolist(), strict=True):
        if moved is not None:
            at = (tris == moved[0])[:, :, None]
            p2[lo:hi] = np.where(at, moved[1], p2[lo:hi])
            p3[lo:hi] = np.where(at, moved[2], p3[lo:hi])
    if shift is None:
        quality = _triangle_quality(p2, p3, math.inf)
    else:
        quality = _triangle_quality(p2, p3, SIM_MAX_STRETCH, shift[k[:, 0]])
    return np.minimum.reduceat(quality, start[:-1]).tolist()


def simulator_pattern(
    pattern: CreasePattern,
    *,
    max_turn: float = SIM_MAX_TURN,
    min_angle: float = SIM_MIN_ANGLE,
    digits: int | None = None,
) -> CreasePattern:
    """A coarse triangulated copy of ``pattern`` that Origami Simulator folds.

    Parameters
    ----------
    pattern : CreasePattern
        A checked pattern (see :func:`~filletfold.surface.validate.validated_faces`).
    max_turn : float
        Largest turn (degrees) of a coarse cylinder cell; fewer cells where a cell would be
        narrower than ``tan(min_angle)`` times its ruling length.
    min_angle : float
        Smallest corner angle (degrees) that a cylinder cell is kept wide enough for; a
        cylinder narrower than that in one cell becomes a single crease (the points at each of
        its ends merged into their mean).
    digits : int, optional
        The significant digits of the file it goes to: its points are rounded so, before its
        edges' fold angles are measured (a thin triangle's dihedral moves by micro-degrees
        when its corners are rounded to the file's digits). None: not rounded.

    Returns
    -------
    CreasePattern
        Triangles only, on (a subset of) the vertices of ``pattern`` (renumbered in their
        order), with the patches, pieces and annotations of ``pattern``; edges, assignments
        and fold angles derived from the folded positions.

    Raises
    ------
    ParameterError
        When ``max_turn`` is not in (0, 180] or ``min_angle`` not in [0, 60).
    """
    if not 0 < max_turn <= 180:
        raise ParameterError(f"max_turn must be in (0, 180], got {max_turn}", name="max_turn")
    if not 0 <= min_angle < 60:
        raise ParameterError(f"min_angle must be in [0, 60), got {min_angle}", name="min_angle")
    pattern = _collapse_narrow(pattern, min_angle)
    faces = _split_faces(pattern)
    flat, start = face_arrays(pattern.faces)
    n = len(pattern.vertices_2d)
    kind = patch_kinds(pattern.face_patch)
    # a vertex may go when all its faces are on cylinders and cones
    ruled = np.isin(kind, RULED_KINDS)
    face_of = run_owners(np.diff(start))
    droppable = np.ones(n, dtype=bool)
    droppable[flat[~ruled[face_of]]] = False
    edge_faces = pattern.faces_beside_edges()
    dihedral = np.nan_to_num(edge_dihedrals(pattern))
    gone = _dropped_rulings(pattern, faces, edge_faces, dihedral, droppable, max_turn, min_angle)
    gone |= _dropped_crease_points(pattern, faces, min_angle)
    out_faces, out_patch, out_piece = _merged_patches(pattern, faces, edge_faces, gone)
    order = np.argsort(np.array(out_piece), kind="stable")  # faces by piece, then as built
    keep = np.nonzero(~gone)[0]
    new_index = -np.ones(n, dtype=np.int64)
    new_index[keep] = np.arange(len(keep))
    tri = new_index[np.array([out_faces[i] for i in order.tolist()], dtype=np.int64)]
    coarse = CreasePattern(
        pattern.vertices_2d[keep],
        pattern.vertices_3d[keep],
        tri,
        [out_patch[i] for i in order.tolist()],
        np.array(out_piece, dtype=np.int64)[order],
        pattern.piece_vertex,
        annotations=pattern.annotations,
    )
    coarse = _clean_slivers(coarse, min_angle)
    if digits is None:
        return coarse
    return CreasePattern(
        round_significant(coarse.vertices_2d, digits),
        round_significant(coarse.vertices_3d, digits),
        coarse.faces,
        coarse.face_patch,
        coarse.face_piece,
        coarse.piece_vertex,
        annotations=coarse.annotations,
    )


def _merged_patches(
    pattern: CreasePattern, faces: list[np.ndarray], edge_faces: np.ndarray, gone: np.ndarray
) -> tuple[list[list[int]], list[str], list[int]]:
    """The triangles of ``pattern`` without the points ``gone`` (n,) bool, their patches and
    pieces; ``gone`` is updated to the points that did go.

    The faces of one patch are merged across every edge that touches a point that goes, and
    each merged group is triangulated without those points (see :func:`_triangles`). A group
    that is not a disc, or whose triangles would be turned over, degenerate or stretched
    beyond ``SIM_MAX_STRETCH`` or ``SIM_MAX_SHIFT``, keeps its points (they stay for the
    groups beside it too), and the groups are made again, until every group has its
    triangles.

    Raises
    ------
    ParameterError
        When a face of ``pattern`` itself has no triangles (it is not simple).
    """
    patch = patch_ids(pattern.face_patch)
    inner = (edge_faces >= 0).all(axis=1)
    fa, fb = edge_faces[:, 0], edge_faces[:, 1]
    same = inner & (patch[fa] == patch[fb])
    v2, v3 = pattern.vertices_2d, pattern.vertices_3d
    shift = _shift_bound(pattern)
    made: dict[tuple, list[list[int]] | None] = {}  # (faces, points gone) -> triangles
    while True:
        touch = gone[pattern.edges].any(axis=1)
        label = _components(len(faces), edge_faces[same & touch])
        order = np.argsort(label, kind="stable")
        groups = split_runs(order, np.nonzero(np.diff(label[order]))[0] + 1)
        out, back = [], []
        for group in groups:
            points = np.unique(np.concatenate([faces[f] for f in group.tolist()]))
            going = points[gone[points]]
            key = (tuple(group.tolist()), tuple(going.tolist()))
            if key not in made:
                if not len(going) and len(faces[group[0]]) == 3:  # a triangle as it is
                    made[key] = [faces[group[0]].tolist()]  # what the line below gives it
                elif not len(going):  # one face of the pattern as it is
                    made[key] = _triangles(faces[group[0]].tolist(), v2, v3) or _triangulate(
                        faces[group[0]].tolist(), v2
                    )
                    if made[key] is None:
                        raise ParameterError(
                            f"simulator.fold: {pattern.face_patch[group[0]]} of the pattern has "
                            f"a face that is not simple (face {int(group[0])})",
                            name="pattern",
                        )
                else:
                    loop = _outline([faces[f] for f in group.tolist()])
                    made[key] = loop and _triangles(
                        [v for v in loop if not gone[v]], v2, v3, SIM_MAX_STRETCH, shift[loop[0]]
                    )
            if made[key] is None:
                back.append(going)
            else:
                out.append((int(group[0]), made[key], going))
        if not back:
            back = [out[k][2] for k in _crossing_groups(v2, out)]
        if not back:
            break
        gone[np.concatenate(back)] = False
    out_faces, out_patch, out_piece = [], [], []
    for f0, tris, _ in sorted(out, key=lambda item: item[0]):
        out_faces += tris
        out_patch += [pattern.face_patch[f0]] * len(tris)
        out_piece += [int(pattern.face_piece[f0])] * len(tris)
    return out_faces, out_patch, out_piece


def _crossing_groups(v2: np.ndarray, out: list) -> list[int]:
    """The merged groups of ``out`` (each ``(face, triangles, points gone)``) whose triangles
    have a side that crosses or touches, in the flat layout, a side it shares no point with:
    a chord across a thin notch of its piece, which the simulator's SVG import would split
    (and which overlaps the pattern). Only groups that dropped points are named."""
    import shapely

    tri = np.array([t for _, tris, _ in out for t in tris], dtype=np.int64).reshape(-1, 3)
    group = run_owners([len(tris) for _, tris, _ in out])
    merged = np.array([len(going) > 0 for _, _, going in out], dtype=bool)
    if not merged.any():
        return []
    sides = _triangle_sides(tri)
    side_group = np.tile(group, 3)
    edges, first = np.unique(sides, axis=0, return_index=True)
    lines = shapely.linestrings(v2[edges])
    mine = np.nonzero(merged[side_group[first]])[0]  # (one group of) each side of a merge
    a, b = shapely.STRtree(lines).query(lines[mine], predicate="intersects")
    a = mine[a]
    apart = _apart(edges[a], edges[b])
    bad_sides = np.unique(np.r_[a[apart], b[apart]])
    if not len(bad_sides):
        return []
    n = len(v2)
    bad = np.isin(sides[:, 0] * n + sides[:, 1], edges[bad_sides] @ [n, 1])  # as triangle sides
    hit = np.unique(side_group[np.nonzero(bad)[0]])
    return [int(k) for k in hit if merged[k]]


def _outline(faces: list[np.ndarray]) -> list[int] | None:
    """The boundary loop of a disc made of counter-clockwise faces, counter-clockwise; None
    when the faces do not make a disc (no boundary, more than one loop, or a loop that
    passes a point twice)."""
    half = set()
    for f in faces:
        fl = f.tolist()
        half.update(zip(fl, fl[1:] + fl[:1], strict=True))
    border = [(a, b) for (a, b) in half if (b, a) not in half]
    nxt = dict(border)
    if not nxt or len(nxt) < len(border):
        return None
    first = min(nxt)
    loop = [first]
    while True:
        v = nxt[loop[-1]]
        if v == first:
            return loop if len(loop) == len(nxt) else None
        loop.append(v)
        if len(loop) > len(nxt):
            return None


def simulator_svg_pattern(coarse: CreasePattern) -> CreasePattern:
    """``coarse`` (a :func:`simulator_pattern`) as ``simulator.svg`` draws it.

    Origami Simulator's SVG import takes a line's target fold angle only from a mountain or
    valley stroke (``stroke-opacity`` times 180 degrees) and holds every facet line at 0, so
    the ``F`` edges that bend in the folded form (inside the cylinders and cones) become
    mountain or valley edges of their folded dihedral, as ``simulator.fold`` gives them in
    ``edges_foldAngle``; the simulator treats both the same (a crease of nonzero target angle,
    at the same stiffness as a facet). Tabs, labels and sheets are left out, as in
    ``simulator.fold``.

    An SVG cannot keep apart two points at one place, and the import merges points closer
    than 3 user units: a real mesh's piece whose border touches itself (the two sides of
    the notch of a nearly flat sharp vertex, closed when folded) would be merged there
    without its edges, and the faces the import then traces across the notch blow its solver
    up. So points within ``SIM_SVG_WELD`` of the drawing's size, flat and folded, are welded
    here first: the sides they close become one edge, a crease or facet by its folded
    dihedral, and the faces of the notch that would be degenerate go.

    Parameters
    ----------
    coarse : CreasePattern
        A pattern from :func:`simulator_pattern`.

    Returns
    -------
    CreasePattern
        The welded points and faces, with their edge assignments and fold angles as drawn and
        no annotations.
    """
    import dataclasses

    pattern = _welded(coarse, SIM_SVG_WELD)
    assign = np.asarray(pattern.edge_assignment, dtype="<U1").copy()
    angle = np.asarray(pattern.edge_fold_angle, dtype=np.float64).copy()
    flat = assign == "F"
    dihedral = np.nan_to_num(edge_dihedrals(pattern))
    bent = flat & (np.abs(dihedral) >= SIM_SVG_FLAT)
    assign[bent] = np.where(dihedral[bent] > 0, "V", "M")  # FOLD: valley positive
    angle[bent] = dihedral[bent]
    return dataclasses.replace(
        pattern, edge_assignment=assign, edge_fold_angle=angle, annotations=Annotations()
    )


def _welded(pattern: CreasePattern, share: float) -> CreasePattern:
    """``pattern`` (triangles) with its points closer than ``share`` of the flat extent
    (larger side) flat and of the folded diameter folded merged into the least-numbered one
    (edges derived again), and the triangles left with a repeated corner dropped; ``pattern``
    itself when no points are that close."""
    from scipy.spatial import cKDTree

    v2, v3 = pattern.vertices_2d, pattern.vertices_3d
    n = len(v2)
    if n < 2:
        return pattern
    extent = float(np.ptp(v2, axis=0).max())
    size = float(np.linalg.norm(np.ptp(v3, axis=0)))
    pairs = cKDTree(v2).query_pairs(share * extent, output_type="ndarray")
    pairs = pairs[np.linalg.norm(v3[pairs[:, 0]] - v3[pairs[:, 1]], axis=1) <= share * size]
    if not len(pairs):
        return pattern
    rep = _components(n, pairs)
    keep = np.unique(rep)
    new_index = -np.ones(n, dtype=np.int64)
    new_index[keep] = np.arange(len(keep))
    tri = new_index[rep[np.asarray(_split_faces(pattern), dtype=np.int64).reshape(-1, 3)]]
    ok = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 2] != tri[:, 0])
    patches = [p for p, good in zip(pattern.face_patch, ok.tolist(), strict=True) if good]
    return CreasePattern(
        v2[keep],
        v3[keep],
        tri[ok],
        patches,
        np.asarray(pattern.face_piece, dtype=np.int64)[ok],
        pattern.piece_vertex,
        annotations=pattern.annotations,
    )
