"""Glue vertex modules into one sheet (the "shrunk" paper of sec. 4, fig. 13).

When every vertex's rounded development closes (consistent material loss on a developable
input), neighbouring modules fit together along their shared borders: the midpoint base curves
of the cylinders and the dividers of the face pieces. Each module is placed by the rigid motion
that maps its copies of shared border points onto the copies already placed, breadth first;
coincident points are then merged, so shared borders become ordinary facet edges.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .module import Piece


def _rigid_fit(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """3x3 homogeneous rotation + translation taking points ``src`` (k, 2) onto ``dst``."""
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    h = (src - cs).T @ (dst - cd)
    u, _, vt = np.linalg.svd(h)
    r = (u @ vt).T
    if np.linalg.det(r) < 0:  # a reflection cannot glue orientation-preserving pieces
        vt[-1] *= -1
        r = (u @ vt).T
    m = np.eye(3)
    m[:2, :2] = r
    m[:2, 2] = cd - r @ cs
    return m


def glue_pieces(pieces: list[Piece], eps: float) -> tuple[Piece | None, list, str]:
    """Place all pieces in one frame by matching shared border points, then merge them.

    Parameters
    ----------
    pieces : list of Piece
    eps : float
        Distance under which two points are the same (in 3D, and in 2D after placing).

    Returns
    -------
    sheet : Piece or None
        One piece holding every face (``vertex = -1``), or None when the pieces do not fit.
    placement : list of (3, 3) float
        The rigid map of each piece into the sheet (empty on failure).
    message : str
        Why gluing failed (empty on success).
    """
    arrays = [p.arrays() for p in pieces]
    owner = np.concatenate([np.full(len(a[0]), k) for k, a in enumerate(arrays)])
    local = np.concatenate([np.arange(len(a[0])) for a in arrays])
    p3 = np.vstack([a[1] for a in arrays])
    tree = cKDTree(p3)
    pairs = tree.query_pairs(eps, output_type="ndarray")
    pairs = pairs[owner[pairs[:, 0]] != owner[pairs[:, 1]]]
    # shared points between every two pieces
    shared: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for a, b in pairs:
        ka, kb = int(owner[a]), int(owner[b])
        shared.setdefault((ka, kb), []).append((int(local[a]), int(local[b])))
        shared.setdefault((kb, ka), []).append((int(local[b]), int(local[a])))
    placed = {0: np.eye(3)}
    queue = [0]
    while queue:
        k = queue.pop(0)
        for (ka, kb), matches in sorted(shared.items()):
            if ka != k or kb in placed or len(matches) < 2:
                continue
            src = arrays[kb][0][[j for _, j in matches]]
            dst = arrays[ka][0][[i for i, _ in matches]]
            dst = dst @ placed[ka][:2, :2].T + placed[ka][:2, 2]
            m = _rigid_fit(src, dst)
            err = np.abs(src @ m[:2, :2].T + m[:2, 2] - dst).max()
            if err > eps:
                return (
                    None,
                    [],
                    (
                        f"the modules of vertices {pieces[ka].vertex} and "
                        f"{pieces[kb].vertex} do not fit together (gap {err:.3g})"
                    ),
                )
            placed[kb] = m
            queue.append(kb)
    if len(placed) != len(pieces):
        missing = sorted(set(range(len(pieces))) - set(placed))
        return (
            None,
            [],
            (
                f"{len(missing)} module(s) share no border with the rest "
                f"(vertices {[pieces[k].vertex for k in missing[:10]]})"
            ),
        )
    sheet = Piece(vertex=-1)
    for k, piece in enumerate(pieces):
        p2, q3 = arrays[k]
        p2 = p2 @ placed[k][:2, :2].T + placed[k][:2, 2]
        base = len(sheet.points_2d)
        sheet.points_2d.extend(p2)
        sheet.points_3d.extend(q3)
        sheet.faces.extend([[i + base for i in f] for f in piece.faces])
        sheet.patches.extend(piece.patches)
    sheet.merge_coincident(eps)
    return sheet, [placed[k] for k in range(len(pieces))], ""
