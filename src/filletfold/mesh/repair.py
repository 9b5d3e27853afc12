"""Repairs of a raw polygon mesh, each one reported.

:func:`~filletfold.mesh.clean.clean_mesh` runs these steps in order; every change they make is
a :class:`Repair` (what, where, why) in a :class:`RepairLog`. With ``strict=True`` the log
raises the :class:`~filletfold.errors.MeshError` that names the element instead of repairing.

Faces are lists of vertex-index arrays with ``origin`` (the input face each one comes from);
vertices carry ``vorig`` (their input index), so that every message names input elements.

* :func:`split_face_loops` -- faces that visit a vertex twice split into simple loops, faces of
  fewer than three distinct vertices dropped;
* :func:`fix_degenerate_faces` -- faces of (almost) zero area: a triangle whose middle vertex lies
  on its longest edge is removed and that vertex inserted into the face across the edge (what
  CGAL's ``remove_degenerate_faces`` does by edge flips), anything else is dropped;
* :func:`drop_duplicate_faces` -- a face on the same vertices as an earlier one; a face and
  its reversed copy both, where that opens no hole (a wall between two cells, a fin of zero
  volume);
* :func:`split_non_manifold` -- a vertex where separate fans of faces touch becomes one copy
  per fan, and an edge shared by more than two faces is cut open so that each sheet keeps a
  manifold neighbourhood: the faces around the edge are paired by their angular order (CGAL's
  ``duplicate_non_manifold_vertices`` does the first, trimesh's and MeshLab's cleaning the
  second only by deleting faces);
* :func:`split_into_triangles` -- a polygon that is not planar, or not convex, is triangulated in
  its plane, along diagonals that are no edge of the mesh yet (the coplanar merge then
  regroups coplanar triangles into convex parts).

:mod:`~filletfold.mesh.clean` itself reverses faces to orient each piece (``flip-face``) and
cuts open the edges where a surface cannot be oriented or where two faces lie back to back
(``cut-edge``, through :func:`split_non_manifold`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..arrays import run_next, run_owners, run_starts, split_runs
from ..errors import MeshError

#: Added to the diagonal of planarize's normal equations (``A A^T``), which are singular when
#: polygons share their constraints: far below their entries, so the step is the least-norm one.
REGULARISE = 1e-12


@dataclass(frozen=True)
class Repair:
    """One change made to the input mesh.

    Attributes
    ----------
    what : str
        The kind of repair: ``"weld"``, ``"drop-face"``, ``"split-face"``, ``"split-vertex"``,
        ``"cut-edge"``, ``"flip-face"``, ``"planarize"``, ...
    where : str
        The element, by its index in the input (``"face 7"``, ``"vertex 12"``,
        ``"edge (3, 9)"``, ``"vertices 4, 17"``).
    why : str
        What was wrong with it.
    """

    what: str
    where: str
    why: str

    def as_dict(self) -> dict:
        return {"what": self.what, "where": self.where, "why": self.why}

    def __str__(self) -> str:
        return f"{self.what} {self.where}: {self.why}"


@dataclass
class RepairLog:
    """The repairs made so far; with ``strict`` the first one raises instead.

    Attributes
    ----------
    strict : bool
    repairs : list of Repair
    """

    strict: bool = False
    repairs: list = field(default_factory=list)

    def add(self, what: str, where: str, why: str, *, error: str, **element) -> None:
        """Record a repair, or (``strict``) raise ``MeshError(error, **element)``."""
        if self.strict:
            raise MeshError(error, **element)
        self.repairs.append(Repair(what, where, why))


# ------------------------------------------------------------------------------ geometry
def polygon_normal(p: np.ndarray) -> np.ndarray:
    """(3,) Newell vector of a polygon ``p`` (k, 3) (twice its vector area), about its centroid."""
    q = p - p.mean(axis=0)
    return np.cross(q, np.roll(q, -1, axis=0)).sum(axis=0)


def plane_axes(normal: np.ndarray) -> np.ndarray:
    """(2, 3) orthonormal in-plane axes ``e1, e2`` with ``e1 x e2`` along ``normal``."""
    n = normal / np.linalg.norm(normal)
    e1 = np.cross(n, np.eye(3)[int(np.argmin(np.abs(n)))])
    e1 /= np.linalg.norm(e1)
    return np.stack([e1, np.cross(n, e1)])


def corner_turns(xy: np.ndarray) -> np.ndarray:
    """(k,) signed turn at each corner of a 2D polygon ``xy`` (k, 2), radians in (-pi, pi]:
    positive at a convex corner of a counter-clockwise polygon, 0 where it is straight."""
    d_in = xy - np.roll(xy, 1, axis=0)
    d_out = np.roll(xy, -1, axis=0) - xy
    cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    dot = np.einsum("ij,ij->i", d_in, d_out)
    return np.arctan2(cross, dot)


# ------------------------------------------------------------------------- face loops
def split_face_loops(faces, origin, vorig, log: RepairLog):
    """Drop consecutive repeats, split faces that visit a vertex twice, drop faces with fewer
    than three distinct vertices.

    Parameters
    ----------
    faces : list of (k,) int
    origin : (n_faces,) int
        Input face of each face.
    vorig : (n_vertices,) int
        Input index of each vertex.
    log : RepairLog

    Returns
    -------
    faces : list of (k,) int
    origin : (n_faces,) int
    """
    bad = _faces_to_split(faces)
    if not bad.any():
        return list(faces), np.asarray(origin, dtype=np.int64)
    out, out_origin = [], []
    for f, o, b in zip(faces, origin.tolist(), bad.tolist(), strict=True):
        if not b:
            out.append(f)
            out_origin.append(o)
            continue
        g = f[f != np.roll(f, 1)] if len(f) > 1 else f
        distinct = len(np.unique(f))
        if distinct < 3:
            log.add(
                "drop-face",
                f"face {o}",
                f"it has {distinct} distinct vertices once coincident vertices are welded",
                error=f"degenerate face {o}: it has {distinct} distinct vertices after merging "
                "duplicates (at least 3 needed)",
                face=o,
            )
            continue
        loops = _simple_loops(g.tolist())
        if len(loops) == 1 and len(loops[0]) == len(g):
            out.append(np.asarray(loops[0], dtype=np.int64))
            out_origin.append(o)
            continue
        x, times = _repeated(g)
        shown = g.tolist() if len(g) <= 12 else [*g[:12].tolist(), "..."]
        log.add(
            "split-face" if loops else "drop-face",
            f"face {o}",
            f"it visits vertex {int(vorig[x])} {_times(times)}: "
            + (
                f"split into {len(loops)} simple polygon(s)"
                if loops
                else "it only goes back and forth (no loop of three vertices)"
            ),
            error=f"degenerate face {o}: it visits a vertex twice ({shown})",
            face=o,
        )
        for loop in loops:
            out.append(np.asarray(loop, dtype=np.int64))
            out_origin.append(o)
    return out, np.asarray(out_origin, dtype=np.int64)


def _faces_to_split(faces) -> np.ndarray:
    """(n_faces,) bool: the faces with fewer than three corners or a vertex twice, all at once.

    Parameters
    ----------
    faces : list of (k,) int

    Returns
    -------
    (n_faces,) bool
    """
    sizes = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
    bad = sizes < 3
    if not len(faces):
        return bad
    flat = np.concatenate(faces).astype(np.int64, copy=False)
    face = run_owners(sizes)
    order = np.lexsort((flat, face))
    f, v = face[order], flat[order]
    twice = (f[1:] == f[:-1]) & (v[1:] == v[:-1])
    bad[f[1:][twice]] = True
    return bad


def _repeated(g: np.ndarray) -> tuple[int, int]:
    """The first repeated vertex of ``g`` (smallest index) and how often it is visited."""
    values, counts = np.unique(g, return_counts=True)
    k = int(np.flatnonzero(counts > 1)[0])
    return int(values[k]), int(counts[k])


def _times(k: int) -> str:
    return "twice" if k == 2 else f"{k} times"


def _simple_loops(loop: list) -> list[list]:
    """A closed vertex loop cut at its repeated vertices into simple loops of >= 3 vertices,
    in one pass (linear in its length however often it repeats a vertex): the loop is walked
    on a stack, and coming back to a vertex on the stack closes the loop from there."""
    done, stack, at = [], [], {}
    for x in loop:
        j = at.get(x)
        if j is None:
            at[x] = len(stack)
            stack.append(x)
            continue
        part = stack[j:]  # x ... back to x
        for y in part[1:]:
            del at[y]
        del stack[j + 1 :]
        if len(part) >= 3:
            done.append(part)
    if len(stack) >= 3:
        done.append(stack)
    return done


# ------------------------------------------------------------------------- zero-area faces
def fix_degenerate_faces(faces, origin, v, vorig, log: RepairLog, rel_height: float):
    """Remove faces of (almost) zero area without opening the surface.

    A face is degenerate when its area is at most ``rel_height / 2`` times its longest edge
    squared (its height over that edge below ``rel_height`` of it). A degenerate triangle
    ``(a, b, c)`` with longest edge ``ab`` is removed and ``c`` is inserted into every other
    face on ``ab`` (a triangle there is split in two), so the surface stays closed; other
    degenerate faces are dropped. Repeated until none is left (at most 8 rounds).

    Returns
    -------
    faces : list of (k,) int
    origin : (n_faces,) int
    """
    for _ in range(8):
        bad = _degenerate(faces, v, rel_height)
        if not len(bad):
            break
        faces = [np.asarray(f, dtype=np.int64) for f in faces]
        on_edge = _faces_on_edges(faces)
        drop, insert = set(), {}  # face -> list of (a, b, c): put c between a and b
        for i in bad.tolist():
            if i in drop:
                continue
            f = faces[i]
            o = int(origin[i])
            p = v[f]
            length = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)
            drop.add(i)
            why = "its area is (almost) zero"
            if len(f) == 3:
                k = int(np.argmax(length))
                a, b, c = int(f[k]), int(f[(k + 1) % 3]), int(f[(k + 2) % 3])
                others = [j for j in on_edge.get((min(a, b), max(a, b)), []) if j != i]
                others = [j for j in others if j not in drop]
                for j in others:
                    insert.setdefault(j, []).append((a, b, c))
                if others:
                    why += (
                        f": vertex {int(vorig[c])} lies on its edge ({int(vorig[a])}, "
                        f"{int(vorig[b])}) and was inserted into the face beside it"
                    )
            log.add(
                "drop-face",
                f"face {o}",
                why,
                error=f"degenerate face {o}: its area is (almost) zero (its height is below "
                f"{rel_height:g} of its longest edge)",
                face=o,
            )
        new_faces, new_origin = [], []
        for j, (f, o) in enumerate(zip(faces, origin.tolist(), strict=True)):
            if j in drop:
                continue
            for part in _insert_vertices(f, insert.get(j, ())):
                new_faces.append(part)
                new_origin.append(o)
        faces, origin = new_faces, np.asarray(new_origin, dtype=np.int64)
    bad = _degenerate(faces, v, rel_height)
    if len(bad):
        keep = np.ones(len(faces), dtype=bool)
        keep[bad] = False
        for i in bad.tolist():
            o = int(origin[i])
            log.add(
                "drop-face",
                f"face {o}",
                "its area is (almost) zero",
                error=f"degenerate face {o}: its area is (almost) zero",
                face=o,
            )
        faces = [f for f, k in zip(faces, keep, strict=True) if k]
        origin = origin[keep]
    return faces, origin


def _degenerate(faces, v, rel_height: float) -> np.ndarray:
    """Indices of the faces whose area is at most ``rel_height / 2`` x longest edge squared."""
    if not faces:
        return np.zeros(0, dtype=np.int64)
    size = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
    start = run_starts(size)
    idx = np.concatenate(faces)
    face = run_owners(size)
    nxt = run_next(start)
    p = v[idx]
    centroid = np.add.reduceat(p, start[:-1], axis=0) / size[:, None]
    q = p - centroid[face]
    area = 0.5 * np.linalg.norm(np.add.reduceat(np.cross(q, q[nxt]), start[:-1], axis=0), axis=1)
    longest = np.maximum.reduceat(np.linalg.norm(p[nxt] - p, axis=1), start[:-1])
    return np.flatnonzero(area <= 0.5 * rel_height * longest**2)


def _faces_on_edges(faces) -> dict:
    """(a, b) with a < b -> faces using that edge."""
    out: dict = {}
    for i, f in enumerate(faces):
        fl = f.tolist()
        for a, b in zip(fl, fl[1:] + fl[:1], strict=True):
            out.setdefault((min(a, b), max(a, b)), []).append(i)
    return out


def _insert_vertices(f: np.ndarray, inserts) -> list[np.ndarray]:
    """Face ``f`` with each ``c`` of ``inserts`` (a, b, c) put between ``a`` and ``b``; a
    triangle that gets one vertex is split into two triangles at it."""
    if not inserts:
        return [f]
    loop = f.tolist()
    for a, b, c in inserts:
        if c in loop:
            continue
        n = len(loop)
        for k in range(n):
            x, y = loop[k], loop[(k + 1) % n]
            if {x, y} == {a, b}:
                loop.insert(k + 1, c)
                break
    if len(f) == 3 and len(loop) == 4:  # split the triangle at the new vertex
        k = next(i for i, x in enumerate(loop) if x not in f.tolist())
        c, b, d, a = (loop[(k + j) % 4] for j in range(4))
        return [np.array([c, b, d], dtype=np.int64), np.array([c, d, a], dtype=np.int64)]
    return [np.asarray(loop, dtype=np.int64)]


# ------------------------------------------------------------------------- duplicate faces
def drop_duplicate_faces(faces, origin, log: RepairLog):
    """Drop the faces on the same set of vertices as another one.

    A face and a reversed copy of it (the same vertices in the opposite order) that can both
    go without opening the surface -- every edge of theirs is then used by two other faces or
    by none, and some edge of theirs by two others -- are both dropped: a wall between two
    cells (two solids sharing a face), a fin of zero volume standing on an edge, a doubled
    sheet hanging from a surface; the faces joined to such a pair by edges and reversed
    copies themselves go with it, as one piece. Otherwise (a copy in the same order, or a
    pair whose removal would leave a hole, or that is all there is) the first face is kept
    and its copies dropped.

    Returns
    -------
    faces : list of (k,) int
    origin : (n_faces,) int
    """
    keep = np.ones(len(faces), dtype=bool)
    twin = {}  # dropped face -> the earlier face it repeats
    size = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
    groups = []  # faces on one vertex set, in face order
    for k in np.unique(size).tolist():
        rows = np.flatnonzero(size == k)
        block = np.array([faces[i] for i in rows.tolist()])
        keys = np.sort(block, axis=1)
        _, first, inverse, counts = np.unique(
            keys, axis=0, return_index=True, return_inverse=True, return_counts=True
        )
        inverse = inverse.reshape(-1)
        for j in np.flatnonzero(np.arange(len(rows)) != first[inverse]).tolist():
            twin[int(rows[j])] = int(rows[first[inverse[j]]])
        many = np.flatnonzero(counts[inverse] > 1)
        by = {}
        for j in many.tolist():
            by.setdefault(int(inverse[j]), []).append(int(rows[j]))
        groups += list(by.values())
    if not twin:
        return list(faces), np.asarray(origin, dtype=np.int64)
    pairs = {} if log.strict else _inner_pairs(faces, groups)  # strict: the copy is named
    for i in sorted(set(twin) | set(pairs)):
        keep[i] = False
        if i in pairs:
            o, o0 = int(origin[i]), int(origin[pairs[i]])
            log.add(
                "drop-face",
                f"face {o}",
                f"it is face {o0} reversed (a wall between two cells, or a fin or sheet of "
                "zero volume): both dropped, which leaves no hole",
                error="",
            )
            continue
        o, o0 = int(origin[i]), int(origin[twin[i]])
        log.add(
            "drop-face",
            f"face {o}",
            f"it uses the same vertices as face {o0} (duplicate face)",
            error=f"degenerate face {o}: it uses the same vertices as face {o0} (duplicate face)",
            face=o,
        )
    return [f for f, k in zip(faces, keep, strict=True) if k], np.asarray(origin)[keep]


def _inner_pairs(faces, groups) -> dict:
    """The faces to drop as reversed pairs (see :func:`drop_duplicate_faces`): face -> the
    other face of its pair (for the message).

    ``groups`` lists the faces on one vertex set (two or more each). Those with both
    orientations are candidates; candidates joined by edges form pieces, and a piece goes
    when removing all its faces leaves each of their edges with zero or two faces and some
    edge with two."""
    cand = []
    partner = {}
    for g in groups:
        ref = faces[g[0]].tolist()
        same = [_same_cycle(ref, faces[i].tolist()) for i in g]
        if all(same) or not any(same) or len(g) % 2:
            continue  # one orientation only, or an odd number: keep one copy
        fw = [i for i, s in zip(g, same, strict=True) if s]
        bw = [i for i, s in zip(g, same, strict=True) if not s]
        if len(fw) != len(bw):
            continue
        cand += g
        for x, y in zip(fw, bw, strict=True):
            partner[x], partner[y] = y, x
    if not cand:
        return {}
    n = int(np.concatenate(faces).max()) + 1
    keys, counts = _edge_counts(faces, n)
    count = dict(zip(keys.tolist(), counts.tolist(), strict=True))
    # pieces: candidates sharing an edge
    parent = {i: i for i in cand}

    def root(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    owner: dict = {}
    for i in cand:
        fl = faces[i].tolist()
        for a, b in zip(fl, fl[1:] + fl[:1], strict=True):
            key = (min(a, b), max(a, b))
            if key in owner:
                parent[root(i)] = root(owner[key])
            else:
                owner[key] = i
    pieces: dict = {}
    for i in cand:
        pieces.setdefault(root(i), []).append(i)
    out = {}
    for members in pieces.values():
        removed: dict = {}
        for i in members:
            fl = faces[i].tolist()
            for a, b in zip(fl, fl[1:] + fl[:1], strict=True):
                key = min(a, b) * n + max(a, b)
                removed[key] = removed.get(key, 0) + 1
        left = [count[k] - r for k, r in removed.items()]
        if all(x == 0 or x == 2 for x in left) and any(x == 2 for x in left):
            out.update({i: partner[i] for i in members})
    return out


def _edge_counts(faces, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The undirected edges of ``faces`` as ``min * n + max`` and how many faces use each."""
    frm = np.concatenate(faces).astype(np.int64)
    size = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
    start = run_starts(size)
    nxt = run_next(start)
    to = frm[nxt]
    return np.unique(np.minimum(frm, to) * n + np.maximum(frm, to), return_counts=True)


def _same_cycle(a: list, b: list) -> bool:
    """Whether polygon ``b`` is polygon ``a`` in the same cyclic order (same vertex set)."""
    k = b.index(a[0])
    return b[k:] + b[:k] == a


# ------------------------------------------------------------------------- non-manifold
def split_non_manifold(faces, origin, v, vorig, log: RepairLog, unpaired=(), why=None):
    """Make every edge and vertex manifold by giving vertices one copy per fan.

    The corners of a vertex (one per face using it) are joined across each edge whose faces
    are paired: the two faces of an ordinary edge; around an edge shared by more than two
    faces, neighbours in the angular order around the edge, paired so that each pair's
    normals point out of the wedge between them (the two faces of one solid, where solids
    touch along an edge); an odd face out keeps the edge as a border. Each connected set of
    corners of a vertex is a fan; a vertex with several fans gets one copy per fan (the first
    keeps its index). Edges listed in ``unpaired`` (as (a, b), a < b, current indices) are
    cut open the same way, each reported with ``why[(a, b)]`` (by default: the surface cannot
    be oriented across it).

    Returns
    -------
    faces : list of (k,) int
    v : (n_vertices', 3) float
    vorig : (n_vertices',) int
        Input index of each vertex (copies keep their original's).
    """
    size = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
    start = run_starts(size)
    frm = np.concatenate(faces).astype(np.int64)
    face = run_owners(size)
    nxt = run_next(start)
    to = frm[nxt]
    n = len(v)
    lo, hi = np.minimum(frm, to), np.maximum(frm, to)
    key = lo * n + hi
    order = np.argsort(key, kind="stable")
    ks = key[order]
    bounds = np.flatnonzero(np.r_[True, ks[1:] != ks[:-1], True])
    count = np.diff(bounds)
    cut = {int(a) * n + int(b) for a, b in unpaired}
    pairs = []  # (half-edge, half-edge) joined across their edge
    two = np.flatnonzero(count == 2)
    h1, h2 = order[bounds[two]], order[bounds[two] + 1]
    keep2 = np.array([int(k) not in cut for k in ks[bounds[two]]], dtype=bool)
    pairs.append(np.stack([h1[keep2], h2[keep2]], axis=1))
    for g in np.flatnonzero(count > 2).tolist():
        hs = order[bounds[g] : bounds[g + 1]]
        a, b = int(lo[hs[0]]), int(hi[hs[0]])
        if a * n + b in cut:
            continue
        chosen, single = _pair_around_edge(hs, a, b, frm, face, start, size, v)
        pairs.append(np.asarray(chosen, dtype=np.int64).reshape(-1, 2))
        why = (
            f"shared by {len(hs)} faces: cut open so that each sheet keeps two faces "
            f"({len(chosen)} pair(s)" + (", one face left with a border there)" if single else ")")
        )
        log.add(
            "cut-edge",
            f"edge ({int(vorig[a])}, {int(vorig[b])})",
            why,
            error=f"non-manifold edge ({int(vorig[a])}, {int(vorig[b])}): shared by {len(hs)} "
            "faces (at most 2 allowed)",
            edge=(int(vorig[a]), int(vorig[b])),
        )
    for a, b in unpaired:
        ia, ib = sorted((int(vorig[a]), int(vorig[b])))
        log.add(
            "cut-edge",
            f"edge ({ia}, {ib})",
            why[(a, b)]
            if why
            else "the surface cannot be oriented consistently across it (a Moebius-like "
            "band): cut open",
            error="non-orientable surface",
            edge=(ia, ib),
        )
    pairs = np.concatenate(pairs) if pairs else np.zeros((0, 2), dtype=np.int64)
    # corner of vertex x in the face of half-edge h (h on edge (x, y)): h if h leaves x
    ha, hb = pairs[:, 0], pairs[:, 1]
    x = frm[ha]
    corner_a_x, corner_a_y = ha, nxt[ha]
    corner_b_x = np.where(frm[hb] == x, hb, nxt[hb])
    corner_b_y = np.where(frm[hb] == x, nxt[hb], hb)
    rows = np.concatenate([corner_a_x, corner_a_y])
    cols = np.concatenate([corner_b_x, corner_b_y])
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(frm), len(frm)))
    _, label = connected_components(graph, directed=False)
    # fans: distinct (vertex, label); the fan with the lowest corner keeps the vertex
    fan_key = frm * (int(label.max()) + 1) + label
    uniq, first_corner, fan_of = np.unique(fan_key, return_index=True, return_inverse=True)
    fan_of = fan_of.reshape(-1)
    fan_vertex = frm[first_corner]
    # order fans of a vertex by their lowest corner; the first keeps the index
    by = np.lexsort((first_corner, fan_vertex))
    rank = np.zeros(len(uniq), dtype=np.int64)
    sv = fan_vertex[by]
    first_of_v = np.r_[True, sv[1:] != sv[:-1]]
    group_start = np.maximum.accumulate(np.where(first_of_v, np.arange(len(sv)), 0))
    rank[by] = np.arange(len(sv)) - group_start
    extra = np.flatnonzero(rank > 0)
    new_index = fan_vertex.copy()
    new_index[extra] = n + np.arange(len(extra))
    if len(extra):
        counts = np.bincount(fan_vertex, minlength=n)
        for u in np.flatnonzero(counts > 1).tolist():
            log.add(
                "split-vertex",
                f"vertex {int(vorig[u])}",
                f"its faces form {int(counts[u])} separate fans: one copy per fan",
                error=f"non-manifold vertex {int(vorig[u])}: its faces form {int(counts[u])} "
                "separate fans (faces touching only at this vertex)",
                vertex=int(vorig[u]),
            )
    corner_vertex = new_index[fan_of]
    v2 = np.concatenate([v, v[fan_vertex[extra]]])
    vorig2 = np.concatenate([vorig, vorig[fan_vertex[extra]]])
    out = split_runs(corner_vertex, start[1:-1])
    return out, v2, vorig2


def detach_faces(faces, origin, v, vorig, he, log: RepairLog):
    """Cut off, at each edge still shared by more than two faces, every face but the first
    two: it gets its own copies of the edge's two vertices (a border there, and along its
    other edges at those vertices). The last resort after :func:`split_non_manifold`, where
    the sheets around an edge also meet elsewhere around its vertices.

    Parameters
    ----------
    he : clean._HalfEdges
        Of ``faces``.

    Returns
    -------
    faces : list of (k,) int
    v : (n_vertices', 3) float
    vorig : (n_vertices',) int
    """
    faces = [f.copy() for f in faces]
    extra_v, extra_o = [], []
    n = len(v)
    for e in np.flatnonzero(he.edge_count > 2).tolist():
        a, b = (int(x) for x in he.edge_ends[e])
        hs = np.flatnonzero(he.edge == e)
        for h in hs[2:].tolist():
            f = int(he.face[h])
            for x in (a, b):
                k = np.flatnonzero(faces[f] == x)
                if len(k):
                    faces[f][k] = n + len(extra_v)
                    extra_v.append(v[x])
                    extra_o.append(vorig[x])
        log.add(
            "cut-edge",
            f"edge ({int(vorig[a])}, {int(vorig[b])})",
            f"still shared by {len(hs)} faces once its vertices are split per fan: "
            f"{len(hs) - 2} face(s) cut off there",
            error="",
        )
    if extra_v:
        v = np.vstack([v, np.asarray(extra_v)])
        vorig = np.concatenate([vorig, np.asarray(extra_o, dtype=np.int64)])
    return faces, v, vorig


def _pair_around_edge(hs, a, b, frm, face, start, size, v):
    """Pair the half-edges ``hs`` of the faces around edge (a, b) by angular order.

    Returns the chosen pairs (list of (h, h)) and whether one face was left unpaired.
    """
    d = v[b] - v[a]
    d /= np.linalg.norm(d)
    axes = plane_axes(d)
    theta, side = [], []
    for h in hs.tolist():
        f = int(face[h])
        p = v[frm[start[f] : start[f] + size[f]]]
        w = p.mean(axis=0) - v[a]
        w -= (w @ d) * d
        theta.append(float(np.arctan2(w @ axes[1], w @ axes[0])))
        nrm = polygon_normal(p)
        side.append(float(np.sign(nrm @ np.cross(d, w))))  # +1: normal toward larger angle
    order = np.argsort(theta, kind="stable")
    hs_sorted = hs[order]
    side = np.asarray(side)[order]
    k = len(hs)

    def score(i, j):  # normals out of the wedge from i to j (i before j in angle)
        return -side[i] + side[j]

    best, best_score, single = None, -np.inf, False
    starts = range(k) if k % 2 else range(2)
    for s in starts:
        idx = [(s + t) % k for t in range(k)]
        chosen = [(idx[t], idx[t + 1]) for t in range(0, k - 1, 2)]
        total = sum(score(i, j) for i, j in chosen)
        if total > best_score:
            best, best_score, single = chosen, total, k % 2 == 1
    return [(int(hs_sorted[i]), int(hs_sorted[j])) for i, j in best], single


# ------------------------------------------------------------------------- triangulation
def triangulate_polygon_3d(p: np.ndarray) -> list[tuple[int, int, int]]:
    """Triangles (local corner indices) of a polygon ``p`` (k, 3), counter-clockwise about its
    Newell normal: a constrained Delaunay triangulation of its projection (shapely), or a fan
    from the first corner when the projection is not a simple polygon."""
    k = len(p)
    if k == 3:
        return [(0, 1, 2)]
    axes = plane_axes(polygon_normal(p))
    xy = (p - p.mean(axis=0)) @ axes.T
    poly = shapely.Polygon(xy)
    if poly.is_valid and len({tuple(q) for q in xy.tolist()}) == k:
        where = {tuple(q): i for i, q in enumerate(xy.tolist())}
        tris = []
        for t in shapely.get_parts(shapely.constrained_delaunay_triangles(poly)):
            ring = np.asarray(t.exterior.coords)[:3]
            ids = [where.get(tuple(q)) for q in ring.tolist()]
            if None in ids:
                break
            i, j, m = ids
            a, b, c = xy[i], xy[j], xy[m]
            if (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0:
                j, m = m, j
            tris.append((i, j, m))
        else:
            if len(tris) == k - 2:
                return sorted(tris)
    return [(0, i, i + 1) for i in range(1, k - 1)]


def split_into_triangles(faces, origin, v, which, log: RepairLog, why, error):
    """Replace the faces ``which`` (indices) by their triangles, choosing diagonals that are
    no edge of the mesh yet (:func:`triangulate_avoiding`).

    ``why(i)`` says what is wrong with face ``i``; ``error(o, i)`` gives the strict-mode
    message for it (``o`` its input face).

    Returns
    -------
    faces : list of (k,) int
    origin : (n_faces,) int
    v : (n_vertices', 3) float
        ``v``, with a vertex appended at the middle of each polygon that had to be split
        around one (every diagonal of it already an edge).
    """
    which = set(int(i) for i in which)
    if not which:
        return faces, origin, v
    base = len(v) + len(which)  # above every vertex index, new ones included
    used = edge_keys(faces, base)
    out, out_origin = [], []
    extra = []
    for i, (f, o) in enumerate(zip(faces, origin.tolist(), strict=True)):
        if i not in which:
            out.append(f)
            out_origin.append(o)
            continue
        tris, middle = triangulate_avoiding(f, v, used, base, len(v) + len(extra))
        how = f"split into {len(tris)} triangles"
        if middle is not None:
            extra.append(middle)
            how += (
                " around a new vertex at its middle (each of its diagonals is an edge of "
                "the mesh already)"
            )
        log.add(
            "split-face",
            f"face {o}",
            f"{why(i)}: {how} (coplanar ones are merged again into convex parts)",
            error=error(o, i),
            face=o,
        )
        out += tris
        out_origin += [o] * len(tris)
    if extra:
        v = np.vstack([v, np.asarray(extra)])
    return out, np.asarray(out_origin, dtype=np.int64), v


def edge_keys(faces, n: int) -> set:
    """The undirected edges of ``faces`` as ``min * n + max`` (``n`` above every vertex
    index)."""
    if not faces:
        return set()
    return set(_edge_counts(faces, n)[0].tolist())


def triangulate_avoiding(f: np.ndarray, v: np.ndarray, used: set, base: int, new: int):
    """Triangles of polygon ``f`` (vertex indices into ``v``) none of whose diagonals is in
    ``used`` (undirected edges as ``min * base + max``, see :func:`edge_keys`), which gets
    the diagonals chosen.

    Tries :func:`triangulate_polygon_3d`, then the fans from each corner whose triangles all face
    the polygon's way; when each of these reuses an edge (two polygons on the same pair of
    opposite corners: their triangles would be one doubled triangle), a fan around a new
    vertex ``new`` at the polygon's centroid. Two faces sharing a diagonal would make it an
    edge of three or four faces, or of two in the same direction.

    Returns
    -------
    triangles : list of (3,) int
    middle : (3,) float or None
        The new vertex, when the fan around it was needed.
    """
    k = len(f)
    fl = f.tolist()
    p = v[f]
    n = base
    own = {min(a, b) * n + max(a, b) for a, b in zip(fl, fl[1:] + fl[:1], strict=True)}

    def diagonals(tris):
        keys = set()
        for t in tris:
            for x, y in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
                a, b = fl[x], fl[y]
                keys.add(min(a, b) * n + max(a, b))
        return keys - own

    first = triangulate_polygon_3d(p)
    options = [first]
    if k > 3:
        axes = plane_axes(polygon_normal(p))
        xy = (p - p.mean(axis=0)) @ axes.T
        scale = float(np.ptp(xy, axis=0).max()) ** 2
        for c in range(k):
            fan = [(c, (c + j) % k, (c + j + 1) % k) for j in range(1, k - 1)]
            if all(_area2(xy, t) > 1e-12 * scale for t in fan):
                options.append(fan)
    for tris in options:
        d = diagonals(tris)
        if not d & used:
            used |= d
            return [f[list(t)] for t in tris], None
    if k > 3:
        middle = p.mean(axis=0)
        c_xy = (middle - p.mean(axis=0)) @ axes.T
        ring = np.vstack([xy, c_xy])
        fan = [(k, i, (i + 1) % k) for i in range(k)]
        if all(_area2(ring, t) > 1e-12 * scale for t in fan):
            out = [np.array([new, fl[i], fl[(i + 1) % k]], dtype=np.int64) for i in range(k)]
            return out, middle
    used |= diagonals(first)  # nothing better: the shared edge is left to the checks
    return [f[list(t)] for t in first], None


def _area2(xy: np.ndarray, t) -> float:
    """Twice the signed area of triangle ``t`` (local indices) of the 2D points ``xy``."""
    a, b, c = xy[t[0]], xy[t[1]], xy[t[2]]
    return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


# ------------------------------------------------------------------------- exact planes
def planarize(faces, v, log: RepairLog, *, rounds: int = 8, rel: float = 1e-15):
    """Move vertices onto the planes of their polygons, so every polygon of more than three
    corners is planar to round-off (not only within ``tol.planar``).

    A polygon planar only within a tolerance (a CAD export in float32, a merged region)
    leaves its edges a little out of its plane, and the development's gluing maps are then
    not rigid at the square of that angle: ruling lengths in 2D and 3D part by ~1e-11 where
    1e-16 is due. Each round fits every polygon's plane (Newell normal through the centroid)
    and takes the smallest joint Gauss-Newton step of the vertices and the planes (each plane
    shifted and turned) that puts every corner on its polygon's plane (:func:`_plane_step`,
    one sparse direct solve; a vertex's own least-squares step, round by round, converged too
    slowly on a quad torus in float32). Holding the normals instead, as before, made the
    system ill-conditioned wherever two polygons meet at a small angle: on the pyvista
    airplane its least-norm step moved vertices by 30 units for deviations of 5e-7 of a
    polygon, and the iterative solver stopped at its condition limit after 8 rounds of 11,000
    iterations with half the polygons still off their planes. The step is first order in the
    deviation, so two or three rounds bring every corner within ``rel`` of its polygon's
    diameter from the plane.

    Parameters
    ----------
    faces : list of (k,) int
    v : (n_vertices, 3) float
    log : RepairLog
    rounds : int
    rel : float

    Returns
    -------
    v : (n_vertices, 3) float
        The moved vertices (a copy; ``v`` itself when nothing moved).
    residual : (n_faces,) float
        Each polygon's largest corner distance from its plane over its diameter, afterwards
        (0 for triangles, and where it is within the rounding of the coordinates).
    """
    poly = np.flatnonzero(np.fromiter(map(len, faces), dtype=np.int64, count=len(faces)) > 3)
    residual = np.zeros(len(faces))
    if not len(poly):
        return v, residual
    size = np.array([len(faces[i]) for i in poly.tolist()])
    start = run_starts(size)
    idx = np.concatenate([faces[i] for i in poly.tolist()])
    face = run_owners(size)
    nxt = run_next(start)
    x = v.copy()
    diam = np.maximum.reduceat(np.linalg.norm(x[idx] - x[idx[nxt]], axis=1), start[:-1])

    def deviation(x):
        p = x[idx]
        c = np.add.reduceat(p, start[:-1], axis=0) / size[:, None]
        q = p - c[face]
        n = np.add.reduceat(np.cross(q, q[nxt]), start[:-1], axis=0)
        n /= np.linalg.norm(n, axis=1)[:, None]
        d = np.einsum("ij,ij->i", q, n[face])  # signed distance of each corner
        return n, (d, q), np.maximum.reduceat(np.abs(d), start[:-1]) / diam

    n, d, dev = deviation(x)
    cap = 16.0 * float((dev * diam).max())  # how far a vertex may move
    # what the coordinates' own rounding leaves (a mesh far from the origin)
    floor = 8.0 * np.finfo(float).eps * float(np.abs(x[idx]).max()) / diam
    for _ in range(rounds):
        if (dev <= np.maximum(rel, floor)).all():
            break
        x = x + _plane_step(idx, face, n, *d, diam, len(x))
        n, d, dev = deviation(x)
    far = np.linalg.norm(x - v, axis=1) > cap  # not a small correction: leave those be
    if far.any():
        x[far] = v[far]
        dev = deviation(x)[2]
    residual[poly] = np.where(dev <= floor, 0.0, dev)
    moved = np.linalg.norm(x - v, axis=1)
    if moved.max() > 0:
        box = np.ptp(v[np.unique(idx)], axis=0)
        scale = float(np.linalg.norm(box)) or 1.0
        log.add(
            "planarize",
            f"{int((moved > 0).sum())} vertices",
            f"moved by at most {moved.max():.2g} ({moved.max() / scale:.2g} of the mesh size) "
            "onto the planes of their polygons, which were planar only within the tolerance",
            error="",
        )
        return x, residual
    return v, residual


def _plane_step(idx, face, n, d, q, diam, n_vertices: int) -> np.ndarray:
    """(n_vertices, 3) float: the least-norm Gauss-Newton step of the vertices toward their
    polygons' planes, the planes free to move.

    At every corner ``(i, f)`` (corner ``idx``, polygon ``face``, unit normal ``n_f``, signed
    distance ``d`` from the plane, ``q`` from the polygon's centroid) the linearised distance
    afterwards is ``d + n_f . dx_i + dn_f . q - dh_f``: the vertex moves by ``dx_i``, the
    plane is shifted by ``dh_f`` and turned by ``dn_f = (a_f t1_f + b_f t2_f) / diam_f``
    (``t1, t2`` across the normal, ``a, b`` lengths like ``dx``). The step is the ``z = (dx,
    dh, a, b)`` of least norm that zeroes it, ``z = A^T y`` with ``(A A^T) y = -d``: one row
    per corner, a sparse symmetric system factorised directly (a ``1e-12`` ridge keeps it
    definite where the rows depend on each other)."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import spsolve

    m, n_faces = len(idx), len(n)
    t1 = np.cross(n, np.eye(3)[np.argmin(np.abs(n), axis=1)])
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    t2 = np.cross(n, t1)
    scale = 1.0 / diam[face]
    rows = np.repeat(np.arange(m), 6)
    base = 3 * n_vertices
    cols = np.stack(
        [
            3 * idx,
            3 * idx + 1,
            3 * idx + 2,
            base + face,
            base + n_faces + face,
            base + 2 * n_faces + face,
        ],
        axis=1,
    ).ravel()
    vals = np.concatenate(
        [
            n[face],
            -np.ones((m, 1)),
            (np.einsum("ij,ij->i", q, t1[face]) * scale)[:, None],
            (np.einsum("ij,ij->i", q, t2[face]) * scale)[:, None],
        ],
        axis=1,
    ).ravel()
    a = sp.csr_matrix((vals, (rows, cols)), shape=(m, base + 3 * n_faces))
    normal = (a @ a.T + REGULARISE * sp.identity(m, format="csr")).tocsc()
    y = spsolve(normal, -d, permc_spec="MMD_AT_PLUS_A")
    return (a.T @ y)[:base].reshape(-1, 3)
