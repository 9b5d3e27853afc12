"""Polylines for cut files: pattern edges chained into paths, tab outlines split at their hinge.

Cutting machines and CAD programs want a curved crease as one path, not as hundreds of short
segments. :func:`edge_chains` joins edges of one kind end to end through every vertex where
exactly two of them meet; :func:`chain_is_smooth` decides whether a path may be written as a
spline through its points; :func:`tab_cut_paths` gives the part of each glue-tab outline that is
cut (all of it except the hinge it shares with its piece).
"""

from __future__ import annotations

import itertools

import numpy as np

from ..arrays import run_owners, run_starts, split_runs
from ..surface.pattern import Annotations, CreasePattern, LabelRows, PointRows

__all__ = [
    "SPLINE_MAX_SPACING_RATIO",
    "SPLINE_MAX_TURN_DEG",
    "SPLINE_MIN_POINTS",
    "annotation_points",
    "chain_is_smooth",
    "chain_runs",
    "dash_polylines",
    "drawn_points",
    "edge_chains",
    "edge_layer_masks",
    "label_positions",
    "pattern_extent",
    "point_rows",
    "polyline_length",
    "simplify_polyline",
    "simplify_polylines",
    "tab_cut_paths",
]

#: A chain becomes a spline only with at least this many points (shorter ones stay polylines).
SPLINE_MIN_POINTS = 7
#: Largest turning angle (degrees) between consecutive segments of a spline-smooth chain. A
#: spline through points of a curve that turns ``d`` radians per segment differs in length from
#: the polyline by about ``d**2 / 24`` relative: 8 degrees keeps that under 1e-3.
SPLINE_MAX_TURN_DEG = 8.0
#: Largest ratio of the lengths of two consecutive segments of a spline-smooth chain (uneven
#: spacing makes interpolating splines overshoot).
SPLINE_MAX_SPACING_RATIO = 3.0
#: Interior points where a path turns by less than this (radians) are dropped as collinear.
_COLLINEAR_RAD = 1e-7
#: Relative tolerance (of the outline size) for matching a tab's hinge to its outline edges.
_HINGE_RTOL = 1e-7


def edge_layer_masks(pattern: CreasePattern, *, flat_edges: bool = False) -> dict:
    """Which pattern edges go on which cut-file layer.

    Parameters
    ----------
    pattern : CreasePattern
    flat_edges : bool
        Include the ``"FLAT"`` layer (``F`` edges).

    Returns
    -------
    dict of str to (m,) bool
        ``"CUT"`` (``B`` edges), ``"MOUNTAIN"`` (``M``), ``"VALLEY"`` (``V``) and, with
        ``flat_edges``, ``"FLAT"`` (``F``), in that order.
    """
    assign = np.asarray(pattern.edge_assignment)
    masks = {"CUT": assign == "B", "MOUNTAIN": assign == "M", "VALLEY": assign == "V"}
    if flat_edges:
        masks["FLAT"] = assign == "F"
    return masks


def edge_chains(edges: np.ndarray, mask: np.ndarray | None = None) -> list[tuple[np.ndarray, bool]]:
    """Join edges end to end into maximal paths through vertices of degree two.

    A vertex where one, three or more of the selected edges meet ends every path through it;
    a vertex where exactly two meet is passed through. Loops of degree-two vertices become
    closed paths. The order is deterministic: open paths start at their lowest end vertex (in
    order of that vertex, then of the first edge), closed ones at their lowest-numbered edge.

    Every path is walked at once, one edge per step for all of them (numpy), so the time
    grows with the edges and the longest path, not with one Python step per edge.

    Parameters
    ----------
    edges : (m, 2) int
        Pattern edges.
    mask : (m,) bool, optional
        The edges to chain (default all).

    Returns
    -------
    list of ((k,) int, bool)
        The vertex indices of each path and whether it is closed (then the first vertex is not
        repeated at the end). Every selected edge is in exactly one path.
    """
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    ids = np.arange(len(edges)) if mask is None else np.flatnonzero(mask)
    if len(ids) == 0:
        return []
    ends = edges[ids]  # the selected edges, numbered 0..m-1 in the order of their ids
    m = len(ends)
    # incidences (vertex, edge), sorted by vertex, then edge
    inc_v = ends.ravel()
    inc_e = np.repeat(np.arange(m), 2)
    order = np.lexsort((inc_e, inc_v))
    sv, se = inc_v[order], inc_e[order]
    _, deg = np.unique(sv, return_counts=True)
    deg_sorted = np.repeat(deg, deg)
    # at a vertex of degree two, each of its two edges leads on to the other
    pair = np.flatnonzero(deg_sorted == 2)
    other_sorted = np.full(2 * m, -1, dtype=np.int64)
    other_sorted[pair[0::2]], other_sorted[pair[1::2]] = se[pair[1::2]], se[pair[0::2]]
    nxt = np.empty(2 * m, dtype=np.int64)  # per edge end: the edge after it, or -1
    nxt[order] = other_sorted
    nxt = nxt.reshape(m, 2)

    # open paths (and loops through a vertex of another degree): from every such incidence
    start_inc = np.flatnonzero(deg_sorted != 2)
    s_vertex, s_edge = sv[start_inc], se[start_inc]
    paths, final, last, walk_of, walked = _walk_chains(ends, nxt, s_vertex, s_edge)
    closed = final == s_vertex
    # a path is walked from both of its ends: keep the walk from the lower one (from the
    # lower-numbered edge of a loop through one vertex; a self-loop's two incidences once)
    keep = (final > s_vertex) | (closed & (s_edge <= last))
    keep[1:] &= (s_vertex[1:] != s_vertex[:-1]) | (s_edge[1:] != s_edge[:-1])
    chains = [
        (paths[k][:-1] if closed[k] else paths[k], bool(closed[k]))
        for k in np.flatnonzero(keep).tolist()
    ]
    used = np.zeros(m, dtype=bool)
    used[walked[keep[walk_of]]] = True

    # loops of degree-two vertices only: from their lowest-numbered edge, along it
    rest = np.flatnonzero(~used)
    if len(rest):
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        n_v = int(ends.max()) + 1
        a, b = ends[rest, 0], ends[rest, 1]
        graph = coo_matrix((np.ones(len(rest)), (a, b)), shape=(n_v, n_v))
        _, label = connected_components(graph, directed=False)
        _, first = np.unique(label[a], return_index=True)
        e0 = np.sort(rest[first])  # ``rest`` ascends: a loop's first edge is its lowest
        loops = _walk_chains(ends, nxt, ends[e0, 0], e0)[0]
        chains.extend((q[:-1], True) for q in loops)
    return chains


def _walk_chains(ends, nxt, start_vertex, start_edge):
    """Walk from every ``start_vertex`` along ``start_edge`` through vertices of degree two
    (``nxt``: the edge after each edge end, or -1), all walks one edge per step, until a
    vertex of another degree or the start again.

    Returns
    -------
    paths : list of (k,) int
        The vertices of each walk, the start first (a walk back to its start ends with it).
    final : (w,) int
        The vertex each walk ends at.
    last : (w,) int
        The last edge of each walk.
    walk_of, walked : (h,) int
        Each edge walked (``walked``) and its walk (``walk_of``).
    """
    w = len(start_vertex)
    start_vertex = np.asarray(start_vertex, dtype=np.int64)
    cur_v = start_vertex.copy()
    cur_e = np.asarray(start_edge, dtype=np.int64).copy()
    last, final = cur_e.copy(), cur_v.copy()
    active = np.arange(w)
    rec_walk, rec_vertex, rec_edge = [active], [cur_v.copy()], []
    for _ in range(len(ends) + 1):
        if not len(active):
            break
        e = cur_e[active]
        far = (ends[e, 0] == cur_v[active]).astype(np.int64)  # the end the walk arrives at
        v = ends[e, far]
        rec_walk.append(active)
        rec_vertex.append(v)
        rec_edge.append(e)
        last[active], final[active] = e, v
        on = nxt[e, far]
        go = (v != start_vertex[active]) & (on >= 0)
        active = active[go]
        cur_v[active], cur_e[active] = v[go], on[go]
    walk = np.concatenate(rec_walk)
    by_walk = np.argsort(walk, kind="stable")  # each walk's vertices in the order visited
    counts = np.bincount(walk, minlength=w)
    paths = split_runs(np.concatenate(rec_vertex)[by_walk], np.cumsum(counts)[:-1]) if w else []
    walk_of = np.concatenate([np.zeros(0, dtype=np.int64), *rec_walk[1:]])
    walked = np.concatenate([np.zeros(0, dtype=np.int64), *rec_edge])
    return paths, final, last, walk_of, walked


def polyline_length(points: np.ndarray, closed: bool = False) -> float:
    """Length of a polyline.

    Parameters
    ----------
    points : (k, d) float
    closed : bool
        Add the segment from the last point back to the first.

    Returns
    -------
    float
    """
    p = np.asarray(points, dtype=np.float64)
    if closed and len(p) > 1:
        p = np.vstack([p, p[:1]])
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


def chain_is_smooth(points: np.ndarray, closed: bool = False) -> bool:
    """Whether a path may be written as a spline through its points.

    The rule: at least :data:`SPLINE_MIN_POINTS` points, no zero-length segment, every turning
    angle between consecutive segments at most :data:`SPLINE_MAX_TURN_DEG` degrees (including
    the closing corner of a closed path), and consecutive segment lengths within a factor
    :data:`SPLINE_MAX_SPACING_RATIO` of each other.

    Parameters
    ----------
    points : (k, 2) float
    closed : bool

    Returns
    -------
    bool
    """
    p = np.asarray(points, dtype=np.float64)
    if len(p) < SPLINE_MIN_POINTS:
        return False
    if closed:
        p = np.vstack([p, p[:2]])
    d = np.diff(p, axis=0)
    length = np.linalg.norm(d, axis=1)
    if not (length > 0).all():
        return False
    ratio = length[1:] / length[:-1]
    if ratio.max() > SPLINE_MAX_SPACING_RATIO or ratio.min() < 1.0 / SPLINE_MAX_SPACING_RATIO:
        return False
    u = d / length[:, None]
    cos = np.clip(np.einsum("ij,ij->i", u[1:], u[:-1]), -1.0, 1.0)
    return bool(np.degrees(np.arccos(cos)).max() <= SPLINE_MAX_TURN_DEG)


def simplify_polyline(points: np.ndarray, closed: bool = False) -> np.ndarray:
    """Drop repeated points and interior points where the path goes straight on.

    A point is dropped when the path turns there by less than ``1e-7`` radians, so the length
    changes by a relative amount of order ``1e-14``.

    Parameters
    ----------
    points : (k, 2) float
    closed : bool
        The path returns from the last point to the first (the first point may then go too).

    Returns
    -------
    (j, 2) float
        ``j >= 2`` for an open path of two distinct points or more.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    keep = np.ones(len(p), dtype=bool)
    keep[1:] = np.any(p[1:] != p[:-1], axis=1)
    p = p[keep]
    if closed and len(p) > 1 and np.array_equal(p[0], p[-1]):
        p = p[:-1]
    changed = True
    while changed and len(p) > (3 if closed else 2):
        prev = np.roll(p, 1, axis=0)
        nxt = np.roll(p, -1, axis=0)
        a, b = p - prev, nxt - p
        cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        dot = np.einsum("ij,ij->i", a, b)
        straight = (np.abs(np.arctan2(cross, dot)) < _COLLINEAR_RAD) & (dot > 0)
        if not closed:
            straight[[0, -1]] = False
        # never drop two neighbours at once (their turn was measured against each other)
        straight[1:] &= ~straight[:-1]
        changed = bool(straight.any())
        p = p[~straight]
    return p


def simplify_polylines(paths: list) -> list[np.ndarray]:
    """:func:`simplify_polyline` of every ``(points, closed)`` of ``paths``, all paths at once:
    each round drops, on every path that still changes, the points it would drop in that
    round (the same arrays as one by one).

    Parameters
    ----------
    paths : list of ((k, 2) float, bool)

    Returns
    -------
    list of (j, 2) float
    """
    if not paths:
        return []
    pts = [np.asarray(q, dtype=np.float64).reshape(-1, 2) for q, _ in paths]
    n = len(pts)
    size = np.fromiter(map(len, pts), dtype=np.int64, count=n)
    closed = np.fromiter((bool(c) for _, c in paths), dtype=bool, count=n)
    p = np.concatenate(pts)
    owner = run_owners(size)
    # repeated points go, and a closed path's last point where it repeats the first
    keep = np.ones(len(p), dtype=bool)
    keep[1:] = (owner[1:] != owner[:-1]) | np.any(p[1:] != p[:-1], axis=1)
    p, owner = p[keep], owner[keep]
    size = np.bincount(owner, minlength=n)
    end = np.cumsum(size) - 1
    again = closed & (size > 1)
    again[again] = np.all(p[end[again] - size[again] + 1] == p[end[again]], axis=1)
    if again.any():
        keep = np.ones(len(p), dtype=bool)
        keep[end[again]] = False
        p, owner = p[keep], owner[keep]
        size = np.bincount(owner, minlength=n)
    least = np.where(closed, 3, 2)
    active = size > least
    while active.any():
        first = run_starts(size)[:-1]
        at = np.arange(len(p)) - first[owner]
        on = active[owner]
        k = np.flatnonzero(on)
        o = owner[k]
        prev = np.where(at[k] == 0, k + size[o] - 1, k - 1)
        nxt = np.where(at[k] == size[o] - 1, k - size[o] + 1, k + 1)
        a, b = p[k] - p[prev], p[nxt] - p[k]
        cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        dot = np.einsum("ij,ij->i", a, b)
        straight = (np.abs(np.arctan2(cross, dot)) < _COLLINEAR_RAD) & (dot > 0)
        straight &= closed[o] | ((at[k] > 0) & (at[k] < size[o] - 1))
        # never two neighbours at once: a point goes only if the one before it (on its path,
        # in the path's order) does not
        before = np.zeros(len(k), dtype=bool)
        before[1:] = straight[:-1] & (o[1:] == o[:-1])
        straight &= ~before
        changed = np.bincount(o[straight], minlength=n) > 0
        drop = np.zeros(len(p), dtype=bool)
        drop[k[straight]] = True
        p, owner = p[~drop], owner[~drop]
        size = np.bincount(owner, minlength=n)
        active &= changed & (size > least)
    return split_runs(p, np.cumsum(size)[:-1])


def chain_runs(points: np.ndarray, closed: bool = False) -> list[tuple[np.ndarray, bool, bool]]:
    """Split a path into spline runs and polyline runs.

    The path is first simplified (:func:`simplify_polyline`), then cut at its *breaks*: points
    where it turns by more than :data:`SPLINE_MAX_TURN_DEG` or where the lengths of the two
    segments differ by more than a factor :data:`SPLINE_MAX_SPACING_RATIO` (a corner, or the
    end of a sampled curve meeting a straight segment). A run between two breaks with at least
    :data:`SPLINE_MIN_POINTS` points is a spline; neighbouring runs that are not are joined into
    one polyline.

    Parameters
    ----------
    points : (k, 2) float
    closed : bool

    Returns
    -------
    list of ((j, 2) float, bool, bool)
        Each run's points, whether it is a spline, and whether it is closed (only a path that is
        one run: a closed polyline, or a closed spline whose last point repeats its first).
        Consecutive runs share their end points; together they trace the path.
    """
    p = simplify_polyline(points, closed)
    if len(p) < 2:
        return []
    if closed:
        if len(p) < 3:
            return [(p, False, False)]
        brk = _breaks(np.vstack([p[-1:], p, p[:1]]))
        if not brk.any():
            if chain_is_smooth(p, closed=True):
                return [(np.vstack([p, p[:1]]), True, True)]
            return [(p, False, True)]
        start = int(np.flatnonzero(brk)[0])
        p = np.vstack([np.roll(p, -start, axis=0), p[start : start + 1]])
        inner = np.roll(brk, -start)[1:]
    else:
        inner = _breaks(p) if len(p) > 2 else np.zeros(0, dtype=bool)
    cuts = [0, *(np.flatnonzero(inner) + 1).tolist(), len(p) - 1]
    runs: list[tuple[np.ndarray, bool, bool]] = []
    for a, b in itertools.pairwise(cuts):
        run = p[a : b + 1]
        spline = len(run) >= SPLINE_MIN_POINTS and chain_is_smooth(run)
        if runs and not spline and not runs[-1][1]:
            runs[-1] = (np.vstack([runs[-1][0], run[1:]]), False, False)
        else:
            runs.append((run, spline, False))
    if closed and len(runs) == 1 and not runs[0][1]:
        return [(runs[0][0][:-1], False, True)]
    return runs


def dash_polylines(points: np.ndarray, closed: bool, dash: float, gap: float) -> list[np.ndarray]:
    """Cut a path into dashes of length ``dash`` with ``gap`` between them (a perforation).

    The dashes are centred on the path: ``n = floor((L + gap) / (dash + gap))`` of them for a
    path of length ``L``, with equal leftovers at both ends. A path shorter than one dash and
    one gap gets one centred dash of ``dash / (dash + gap)`` of its length. A dash follows the
    path through its corners.

    Parameters
    ----------
    points : (k, 2) float
    closed : bool
        The path returns from the last point to the first.
    dash, gap : float
        Positive lengths.

    Returns
    -------
    list of (j, 2) float
        The dashes, in order along the path, each from its start to its end point.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if closed and len(p) > 1:
        p = np.vstack([p, p[:1]])
    if len(p) < 2:
        return []
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    length = float(s[-1])
    if not length > 0:
        return []
    period = dash + gap
    n = int(np.floor((length + gap) / period))
    if n == 0:
        n, dash = 1, length * dash / period
    start = 0.5 * (length - (n * dash + (n - 1) * gap))
    a = start + period * np.arange(n)
    b = a + dash
    ends = np.c_[np.interp(a, s, p[:, 0]), np.interp(a, s, p[:, 1])]
    tips = np.c_[np.interp(b, s, p[:, 0]), np.interp(b, s, p[:, 1])]
    lo = np.searchsorted(s, a, side="right")  # first path point after the dash's start
    hi = np.searchsorted(s, b, side="left")  # first path point at or after its end
    return [np.vstack([ends[i], p[lo[i] : hi[i]], tips[i]]) for i in range(n)]


def _breaks(p: np.ndarray) -> np.ndarray:
    """(k - 2,) bool: interior points of the open path ``p`` (k, 2) that break a spline run."""
    d = np.diff(p, axis=0)
    length = np.linalg.norm(d, axis=1)
    u = d / length[:, None]
    cos = np.clip(np.einsum("ij,ij->i", u[1:], u[:-1]), -1.0, 1.0)
    turn = np.degrees(np.arccos(cos))
    ratio = length[1:] / length[:-1]
    return (
        (turn > SPLINE_MAX_TURN_DEG)
        | (ratio > SPLINE_MAX_SPACING_RATIO)
        | (ratio < 1.0 / SPLINE_MAX_SPACING_RATIO)
    )


def tab_cut_paths(annotations: Annotations) -> list[tuple[np.ndarray, bool]]:
    """The cut part of each glue-tab outline: the outline without its hinge.

    An outline edge whose two ends lie on the tab's hinge segment is the hinge (folded, not
    cut); the remaining edges form one open path. When no edge matches the hinge (or there is no
    hinge for the tab), the whole outline is cut as a closed path.

    Parameters
    ----------
    annotations : Annotations

    Returns
    -------
    list of ((k, 2) float, bool)
        One path per tab: its points and whether it is closed.
    """
    flat, size = point_rows(annotations.tabs)
    n = len(size)
    if n == 0:
        return []
    rows = annotations.tab_hinges
    if isinstance(rows, PointRows) and (np.diff(rows.start) == 2).all():
        hinges = rows.points.reshape(-1, 2, 2)[:n]  # one array, no object per tab
    else:
        hinges = [np.asarray(h, dtype=np.float64).reshape(2, 2) for h in list(rows)[:n]]
        hinges = np.array(hinges).reshape(-1, 2, 2)
    first = run_starts(size)[:-1]
    # a closing point that repeats the first is dropped
    repeat = size > 1
    repeat[repeat] = (flat[first[repeat]] == flat[(first + size - 1)[repeat]]).all(axis=1)
    size = size - repeat
    paths: list = [None] * n  # of each tab: its paths (the whole outline, closed, when None)
    hinged = np.flatnonzero((np.arange(n) < len(hinges)) & (size >= 2))
    for k in np.unique(size[hinged]).tolist():
        ids = hinged[size[hinged] == k]
        pts = flat[first[ids, None] + np.arange(k)]  # (m, k, 2)
        hinge = hinges[ids]  # (m, 2, 2)
        eps = _HINGE_RTOL * np.maximum(np.ptp(pts, axis=1).max(axis=1), 1.0)
        on_hinge, unsure = _on_segments(pts, hinge, eps)
        for j in np.flatnonzero(unsure).tolist():  # a point at the tolerance: as before
            on_hinge[j] = _on_segment(pts[j], hinge[j], float(eps[j]))
        is_hinge_edge = on_hinge & np.roll(on_hinge, -1, axis=1)  # edge i -> i + 1
        count = is_hinge_edge.sum(axis=1)
        # one hinge edge: the path is the outline from the point after it, once round
        one = np.flatnonzero(count == 1)
        start = (np.argmax(is_hinge_edge[one], axis=1) + 1)[:, None]
        rolled = pts[one[:, None], (start + np.arange(k)) % k]
        for i, path in zip(ids[one].tolist(), rolled, strict=True):
            paths[i] = [(path, False)]
        for j in np.flatnonzero((count > 1) & (count < k)).tolist():
            paths[ids[j]] = _tab_cut_path(pts[j], is_hinge_edge[j])
    end = (first + size).tolist()
    out = []
    for i, (a, tab) in enumerate(zip(first.tolist(), paths, strict=True)):
        if tab is None:
            out.append((flat[a : end[i]], True))
        else:
            out += tab
    return out


def _tab_cut_path(p: np.ndarray, is_hinge_edge: np.ndarray) -> list[tuple[np.ndarray, bool]]:
    """The cut paths of one tab outline ``p`` (k, 2): the runs of the edges that are not its
    hinge (``is_hinge_edge`` (k,) bool: edge i -> i + 1), from right after the last hinge edge;
    the whole outline, closed, when none or every edge is the hinge."""
    if not is_hinge_edge.any() or is_hinge_edge.all():
        return [(p, True)]
    # start right after the last hinge edge, walk the non-hinge edges
    k = len(p)
    start = (int(np.flatnonzero(is_hinge_edge)[-1]) + 1) % k
    order = [(start + i) % k for i in range(k + 1)]
    pieces, current = [], [p[order[0]]]
    for i in range(k):
        a = order[i]
        if is_hinge_edge[a]:
            if len(current) > 1:
                pieces.append(np.array(current))
            current = [p[order[i + 1]]]
        else:
            current.append(p[order[i + 1]])
    if len(current) > 1:
        pieces.append(np.array(current))
    return [(piece, False) for piece in pieces]


def _on_segment(p: np.ndarray, seg: np.ndarray, eps: float) -> np.ndarray:
    """(k,) bool: points of ``p`` (k, 2) within ``eps`` of the segment ``seg`` (2, 2)."""
    a, b = seg
    d = b - a
    dd = float(d @ d)
    t = np.clip(((p - a) @ d) / dd, 0.0, 1.0) if dd > 0 else np.zeros(len(p))
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1) <= eps


def _on_segments(p: np.ndarray, seg: np.ndarray, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_on_segment` of many outlines at once.

    Parameters
    ----------
    p : (m, k, 2) float
        The points of ``m`` outlines.
    seg : (m, 2, 2) float
        Each outline's segment.
    eps : (m,) float
        Each outline's tolerance.

    Returns
    -------
    on : (m, k) bool
        The points within ``eps`` of their segment.
    unsure : (m,) bool
        The outlines with a point whose distance is within round-off of ``eps`` (or not
        finite): there ``on`` may differ from :func:`_on_segment`'s in the last bit.
    """
    a = seg[:, None, 0]
    d = seg[:, None, 1] - a  # (m, 1, 2)
    dd = d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1]
    q = p - a
    ok = dd > 0
    t = np.clip((q[..., 0] * d[..., 0] + q[..., 1] * d[..., 1]) / np.where(ok, dd, 1.0), 0.0, 1.0)
    r = p - (a + np.where(ok, t, 0.0)[..., None] * d)
    dist = np.sqrt(r[..., 0] * r[..., 0] + r[..., 1] * r[..., 1])
    scale = np.maximum(np.abs(p).max(axis=(1, 2)), np.abs(seg).max(axis=(1, 2)))
    margin = 1e-9 * (eps + scale)
    unsure = ~(np.abs(dist - eps[:, None]) > margin[:, None]).all(axis=1)
    return dist <= eps[:, None], unsure


def annotation_points(annotations: Annotations) -> np.ndarray:
    """(k, 2) float: every point of the annotations (tab corners, hinge ends, label anchors,
    sheet corners), for bounding boxes."""
    return _annotation_points(annotations, label_positions(annotations.labels))


def _annotation_points(annotations: Annotations, labels: np.ndarray) -> np.ndarray:
    """:func:`annotation_points` with the label positions (n, 2) given."""
    sheets = np.asarray(annotations.sheets, dtype=np.float64).reshape(-1, 4)
    return np.concatenate(
        [
            point_rows(annotations.tabs)[0],
            point_rows(annotations.tab_hinges)[0],
            labels,
            sheets[:, :2],
            sheets[:, 2:],
        ]
    )


def point_rows(rows: list) -> tuple[np.ndarray, np.ndarray]:
    """The points of a list of point arrays (tab outlines, hinges), each row read as
    ``np.asarray(row, dtype=np.float64).reshape(-1, 2)``, all at once when they are (k, 2)
    arrays of numbers.

    Parameters
    ----------
    rows : list of array_like

    Returns
    -------
    points : (k, 2) float
        The points of every row, one row after the other.
    sizes : (n,) int
        The number of points of each row.
    """
    if isinstance(rows, PointRows):
        return rows.points, np.diff(rows.start)
    try:
        flat = np.concatenate(rows) if rows else np.zeros((0, 2))
    except ValueError:  # rows of several dimensions
        flat = None
    if flat is None or flat.ndim != 2 or flat.shape[1] != 2 or flat.dtype.kind not in "biuf":
        parts = [np.asarray(r, dtype=np.float64).reshape(-1, 2) for r in rows]
        flat = np.concatenate([np.zeros((0, 2)), *parts])
        return flat, np.fromiter(map(len, parts), dtype=np.int64, count=len(parts))
    return np.asarray(flat, dtype=np.float64), np.fromiter(map(len, rows), np.int64, len(rows))


def label_positions(labels: list) -> np.ndarray:
    """(n, 2) float: the position of every label (each read as ``reshape(2)``)."""
    return LabelRows.of(labels).position


def pattern_extent(pattern: CreasePattern) -> tuple[np.ndarray, np.ndarray]:
    """Bounding box of the pattern and its annotations in pattern coordinates.

    Label text is counted by its anchor and an estimate of its width.

    Returns
    -------
    lo, hi : (2,) float
        ``(0, 0)`` and ``(1, 1)`` for an empty pattern.
    """
    allp = drawn_points(pattern)
    if len(allp) == 0:
        return np.zeros(2), np.ones(2)
    return allp.min(axis=0), allp.max(axis=0)


def drawn_points(pattern: CreasePattern, sheets: bool = True) -> np.ndarray:
    """(k, 2) float: the points that bound what is drawn of a pattern: its vertices, its
    annotations' points (the sheets' corners unless ``sheets`` is False), and each label's
    text (its anchor and an estimate of its width)."""
    labels = LabelRows.of(pattern.annotations.labels)
    centre, height = labels.position, labels.height
    chars = np.fromiter(map(len, labels.text), np.int64, len(labels))
    half = (0.5 * height * np.maximum(chars, 1).astype(np.float64) * 0.6)[:, None]
    ann = pattern.annotations
    pts = [
        np.asarray(pattern.vertices_2d, dtype=np.float64).reshape(-1, 2),
        _annotation_points(ann, centre) if sheets else point_rows(ann.tabs)[0],
        centre - half,
        centre + half,
    ]
    return np.concatenate(pts)
