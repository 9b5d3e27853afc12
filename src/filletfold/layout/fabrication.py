"""Fabrication layouts: nets of few pieces, pieces placed on sheets of material.

``net_pieces`` tries a few choices of where each vertex module is cut (the default ring start,
and cuts off glue spanning trees rooted at different vertices), grows nets for each, and keeps
the one with the fewest pieces. ``pack_on_sheets`` turns every piece to its smallest bounding
rectangle and places the pieces row by row onto as few sheets as it can.
"""

from __future__ import annotations

import numpy as np
import shapely

from ..errors import ParameterError
from ..surface.faces import face_polygons
from ..surface.module import build_modules
from ..surface.piece import Piece
from ..tolerances import tol
from ..units import MM_PER_UNIT, check_units, sheet_size_mm
from ..vertex.frame import apply, invert, vertex_frames
from .net import build_nets, cut_edges_for_nets

#: Meshes of at most this many vertices try four choices of cuts for their nets, larger ones one.
SMALL = 60


def sheet_in_pattern_units(sheet: str, units: str, scale: float) -> tuple[float, float]:
    """Sheet size in pattern units, when one pattern unit is drawn as ``scale`` ``units``.

    Parameters
    ----------
    sheet : str
        See :func:`~filletfold.units.sheet_size_mm`.
    units : str
        One of :data:`~filletfold.units.CUT_FILE_UNITS`.
    scale : float
        Positive.

    Returns
    -------
    (float, float)
        Width and height of the sheet in pattern length units.

    Raises
    ------
    ParameterError
        Naming ``sheet``, ``units`` or ``scale``.
    """
    check_units(units, unitless=False)
    if not (np.isfinite(scale) and scale > 0):
        raise ParameterError(f"scale must be positive, got {scale!r}", name="scale")
    w, h = sheet_size_mm(sheet)
    k = 1.0 / (MM_PER_UNIT[units] * scale)
    return w * k, h * k


def net_pieces(mesh, sol, modules, samples, eps, sheet=None, tries=None):
    """Vertex modules joined into the fewest nets found over a few choices of cuts.

    Parameters
    ----------
    mesh : PolyMesh
    sol : VertexSolution
        Its rounding, face piece centres and ``solved``: the frames the apices were solved
        in, and the apices (:class:`~filletfold.vertex.solution.VertexSolution`).
    modules : list of list of Piece
        Each vertex's module (its pieces) as built from ``solved``: the first choice of cuts,
        and the module of every vertex that a later choice cuts where it was cut.
    samples : int or (n_edges,) int
        Points per arc (see :func:`~filletfold.surface.module.build_modules`).
    eps : float
    sheet : (float, float), optional
        Every net must fit this (pattern units).
    tries : int, optional
        How many cut choices to try (the default ring starts, the glue tree's cuts, then trees
        rooted at far vertices; one: the glue tree's cuts); default 4, or 1 above
        :data:`SMALL` vertices.

    Returns
    -------
    list of Piece
    """
    rounding, solved, centres = sol.rounding, sol.solved, sol.centres
    if tries is None:
        tries = 4 if mesh.n_vertices <= SMALL else 1
    # a larger mesh tries the glue tree's cuts alone: never more nets than the ring starts'
    # on the corpus (cow: 334 against 355; spot 288 against 365; airplane 509 against 670)
    # a vertex the tree cuts where its module is cut keeps its module
    choices = [None, cut_edges_for_nets(mesh)]
    if tries == 1:
        choices = choices[1:]
    # further trees rooted at the vertices farthest from each other
    far = np.argsort(-np.linalg.norm(mesh.vertices - mesh.vertices.mean(axis=0), axis=1))
    for root in far[: max(0, tries - 2)]:
        choices.append(cut_edges_for_nets(mesh, root=int(root)))
    best = None
    for cut in choices[:tries]:
        recut = {} if cut is None else recut_solved(mesh, rounding, solved, cut)
        rebuilt = {}
        if recut:
            frames, apices, developed = (list(c) for c in zip(*recut.values(), strict=True))
            built = build_modules(mesh, frames, centres, samples, apices, developed)
            rebuilt = dict(zip(recut, built, strict=True))
        pieces = [piece for u, module in enumerate(modules) for piece in rebuilt.get(u, module)]
        nets, _ = build_nets(pieces, eps, sheet, mesh=mesh)
        if best is None or len(nets) < len(best):
            best = nets
        if len(best) == 1:
            break
    return best


def cut_first(params, n_vertices: int) -> bool:
    """Whether the modules are built cut where the nets will cut them
    (:func:`recut_solved` of the glue tree's cuts, before they are built): where the layout
    will be nets of one choice of cuts (more than :data:`SMALL` vertices, ``layout`` net, or
    auto without the material-loss radii, which may glue into one sheet instead), so that
    :func:`net_pieces` finds every module cut where it would cut it and builds none again."""
    nets = params.layout == "net" or (params.layout == "auto" and not params.material_loss)
    return nets and n_vertices > SMALL


def recut_solved(mesh, rounding, solved: list, cut: np.ndarray) -> dict:
    """The vertices whose module a net cuts elsewhere than it is cut, framed again there.

    Parameters
    ----------
    mesh : PolyMesh
    rounding : Rounding
    solved : list of (VertexFrame, apex, developed apex)
        Per vertex (:class:`~filletfold.vertex.solution.VertexSolution`'s ``solved``).
    cut : (n_vertices,) int
        The edge each vertex's module is to be cut along (:func:`cut_edges_for_nets`; -1:
        none).

    Returns
    -------
    dict
        Vertex -> (frame, apex, developed apex) for every closed vertex whose ring starts at
        another edge than ``cut`` names: its frame starting at that edge, the developed apex
        in it (the spatial apex is the same).
    """
    start = np.array([f.ring.edges[0] if f.ring.closed else -1 for f, _, _ in solved])
    cut_at = [u for u, (f, _, _) in enumerate(solved) if f.ring.closed and cut[u] >= 0]
    cut_at = [u for u in cut_at if cut[u] != start[u]]
    sharp = np.array([f.sharp for f, _, _ in solved], dtype=bool)
    new_frames = vertex_frames(mesh, rounding, cut_at, [int(cut[u]) for u in cut_at], sharp=sharp)
    out = {}
    for u, new in zip(cut_at, new_frames, strict=True):
        frame, apex, v = solved[u]
        k = int(np.nonzero(frame.ring.edges == cut[u])[0][0])
        if v is not None and k:
            v = apply(invert(frame.face_map[k - 1]), v)[0]
        out[u] = (new, apex, v)
    return out


def orient(piece: Piece) -> Piece:
    """The piece turned so its smallest bounding rectangle is axis-aligned and wider than tall."""
    p2, _ = piece.arrays()
    shape = shapely.union_all(shapely.make_valid(face_polygons(p2, piece.faces)))
    rect = np.asarray(shapely.minimum_rotated_rectangle(shape).exterior.coords)[:4]
    sides = [rect[1] - rect[0], rect[2] - rect[1]]
    d = max(sides, key=np.linalg.norm)
    ang = -np.arctan2(d[1], d[0])
    rot = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]])
    piece.points_2d = [rot @ q for q in piece.points_2d]
    return piece


def pack_on_sheets(pieces: list[Piece], sheet: tuple[float, float], gap: float):
    """Translations that place pieces row by row on sheets, never overlapping.

    Parameters
    ----------
    pieces : list of Piece
        Already oriented (see :func:`orient`); each must fit a sheet.
    sheet : (float, float)
        Width and height of a sheet (pattern units); sheets are laid out left to right.
    gap : float
        Clearance between pieces and from the sheet edges.

    Returns
    -------
    offsets : (n_pieces, 2) float
    boxes : (n_sheets, 4) float
        ``(xmin, ymin, xmax, ymax)`` of each sheet.
    sheet_of : (n_pieces,) int
    """
    w, h = sheet
    if w < h:  # pieces are landscape: use landscape sheets
        w, h = h, w
    arrays = [p.arrays()[0] for p in pieces]
    size = np.array([np.ptp(a, axis=0) for a in arrays])
    for k, (sw, sh) in enumerate(size):
        if sw + 2 * gap > w * (1 + tol.relative) or sh + 2 * gap > h * (1 + tol.relative):
            raise ParameterError(
                f"piece {k + 1} ({sw:.4g} x {sh:.4g}) does not fit on the sheet "
                f"({w:.4g} x {h:.4g} in pattern units); use a larger sheet or a smaller scale",
                name="sheet",
            )
    order = np.argsort(-size[:, 1], kind="stable")
    offsets = np.zeros((len(pieces), 2))
    sheet_of = np.zeros(len(pieces), dtype=np.int64)
    n_sheets, x, y, row_h = 1, gap, gap, 0.0
    for k in order:
        sw, sh = size[k]
        if x + sw + gap > w:
            x, y, row_h = gap, y + row_h + gap, 0.0
        if y + sh + gap > h:
            n_sheets, x, y, row_h = n_sheets + 1, gap, gap, 0.0
        origin = np.array([(n_sheets - 1) * (w + 4 * gap), 0.0])
        offsets[k] = origin + np.array([x, h - y - sh]) - arrays[k].min(axis=0)
        sheet_of[k] = n_sheets - 1
        x += sw + gap
        row_h = max(row_h, sh)
    boxes = np.array([[s * (w + 4 * gap), 0.0, s * (w + 4 * gap) + w, h] for s in range(n_sheets)])
    return offsets, boxes, sheet_of
