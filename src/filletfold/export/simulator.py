"""A coarse, triangulated copy of a crease pattern for Origami Simulator (``simulator.fold``).

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
``turn**2 / 24`` of the cell width (2.6 % for 45 degrees).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ..errors import ParameterError
from ..surface.pattern import CreasePattern, face_arrays

__all__ = [
    "SIM_MAX_TURN",
    "SIM_MIN_ANGLE",
    "simulator_pattern",
    "triangle_min_angles",
]

#: Largest turn (degrees) of one coarse cylinder cell.
SIM_MAX_TURN = 45.0
#: Smallest corner angle (degrees) a coarse cylinder cell is made wide enough for.
SIM_MIN_ANGLE = 5.0


def triangle_min_angles(points: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(n_faces,) the smallest corner angle (degrees) of each triangle.

    Parameters
    ----------
    points : (n, d) float
    faces : (n_faces, 3) int
    """
    p = np.asarray(points, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]
    out = np.full(len(p), 180.0)
    for i in range(3):
        u = p[:, (i + 1) % 3] - p[:, i]
        w = p[:, (i + 2) % 3] - p[:, i]
        if p.shape[2] == 2:
            cross = np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0])
        else:
            cross = np.linalg.norm(np.cross(u, w), axis=1)
        out = np.minimum(out, np.degrees(np.arctan2(cross, np.einsum("ij,ij->i", u, w))))
    return out


def _triangulate(loop: list[int], p: np.ndarray) -> list[list[int]]:
    """Counter-clockwise triangles of a simple counter-clockwise flat polygon whose smallest
    angle is the largest of all its triangulations (dynamic programming over diagonals)."""
    k = len(loop)
    if k == 3:
        return [list(loop)]
    q = p[np.asarray(loop)]
    ok = np.zeros((k, k), dtype=bool)
    for i in range(k):
        ok[i, (i + 1) % k] = ok[(i + 1) % k, i] = True
        for j in range(i + 2, k):
            if not (i == 0 and j == k - 1):
                ok[i, j] = ok[j, i] = _is_diagonal(q, i, j)
    best = np.full((k, k), -math.inf)
    split = -np.ones((k, k), dtype=np.int64)
    for i in range(k - 1):
        best[i, i + 1] = math.inf
    for gap in range(2, k):
        for i in range(k - gap):
            j = i + gap
            if not ok[i, j]:
                continue
            for m in range(i + 1, j):
                if not (ok[i, m] and ok[m, j]):
                    continue
                angle = float(triangle_min_angles(q[[i, m, j]], np.array([[0, 1, 2]]))[0])
                value = min(best[i, m], best[m, j], angle)
                if value > best[i, j]:
                    best[i, j], split[i, j] = value, m
    if split[0, k - 1] < 0:  # no triangulation found (a degenerate outline): a fan
        return [[loop[0], loop[i], loop[i + 1]] for i in range(1, k - 1)]
    tris, stack = [], [(0, k - 1)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        m = int(split[i, j])
        tris.append([loop[i], loop[m], loop[j]])
        stack += [(i, m), (m, j)]
    return tris


def _is_diagonal(q: np.ndarray, i: int, j: int) -> bool:
    """Whether the segment between corners ``i`` and ``j`` of the counter-clockwise polygon
    ``q`` lies inside it (crossing no side, its midpoint inside)."""
    a, b = q[i], q[j]
    k = len(q)
    scale = float(np.abs(q).max()) or 1.0
    eps = 1e-12 * scale * scale
    for s in range(k):
        t = (s + 1) % k
        if len({i, j, s, t}) < 4:
            continue
        c, d = q[s], q[t]
        d1, d2 = _cross(a, b, c), _cross(a, b, d)
        d3, d4 = _cross(c, d, a), _cross(c, d, b)
        if (d1 > eps) != (d2 > eps) and (d3 > eps) != (d4 > eps):
            return False
        if abs(d1) <= eps and _between(a, b, c):
            return False
    mid = (a + b) / 2
    x, y = q[:, 0], q[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    crossing = (y > mid[1]) != (yn > mid[1])
    xs = x + (mid[1] - y) * (xn - x) / np.where(yn == y, 1.0, yn - y)
    return bool(np.count_nonzero(crossing & (xs > mid[0])) % 2)


def _cross(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    """The z component of ``(b - a) x (c - a)``."""
    return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


def _between(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> bool:
    """Whether ``c`` (on the line ``a b``) lies strictly between ``a`` and ``b``."""
    t = float((c - a) @ (b - a)) / max(float((b - a) @ (b - a)), 1e-300)
    return 0 < t < 1


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


def _edge_faces_of(pattern: CreasePattern, faces: list[np.ndarray]) -> np.ndarray:
    """(m, 2) the faces beside each pattern edge (derived when the pattern has none)."""
    ef = pattern.edge_faces
    if ef is None:  # a pattern read from a file
        from .fold_read import _edge_faces

        ef = _edge_faces(pattern.edges, faces, len(pattern.vertices_2d))
    return np.asarray(ef, dtype=np.int64).reshape(-1, 2)


def _split_faces(pattern: CreasePattern) -> list[np.ndarray]:
    """The faces of ``pattern`` as a list of int arrays."""
    flat, start = face_arrays(pattern.faces)
    return [flat[a:b].astype(np.int64) for a, b in itertools.pairwise(start)]


def _ruled_strips(pattern: CreasePattern, faces: list[np.ndarray], edge_faces: np.ndarray):
    """Each connected cylinder or conical fillet strip, as a tuple: its faces, its points, each
    point's place along the rulings (flat), its rulings (k, 2) (sides of its faces along the
    rulings: developed, a cylinder's rulings are parallel and a fillet's meet at one point),
    which of them are inner edges, each ruling's place across the strip (0 to 1), the strip's
    width across the rulings and their mean length."""
    kind = np.array([p.split(" ")[0] for p in pattern.face_patch] or [""])
    patch = np.array(pattern.face_patch or [""])
    inner = (edge_faces >= 0).all(axis=1)
    fa, fb = edge_faces[:, 0], edge_faces[:, 1]
    ruled = np.isin(kind, ["cylinder", "fillet"])
    same = inner & (patch[fa] == patch[fb]) & ruled[fa]
    label = _components(len(faces), edge_faces[same])
    v2 = pattern.vertices_2d
    key = pattern.edges[:, 0] * len(v2) + pattern.edges[:, 1]  # sorted
    for comp in np.unique(label[ruled]).tolist():
        members = np.nonzero(label == comp)[0]
        sides = np.concatenate([np.c_[faces[f], np.roll(faces[f], -1)] for f in members.tolist()])
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
    """
    faces = _split_faces(pattern)
    edge_faces = _edge_faces_of(pattern, faces)
    n = len(pattern.vertices_2d)
    v2 = pattern.vertices_2d
    merged = [np.zeros((0, 2), dtype=np.int64)]  # pairs of points that become one
    bound = math.tan(math.radians(min_angle))
    flat_sides = [
        np.linalg.norm(v2[f] - v2[np.roll(f, -1)], axis=1)
        for f, name in zip(faces, pattern.face_patch, strict=True)
        if name.startswith("face ")
    ]
    scale = float(np.median(np.concatenate(flat_sides))) if flat_sides else 0.0
    strips = _ruled_strips(pattern, faces, edge_faces)
    for _, verts, along, rulings, _, _, width, length in strips:
        if width < length * bound:
            # each line of points across the strip (its ends, and any seam between rows of
            # cells) becomes one point
            order = np.argsort(along, kind="stable")
            cut = np.nonzero(np.diff(along[order]) > 0.1 * length)[0] + 1
            for line in np.split(verts[order], cut):
                merged.append(np.c_[line[:-1], line[1:]])
        elif length < scale * bound:
            merged.append(np.asarray(rulings, dtype=np.int64).reshape(-1, 2))
    rep = _components(n, np.concatenate(merged))  # each point's group, named by its least
    if (rep == np.arange(n)).all():
        return pattern
    count = np.bincount(rep, minlength=n)
    v2 = np.zeros((n, 2))
    v3 = np.zeros((n, 3))
    np.add.at(v2, rep, pattern.vertices_2d)
    np.add.at(v3, rep, pattern.vertices_3d)
    used = count > 0
    v2[used] /= count[used, None]
    v3[used] /= count[used, None]
    out_faces, out_patch, out_piece = [], [], []
    for f, face in enumerate(faces):
        loop = rep[face].tolist()
        loop = [v for i, v in enumerate(loop) if v != loop[i - 1]]  # cyclic duplicates
        if len(set(loop)) >= 3 and len(set(loop)) == len(loop):
            out_faces.append(loop)
            out_patch.append(pattern.face_patch[f])
            out_piece.append(int(pattern.face_piece[f]))
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
    for _, _, _, rulings, is_inner, at, width, length in strips:
        if not is_inner.any():
            continue
        turn = _strip_turn(pattern, rulings[is_inner], at[is_inner], dihedral)
        by_turn = math.ceil(turn / max_turn - 1e-9) if turn > 0 else 1
        by_width = math.floor(width / (1.5 * length * bound)) if bound > 0 else len(rulings) + 1
        cells = max(1, min(by_turn, by_width))
        inner_at = at[is_inner]
        chosen = {float(inner_at[np.argmin(np.abs(inner_at - k / cells))]) for k in range(1, cells)}
        near = np.abs(at[:, None] - np.array(sorted(chosen) or [np.inf])[None, :]) < 1e-6
        kept = ~is_inner | near.any(axis=1)
        drop = np.zeros(len(v2), dtype=bool)
        drop[rulings[~kept].ravel()] = True
        drop[rulings[kept].ravel()] = False
        # a ruling goes only when both its ends may go (a fillet's apex, on many rulings,
        # stays and does not count)
        hub = np.bincount(rulings.ravel(), minlength=len(v2)) >= 3
        drop[hub] = False
        free = droppable | hub
        drop[rulings[~free[rulings].all(axis=1)].ravel()] = False
        half = (drop | hub)[rulings].all(axis=1)
        drop[rulings[drop[rulings].any(axis=1) & ~half].ravel()] = False
        gone |= drop
    return gone


def _strip_turn(
    pattern: CreasePattern, rulings: np.ndarray, at: np.ndarray, dihedral: np.ndarray
) -> float:
    """The total bend (degrees) of a strip across its inner ``rulings`` (at places ``at``
    across it): the sum of their dihedrals, one ruling per place (a strip may have rows)."""
    n = len(pattern.vertices_2d)
    key = pattern.edges[:, 0] * n + pattern.edges[:, 1]
    lo, hi = rulings.min(axis=1), rulings.max(axis=1)
    bends = np.abs(dihedral[np.searchsorted(key, lo * n + hi)])  # pattern edges are sorted
    order = np.argsort(at, kind="stable")
    first = order[np.r_[True, np.diff(at[order]) > 1e-6]]
    return float(bends[first].sum())


def _dropped_crease_points(
    pattern: CreasePattern, faces: list[np.ndarray], min_angle: float
) -> np.ndarray:
    """(n,) bool: points to drop on the creases between two cones (where a collapsed cylinder
    was): along each such crease, the points nearest to equal steps of about
    ``tan(3 min_angle)`` times the distance to the nearer apex are kept."""
    n = len(pattern.vertices_2d)
    v2 = pattern.vertices_2d
    gone = np.zeros(n, dtype=bool)
    names = pattern.face_patch
    cone = np.array([p.startswith("cone ") for p in names] or [False])
    corners = np.concatenate(faces) if faces else np.zeros(0, dtype=np.int64)
    face_of = np.repeat(np.arange(len(faces)), [len(f) for f in faces])
    only_cones = np.ones(n, dtype=bool)
    only_cones[corners[~cone[face_of]]] = False
    patches_at: dict[int, set[str]] = {}
    for v, f in zip(corners.tolist(), face_of.tolist(), strict=True):
        patches_at.setdefault(v, set()).add(names[f])
    candidate = np.array([only_cones[v] and len(patches_at.get(v, ())) >= 2 for v in range(n)])
    # the apex of each cone patch: the corner its faces share most
    apex: dict[str, int] = {}
    for name in {names[f] for f in np.nonzero(cone)[0].tolist()}:
        members = [faces[f] for f in range(len(faces)) if names[f] == name]
        apex[name] = int(np.bincount(np.concatenate(members)).argmax())
    crease = np.isin(pattern.edge_assignment, ["M", "V"])
    pairs = pattern.edges[crease]
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
        # walk to one end of the run, then along it
        run, prev, v = [], -1, start_v
        while True:  # to an end: a non-candidate or a point seen again (a closed loop)
            nxt = [w for w in neighbours.get(v, []) if w != prev]
            if not candidate[v] or not nxt or (run and v == start_v):
                break
            run.append(v)
            prev, v = v, nxt[0]
            if len(run) > n:
                break
        end = v
        path, prev, v = [end], -1, end
        while True:
            nxt = [w for w in neighbours.get(v, []) if w != prev and w not in path[-2:]]
            if not nxt:
                break
            prev, v = v, nxt[0]
            path.append(v)
            if not candidate[v] or v == end or len(path) > n:
                break
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
            for name in patches_at[inner[len(inner) // 2]]
        )
        cells = max(1, math.ceil(total / max(radius * tan, 1e-300)))
        keep = {int(np.argmin(np.abs(at - k * total / cells))) for k in range(1, cells)}
        for i, w in enumerate(path):
            if candidate[w] and i not in keep:
                gone[w] = True
    return gone


def _clean_slivers(pattern: CreasePattern, min_angle: float, rounds: int = 8) -> CreasePattern:
    """``pattern`` (triangles) with its triangles under ``min_angle`` improved where a local
    move does it: a short side collapsed (its end that is not on a crease or border, or on
    one through the side, moved onto the other end: every point keeps its exact flat and
    folded position) or, inside a smooth patch, the longest side flipped. A move is taken
    when the smallest angle of the triangles it changes grows and none turns over."""
    v2, v3 = pattern.vertices_2d.copy(), pattern.vertices_3d.copy()
    tri = np.array(list(pattern.faces), dtype=np.int64).reshape(-1, 3)
    patch = list(pattern.face_patch)
    piece = np.asarray(pattern.face_piece).copy()
    for _ in range(rounds):
        current = CreasePattern(v2, v3, tri, patch, piece, pattern.piece_vertex)
        quality = triangle_min_angles(v2, tri)
        bad = np.nonzero(quality < min_angle)[0]
        if not len(bad):
            break
        feature = np.isin(current.edge_assignment, ["M", "V", "B"])
        n = len(v2)
        key = current.edges[:, 0] * n + current.edges[:, 1]
        fdeg = np.bincount(current.edges[feature].ravel(), minlength=n)
        is_feature = dict(zip(key.tolist(), feature.tolist(), strict=True))
        alive = np.ones(len(tri), dtype=bool)
        touched = np.zeros(n, dtype=bool)
        for t in bad[np.argsort(quality[bad])].tolist():
            if not alive[t] or touched[tri[t]].any():
                continue
            move = _best_move(tri, alive, t, v2, v3, is_feature, fdeg, patch, n, min_angle)
            if move is None:
                continue
            changed, new, moved = move
            if moved is not None:
                v, p2, p3 = moved
                v2[v], v3[v] = p2, p3
            for f, corners in zip(changed, new, strict=True):
                if corners is None:
                    alive[f] = False
                else:
                    tri[f] = corners
            touched[np.unique(tri[changed])] = True
        if alive.all() and not touched.any():
            break
        tri, patch = tri[alive], [p for p, a in zip(patch, alive, strict=True) if a]
        piece = piece[alive]
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


def _best_move(tri, alive, t, v2, v3, is_feature, fdeg, patch, n, min_angle):
    """The best collapse or flip for the sliver ``t`` (see :func:`_clean_slivers`): the
    changed faces, their new corners (None: removed) and the point moved (None, or (vertex,
    flat, folded position)); None when nothing improves.

    A side shorter than ``tan(min_angle)`` times the longest, whose ends both lie on creases
    or borders, may also be collapsed to its midpoint (the one move that moves a point)."""
    corners = tri[t].tolist()
    around = {v: np.nonzero(alive & (tri == v).any(axis=1))[0] for v in corners}
    best, best_q = None, float(triangle_min_angles(v2, tri[[t]])[0])
    sides = [(corners[i], corners[(i + 1) % 3]) for i in range(3)]
    lengths = [float(np.linalg.norm(v2[a] - v2[b])) for a, b in sides]
    short = math.tan(math.radians(min_angle)) * max(lengths)
    for (a, b), length in zip(sides, lengths, strict=True):
        edge_feature = is_feature.get(min(a, b) * n + max(a, b), False)
        for keep, go in ((a, b), (b, a), (min(a, b), -1)):
            moved = None
            if go == -1:  # both ends on features: the midpoint, for a short side only
                if not (fdeg[a] and fdeg[b] and length < short):
                    continue
                go = max(a, b)
                moved = (keep, (v2[a] + v2[b]) / 2, (v3[a] + v3[b]) / 2)
            elif fdeg[go] and not (fdeg[go] == 2 and edge_feature):
                continue
            faces = around[go]
            new = []
            for f in faces.tolist():
                c = tri[f]
                new.append(None if keep in c else np.where(c == go, keep, c))
            kept = [c for c in new if c is not None]
            if not kept:
                continue
            keep_faces = around[keep]
            if moved is not None:  # the faces of keep move too
                for f in keep_faces.tolist():
                    if f not in faces:
                        faces = np.append(faces, f)
                        new.append(tri[f].copy())
                kept = [c for c in new if c is not None]
            k = np.array(kept)
            p = v2[k]
            if moved is not None:
                p = np.where((k == keep)[:, :, None], moved[1], p)
            area = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (
                p[:, 1, 1] - p[:, 0, 1]
            ) * (p[:, 2, 0] - p[:, 0, 0])
            if (area <= 0).any():
                continue
            # the link condition: keep and go share exactly the corners of the faces removed
            ring_go = set(tri[around[go]].ravel().tolist()) - {go}
            ring_keep = set(tri[keep_faces].ravel().tolist()) - {keep}
            if len(ring_go & ring_keep) != sum(c is None for c in new):
                continue
            q = float(
                triangle_min_angles(p.reshape(-1, 2), np.arange(3 * len(k)).reshape(-1, 3)).min()
            )
            if q > best_q:
                best, best_q = (faces.tolist(), new, moved), q
    # flip the longest side inside one smooth patch
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
            k = np.array(new)
            p = v2[k]
            area = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (
                p[:, 1, 1] - p[:, 0, 1]
            ) * (p[:, 2, 0] - p[:, 0, 0])
            if (area > 0).all():
                q = float(triangle_min_angles(v2, k).min())
                if q > best_q:
                    best, best_q = ([t, o], new, None), q
    return best


def simulator_pattern(
    pattern: CreasePattern,
    *,
    max_turn: float = SIM_MAX_TURN,
    min_angle: float = SIM_MIN_ANGLE,
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
    from .fold import edge_dihedrals

    pattern = _collapse_narrow(pattern, min_angle)
    faces = _split_faces(pattern)
    flat, start = face_arrays(pattern.faces)
    n = len(pattern.vertices_2d)
    kind = np.array([p.split(" ")[0] for p in pattern.face_patch] or [""])
    # a vertex may go when all its faces are on cylinders and cones
    ruled = np.isin(kind, ["cylinder", "cone", "fillet"])
    face_of = np.repeat(np.arange(len(faces)), np.diff(start))
    droppable = np.ones(n, dtype=bool)
    droppable[flat[~ruled[face_of]]] = False
    edge_faces = _edge_faces_of(pattern, faces)
    dihedral = np.nan_to_num(edge_dihedrals(pattern))
    gone = _dropped_rulings(pattern, faces, edge_faces, dihedral, droppable, max_turn, min_angle)
    gone |= _dropped_crease_points(pattern, faces, min_angle)
    # merge the faces of one patch across every edge that touches a dropped vertex
    patch = np.array(pattern.face_patch or [""])
    inner = (edge_faces >= 0).all(axis=1)
    fa, fb = edge_faces[:, 0], edge_faces[:, 1]
    touch = gone[pattern.edges].any(axis=1)
    merge = inner & touch & (patch[fa] == patch[fb])
    label = _components(len(faces), edge_faces[merge])
    v2 = pattern.vertices_2d
    out_faces, out_patch, out_piece = [], [], []
    for root in np.unique(label).tolist():
        group = np.nonzero(label == root)[0]
        f0 = int(group[0])
        loop = _outline([faces[f] for f in group.tolist()], pattern.face_patch[f0])
        loop = [v for v in loop if not gone[v]]
        for tri in _triangulate(loop, v2):
            out_faces.append(tri)
            out_patch.append(pattern.face_patch[f0])
            out_piece.append(int(pattern.face_piece[f0]))
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
    return _clean_slivers(coarse, min_angle)


def _outline(faces: list[np.ndarray], patch: str = "") -> list[int]:
    """The boundary loop of a disc made of counter-clockwise faces, counter-clockwise."""
    half = {}
    for f in faces:
        fl = f.tolist()
        for a, b in zip(fl, fl[1:] + fl[:1], strict=True):
            half[(a, b)] = True
    nxt = {a: b for (a, b) in half if (b, a) not in half}
    if not nxt:
        raise ParameterError(
            f"simulator.fold: {patch or 'a patch'} of the pattern has no outline", name="pattern"
        )
    first = min(nxt)
    loop = [first]
    while True:
        v = nxt[loop[-1]]
        if v == first:
            return loop
        loop.append(v)
        if len(loop) > len(nxt):
            raise ParameterError(
                f"simulator.fold: {patch or 'a patch'} of the pattern is not a disc", name="pattern"
            )
