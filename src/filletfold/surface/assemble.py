"""The crease pattern of translated pieces, and the rulings made isometric to round-off."""

from __future__ import annotations

import itertools
from typing import TYPE_CHECKING

import numpy as np

from ..arrays import run_owners, run_starts
from ..tolerances import tol
from .faces import flat_faces
from .patch import Patch, patch_kinds
from .pattern import CreasePattern, FaceRows
from .piece import Piece

if TYPE_CHECKING:
    from ..vertex.solve import VertexResult


def assemble_pattern(pieces: list[Piece], offsets: np.ndarray) -> CreasePattern:
    """Merge translated pieces into one crease pattern, all faces at once.

    Parameters
    ----------
    pieces : list of Piece
    offsets : (n_pieces, 2) float
        Translation of each piece.

    Returns
    -------
    CreasePattern
        Vertices piece after piece (each piece's points in order, translated), faces as
        ``(k,) int64`` arrays piece after piece (:class:`~filletfold.surface.pattern.FaceRows`),
        with their patches and pieces.
    """
    points = [piece.arrays() for piece in pieces]
    n_points = np.array([len(p2) for p2, _ in points], dtype=np.int64)
    n_faces = np.array([len(piece.faces) for piece in pieces], dtype=np.int64)
    v2 = np.vstack([p2 for p2, _ in points]) if pieces else np.zeros((0, 2))
    v3 = np.vstack([p3 for _, p3 in points]) if pieces else np.zeros((0, 3))
    v2 = v2 + np.repeat(np.asarray(offsets, dtype=float).reshape(-1, 2), n_points, axis=0)
    flats, sizes = zip(*(flat_faces(p.faces) for p in pieces), strict=True) if pieces else ((), ())
    size = np.concatenate([np.zeros(0, dtype=np.int64), *sizes])
    flat = np.concatenate([np.zeros(0, dtype=np.int64), *flats])
    base = run_starts(n_points)[:-1]
    flat += np.repeat(np.repeat(base, n_faces), size)
    start = run_starts(size)
    faces = FaceRows(flat, start)  # (k,) int64 rows made when asked for
    patches = list(itertools.chain.from_iterable(piece.patches for piece in pieces))
    apex = np.array([-1 if p.apex_index is None else p.apex_index for p in pieces], dtype=np.int64)
    apex = np.where(apex >= 0, apex + base, -1) if pieces else apex
    true_rulings(v2, v3, flat, size, np.repeat(apex, n_faces), patches)
    return CreasePattern(
        vertices_2d=v2,
        vertices_3d=v3,
        faces=faces,
        face_patch=patches,
        face_piece=run_owners(n_faces),
        piece_vertex=np.array([piece.vertex for piece in pieces], dtype=np.int64),
    )


def true_rulings(v2, v3, flat, size, face_apex, patches) -> None:
    """Put every cone face's corner on its ruling at its folded distance from the apex, in place.

    Eq. (1) gives the crease point's height as a difference of squared distances divided by the
    denominator, so it loses ``(D / l)^2`` digits on a ruling of length ``l`` far (``D``) from
    its chart's origin: on float32 or near-developable inputs a short ruling came out longer
    folded than flat by ``3e-11`` of its length. The construction makes the ruling isometric,
    so the developed point is moved along its ruling ``v -> p`` to the distance ``|P - V|``
    (by round-off: ``1e-13`` of the design at most).

    Parameters
    ----------
    v2 : (n, 2) float
        Pattern points, moved in place.
    v3 : (n, 3) float
        Folded points.
    flat, size : (N,) int, (n_faces,) int
        The faces' corners one after the other, and how many each face has.
    face_apex : (n_faces,) int
        The apex point of each face's piece (-1 without a cone).
    patches : list of str
        Each face's patch; the corners of ``"cone ..."`` faces are moved.
    """
    cone = patch_kinds(patches) == "cone"
    cone &= face_apex >= 0
    if not cone.any():
        return
    corner_face = run_owners(size)
    on = cone[corner_face]
    point, apex = flat[on], face_apex[corner_face[on]]
    keep = point != apex
    pairs = np.unique(np.stack([point[keep], apex[keep]], axis=1), axis=0)
    p, a = pairs[:, 0], pairs[:, 1]
    d2 = v2[p] - v2[a]
    l2 = np.linalg.norm(d2, axis=1)
    l3 = np.linalg.norm(v3[p] - v3[a], axis=1)
    ok = l2 > 0
    v2[p[ok]] = v2[a[ok]] + d2[ok] * (l3[ok] / l2[ok])[:, None]


def locate_apices(pattern: CreasePattern, res: VertexResult) -> None:
    """Set ``res.apex_2d``: where each solved apex lies in the pattern's layout."""
    from scipy.spatial import cKDTree

    tree = cKDTree(pattern.vertices_3d)
    names = set(pattern.face_patch)
    cones = {p.index for p in map(Patch.parse, names) if p.kind == "cone"}
    us = np.array(
        [u for u in np.flatnonzero(np.isfinite(res.apex[:, 0])).tolist() if u in cones],
        dtype=np.int64,
    )
    if not len(us):
        return
    dist, k = tree.query(res.apex[us])
    near = dist < tol.relative * (1 + np.abs(res.apex[us]).max(axis=1))
    res.apex_2d[us[near]] = pattern.vertices_2d[k[near]]
