"""The glue tabs as they were placed before :mod:`filletfold.layout.tabs` worked on arrays: one
shapely geometry at a time. Kept as the reference that the array version must match exactly
(the same tabs, hinges, labels and seams, to the bit).
"""

from __future__ import annotations

import numpy as np
import shapely

from filletfold.surface.pattern import Annotations, CreasePattern, Label


def _seam_pairs(p: CreasePattern, decimals: int = 9) -> list[tuple[int, int]]:
    """Pairs of pattern edges that are the two sides of one cut."""
    mask = p.cut_mask(decimals)
    groups: dict[tuple, list[int]] = {}
    for e in np.nonzero(mask)[0]:
        a, b = p.edges[e]
        key = tuple(
            sorted(
                (tuple(p.vertices_3d[a].round(decimals)), tuple(p.vertices_3d[b].round(decimals)))
            )
        )
        groups.setdefault(key, []).append(int(e))
    return [(g[0], g[1]) for g in groups.values() if len(g) == 2]


def _runs(p: CreasePattern, pairs: list[tuple[int, int]], angle_tol: float = 1e-6):
    """Group seam pairs into straight runs: consecutive, collinear edges on both sides.

    Returns
    -------
    list of (list of int, list of int)
        The edges of each run on side A and on side B.
    """
    side_a = {e: k for k, (e, _) in enumerate(pairs)}
    at_vertex: dict[int, list[int]] = {}
    for e in side_a:
        for v in p.edges[e]:
            at_vertex.setdefault(int(v), []).append(e)

    def direction(e):
        a, b = p.edges[e]
        d = p.vertices_2d[b] - p.vertices_2d[a]
        return d / np.linalg.norm(d)

    seen, runs = set(), []
    for e0 in side_a:
        if e0 in seen:
            continue
        run = [e0]
        seen.add(e0)
        for end in (0, 1):  # grow from both ends while straight and unbranched
            v = int(p.edges[e0][end])
            cur = e0
            while True:
                nxt = [e for e in at_vertex.get(v, []) if e != cur and e not in seen]
                if len(at_vertex.get(v, [])) != 2 or len(nxt) != 1:
                    break
                e = nxt[0]
                if abs(abs(direction(e) @ direction(cur)) - 1) > angle_tol:
                    break
                # the twins must run on together too (one straight run on the other side)
                if (
                    abs(abs(direction(pairs[side_a[e]][1]) @ direction(pairs[side_a[cur]][1])) - 1)
                    > angle_tol
                ):
                    break
                run.insert(0, e) if end == 0 else run.append(e)
                seen.add(e)
                cur = e
                a, b = p.edges[e]
                v = int(b) if int(a) == v else int(a)
        runs.append((run, [pairs[side_a[e]][1] for e in run]))
    return runs


def _segment(p: CreasePattern, edges: list[int]):
    """End points (2,2) of a straight run of edges, and the outward unit normal."""
    pts = p.vertices_2d[p.edges[edges].ravel()]
    d = pts.max(axis=0) - pts.min(axis=0)
    axis = d / np.linalg.norm(d) if np.linalg.norm(d) > 0 else np.array([1.0, 0.0])
    t = pts @ axis
    ends = np.array([pts[np.argmin(t)], pts[np.argmax(t)]])
    face = p.edge_faces[edges[0]].max()
    centre = p.vertices_2d[p.faces[face]].mean(axis=0)
    normal = np.array([-axis[1], axis[0]])
    if (centre - ends.mean(axis=0)) @ normal > 0:
        normal = -normal
    return ends, normal


def _tab_polygon(ends: np.ndarray, normal: np.ndarray, height: float) -> np.ndarray | None:
    p0, p1 = ends
    length = np.linalg.norm(p1 - p0)
    if length <= 1e-9 * height:
        return None
    d = (p1 - p0) / length
    inset = min(height, 0.3 * length)
    return np.array([p0, p1, p1 + height * normal - inset * d, p0 + height * normal + inset * d])


def _half(ends: np.ndarray, which: int) -> np.ndarray:
    """The first (0) or second (1) half of a segment (2, 2): a tab clear of a narrow corner."""
    mid = ends.mean(axis=0)
    return np.array([ends[0], mid]) if which == 0 else np.array([mid, ends[1]])


def _readable(angle: float) -> float:
    """Text angle in (-90, 90] so that labels are never upside down."""
    a = (angle + 180.0) % 360.0 - 180.0
    if a <= -90:
        a += 180
    elif a > 90:
        a -= 180
    return a


def add_tabs_and_labels(p: CreasePattern, tab_height: float, *, part_names=None) -> dict:
    """Fill ``p.annotations`` with glue tabs, matching labels and part numbers.

    Parameters
    ----------
    p : CreasePattern
        Its 2D layout is final (tabs are placed in it).
    tab_height : float
        Height of a full tab (pattern units); a tab that would overlap a piece or another tab
        is tried on the other side of its cut, then at half the height, then at half or a
        quarter of the height along either half of the border (clear of a narrow wedge).
    part_names : list of str, optional
        Names of the pieces (default ``P1``, ``P2``, ...).

    Returns
    -------
    dict
        ``cut_borders``, ``tabs`` (placed), ``tabs_reduced`` (at a smaller height),
        ``untabbed`` (cut borders where no tab fits: they keep their two labels) and ``seams``
        (per label: the two pieces it joins and the piece carrying the tab).
    """
    polys = [shapely.Polygon(p.vertices_2d[f]) for f in p.faces]
    if polys:  # a face that is not a valid polygon is taken as its valid part (tabs only)
        valid = shapely.is_valid(polys)
        if not valid.all():
            fixed = shapely.make_valid(np.asarray(polys, dtype=object)[~valid])
            for i, g in zip(np.flatnonzero(~valid).tolist(), fixed, strict=True):
                polys[i] = g
    tree = shapely.STRtree(polys)
    placed_tabs: list = []
    ann = Annotations(sheets=p.annotations.sheets)
    label_h = 0.45 * tab_height
    stats = {"cut_borders": 0, "tabs": 0, "tabs_reduced": 0, "untabbed": 0}
    seams = []

    tab_boxes = np.zeros((0, 4))  # bounds of the placed tabs, to test only the nearby ones

    def clear(tab: shapely.Polygon) -> bool:
        """Whether the tab overlaps no face and no placed tab (False too when its geometry
        fails: a tab is an annotation, its border then keeps its labels)."""
        try:
            return _clear(tab)
        except shapely.errors.GEOSException:
            return False

    def _clear(tab: shapely.Polygon) -> bool:
        shrunk = tab.buffer(-1e-9 * tab_height)
        for i in tree.query(shrunk):
            if polys[int(i)].intersection(shrunk).area > 1e-12 * tab.area:
                return False
        x0, y0, x1, y1 = shrunk.bounds
        near = np.nonzero(
            (tab_boxes[:, 0] <= x1) & (tab_boxes[:, 2] >= x0)
            & (tab_boxes[:, 1] <= y1) & (tab_boxes[:, 3] >= y0)
        )[0]  # fmt: skip
        return not any(placed_tabs[int(i)].intersects(shrunk) for i in near)

    runs, run_edges = [], []
    for side_a, side_b in _runs(p, _seam_pairs(p)):
        sides = [_segment(p, side_a), _segment(p, side_b)]
        if np.linalg.norm(sides[0][0][1] - sides[0][0][0]) > 1e-6 * tab_height:
            runs.append(sides)  # shorter runs are slivers of round-off, not borders
            run_edges.append((side_a, side_b))
    piece_of_edge = p.face_piece[p.edge_faces.max(axis=1)]
    names = part_names or [f"P{k + 1}" for k in range(p.n_pieces)]
    for n, sides in enumerate(runs, start=1):
        stats["cut_borders"] += 1
        tab_on = None
        done = False
        for scale, part in ((1.0, None), (0.5, None), (0.5, 0), (0.5, 1), (0.25, 0), (0.25, 1)):
            for ends, normal in sides:
                sub = ends if part is None else _half(ends, part)
                poly = _tab_polygon(sub, normal, scale * tab_height)
                if poly is None:
                    continue
                tab = shapely.Polygon(poly)
                if tab.is_valid and tab.area > 1e-3 * (scale * tab_height) ** 2 and clear(tab):
                    if tab.exterior.is_ccw is False:
                        poly = poly[::-1]
                    ann.tabs.append(poly)
                    ann.tab_hinges.append(sub.copy())
                    placed_tabs.append(tab)
                    tab_boxes = np.vstack([tab_boxes, tab.bounds])
                    stats["tabs"] += 1
                    stats["tabs_reduced"] += scale < 1
                    tab_on = 0 if ends is sides[0][0] else 1
                    done = True
                    break
            if done:
                break
        if not done:
            stats["untabbed"] += 1
        pieces = [names[piece_of_edge[edges[0]]] for edges in run_edges[n - 1]]
        seams.append(
            {"label": n, "pieces": pieces, "tab_on": None if tab_on is None else pieces[tab_on]}
        )
        for ends, normal in sides:
            d = ends[1] - ends[0]
            pos = ends.mean(axis=0) - 0.9 * label_h * normal
            ann.labels.append(
                Label(pos, f"{n}", _readable(np.degrees(np.arctan2(d[1], d[0]))), label_h, "tab")
            )
    area = shapely.area(polys) if polys else np.zeros(0)
    for k in range(p.n_pieces):
        faces = np.nonzero(p.face_piece == k)[0]
        if not len(faces):
            continue
        # the part number goes inside the piece's largest face
        where = polys[int(faces[np.argmax(area[faces])])].representative_point()
        ann.labels.append(Label(np.array([where.x, where.y]), names[k], 0.0, 2 * label_h, "part"))
    p.annotations = ann
    stats["seams"] = seams
    return stats
