"""Glue vertex modules into one sheet (the "shrunk" paper of sec. 4, fig. 13).

When every vertex's rounded development closes (consistent material loss on a developable
input), neighbouring modules fit together along their shared borders: the midpoint base curves
of the cylinders and the dividers of the face pieces. Each module is placed by the rigid motion
that maps its copies of shared border points onto the copies already placed, breadth first;
coincident points are then merged, so shared borders become ordinary facet edges.
"""

from __future__ import annotations

import collections

import numpy as np

from ..surface.piece import Piece
from .net import merge_pieces, rigid_fit, shared_points


def glue_pieces(pieces: list[Piece], eps: float, mesh=None) -> tuple[Piece | None, list, str]:
    """Place all pieces in one frame by matching shared border points, then merge them.

    Parameters
    ----------
    pieces : list of Piece
    eps : float
        Distance under which two points are the same (in 3D, and in 2D after placing).
    mesh : PolyMesh, optional
        The mesh of the pieces' vertices: borders only between modules of one face
        (:func:`~filletfold.layout.net.shared_points`).

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
    shared = shared_points(pieces, eps, mesh)
    neighbours: dict[int, list] = {}  # per piece, its (other piece, matches) in order
    for (ka, kb), matches in sorted(shared.items()):
        neighbours.setdefault(ka, []).append((kb, matches))
    placed = {0: np.eye(3)}
    queue = collections.deque([0])
    while queue:
        ka = queue.popleft()
        for kb, matches in neighbours.get(ka, []):
            if kb in placed or len(matches) < 2:
                continue
            src = arrays[kb][0][[j for _, j in matches]]
            dst = arrays[ka][0][[i for i, _ in matches]]
            dst = dst @ placed[ka][:2, :2].T + placed[ka][:2, 2]
            m = rigid_fit(src, dst)
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
    placement = [placed[k] for k in range(len(pieces))]
    return merge_pieces(pieces, placement, eps), placement, ""
