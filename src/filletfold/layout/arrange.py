"""The layout stage: where the flat pieces go (paper step 4, the 2D development laid out).

:func:`arrange` takes the vertex modules and returns the crease pattern: the modules side by
side on shelves, glued into one uncut sheet where every development closes, or joined into
nets (on sheets of a size, packed), with glue tabs and labels on the cut borders.
"""

from __future__ import annotations

import time

import numpy as np

from ..errors import ParameterError, SolverError
from ..rounding.bend import floor_size
from ..surface.assemble import assemble_pattern
from ..surface.module import Modules
from ..surface.pattern import face_arrays
from ..surface.piece import piece_area
from ..tolerances import tol
from ..units import AUTO_SIZE, LEAST_SIZE_MM, MIN_LABEL_MM, MIN_PIECE_MM, ceil_digits
from ..vertex.solution import VertexSolution
from .fabrication import net_pieces, orient, pack_on_sheets, sheet_in_pattern_units
from .nest import SEED, choose_nester, nest_on_sheets, placement_errors, use_figures
from .net import fits_sheet
from .sheet import glue_pieces
from .shelf import shelf_offsets
from .tabs import LABEL_SHARE, add_tabs_and_labels

#: Height of a glue tab, as a share of the mean edge length, in a drawing without units.
TAB_HEIGHT = 0.04
#: Height of a glue tab on the sheet (mm) when the drawing has units (``units``, or ``size``):
#: the paper-craft flap; labels are 0.45 of it, 2.25 mm.
TAB_MM = 5.0
#: ... but at most this share of the mean edge length (a tiny drawing keeps tabs its edges
#: can carry, and the summary warns of its labels).
TAB_MAX = 0.5


def tab_height(params, ref: float) -> float:
    """The glue tabs' full height in pattern units: :data:`TAB_MM` on the sheet when the
    drawing has units (at most :data:`TAB_MAX` of the mean edge length ``ref``), else
    :data:`TAB_HEIGHT` of ``ref``."""
    if not params.units:
        return TAB_HEIGHT * ref
    return min(TAB_MM / params.mm_per_unit, TAB_MAX * ref)


def default_size(
    extent: float, ref: float, smallest: float | None = None, bend: float | None = None
) -> tuple[float, str]:
    """The default size of an object whose mesh's largest side is ``extent`` and mean edge
    length ``ref``: the least largest side (mm) at which it can be built, rounded up to two
    significant digits, and what sets it.

    Four lower bounds, the largest of which sets it (``"least"``, ``"labels"``,
    ``"pieces"``, ``"material"``): :data:`~filletfold.units.LEAST_SIZE_MM`; the size at which
    the labels are :data:`~filletfold.units.MIN_LABEL_MM` high, tabs being at most
    :data:`TAB_MAX` of the mean edge length and labels
    :data:`~filletfold.layout.tabs.LABEL_SHARE` of a tab; given the ``smallest`` piece's span
    (pattern units), the size at which it spans :data:`~filletfold.units.MIN_PIECE_MM`; and
    ``bend``, the size (mm) at which every fillet holds the sheet material's bend floor
    (:func:`~filletfold.rounding.bend.floor_size`).

    Returns
    -------
    mm : float
    binding : str
    """
    bounds = {
        "least": LEAST_SIZE_MM,
        "labels": extent * MIN_LABEL_MM / (LABEL_SHARE * TAB_MAX * ref),
    }
    if smallest is not None and smallest > 0:
        bounds["pieces"] = extent * MIN_PIECE_MM / smallest
    if bend is not None:
        bounds["material"] = bend
    binding = max(bounds, key=bounds.__getitem__)
    return ceil_digits(bounds[binding]), binding


def smallest_span(pieces: list) -> float | None:
    """The least over ``pieces`` of the longer side of a piece's bounding box (of the points
    its faces use; pattern units); None without a piece that has faces."""
    spans = []
    for piece in pieces:
        flat, _ = face_arrays(piece.faces)
        if len(flat):
            xy = np.asarray(piece.points_2d, dtype=np.float64)[flat]
            spans.append(float(np.ptp(xy, axis=0).max()))
    return min(spans) if spans else None


def settle_size(params, extent: float, ref: float, pieces: list | None, radius=None):
    """``params`` with the default size settled (unchanged unless ``size`` is
    :data:`~filletfold.units.AUTO_SIZE`): :func:`default_size` with the smallest of the laid
    out ``pieces`` (None: the labels and the least size only, the size pieces are first fitted
    to sheets at) and, with a sheet material, the fillets' ``radius`` (mesh units: the size
    at which they hold its bend floor), written as the size in millimetres it is (``"620mm"``), with
    the units (mm) and scale it gives, and the report's account of it (``{"size",
    "binding"}``; None when the size was given). A mesh of no extent gets no size."""
    if params.size != AUTO_SIZE:
        return params, None
    if not (extent > 0 and ref > 0):
        return params.replace(size=None), None
    material = params.sheet_material()
    bend = None
    if material is not None and radius is not None:  # the fillets hold the bend floor
        bend = floor_size(extent, material.bend_floor_mm(), radius)
    smallest = None if pieces is None else smallest_span(pieces)
    mm, binding = default_size(extent, ref, smallest, bend)
    size = f"{mm:g}mm"
    return params.replace(size=size, units="mm", scale=mm / extent), {
        "size": size,
        "binding": binding,
    }


def spacing(params, ref: float):
    """The glue tabs' height, the gap between pieces, and with ``params.sheet`` the sheet's
    size and the room a piece has on it (pattern units; else None), for a mesh of mean edge
    length ``ref`` drawn at ``params``' units and scale.

    Raises
    ------
    ParameterError
        A sheet too small for any piece at that scale.
    """
    tab_h = tab_height(params, ref) if params.tabs else 0.0
    gap = 0.1 * ref + 2.5 * tab_h
    if params.sheet is None:
        return tab_h, gap, None, None
    units, scale = params.sheet_units, params.sheet_scale
    sheet_box = sheet_in_pattern_units(params.sheet, units, scale)
    margin = 2 * (gap + tab_h)
    room = (sheet_box[0] - margin, sheet_box[1] - margin)
    if min(room) <= 0:
        raise ParameterError(
            f"the sheet {params.sheet} at scale {scale:g} {units} per unit is too small for any "
            "piece",
            name="sheet",
        )
    return tab_h, gap, sheet_box, room


def arrange(
    mesh,
    sol: VertexSolution,
    mods: Modules,
    pieces: list,
    params,
    *,
    stage=lambda name: None,
    timings: dict | None = None,
    release_pieces: bool = False,
):
    """The crease pattern of the vertex modules' pieces, laid out.

    Parameters
    ----------
    mesh : PolyMesh
    sol : VertexSolution
        The vertices: their rounding, results, face piece centres, whether each ring is
        closed, and ``solved`` (needed by nets only: they re-cut the modules; None when
        released).
    mods : Modules
        The samples per arc (``mods.points``).
    pieces : list of Piece
        Every vertex module's pieces.
    params : Parameters
        ``layout`` (``"auto"``, ``"modules"``, ``"net"`` or ``"sheet"``), ``material_loss``,
        ``sheet`` (None: none) with ``sheet_units`` and ``sheet_scale`` (how a pattern unit is
        drawn), ``tabs``, and ``nest``: how pieces are placed on sheets (``"shelf"``,
        ``"sparrow"`` or ``"auto"``, optionally ``":SECONDS"``,
        :func:`~filletfold.layout.nest.choose_nester`).
    stage : callable
        Called with the name of each sub-stage as it starts (``"glue tabs"``).
    timings : dict, optional
        Gets ``"tabs"``: the seconds the glue tabs took (when ``tabs``), and ``"nest"``: the
        seconds the placement on sheets took (with a sheet).
    release_pieces : bool
        Empty ``pieces`` (the caller's list) once the pattern is assembled, so that the glue
        tabs run without them in memory (the pattern holds their points again); with nets,
        as soon as the nets are made, with ``sol``'s frames, classification and solutions
        and ``mods``'s modules (the nets are copies).

    Returns
    -------
    pattern : CreasePattern
    layout_used : str
    layout_note : str
    fabrication : dict
        Cut borders, tabs and sheet figures (the report's ``fabrication``), and
        ``default_size`` (:func:`settle_size`) when the size was the default.
    params : Parameters
        ``params`` with the default size settled (:func:`settle_size`).
    """
    pm, res, ring_closed = mesh, sol.res, sol.ring_closed
    layout, material_loss, sheet, tabs = (
        params.layout,
        params.material_loss,
        params.sheet,
        params.tabs,
    )
    ref = pm.mean_edge_length
    asked = params  # the size settles once the pieces are known (on sheets, before)
    extent = float(np.ptp(pm.vertices, axis=0).max(initial=0.0))
    radius = sol.rounding.radius  # the fillets as the vertices left them
    params, _ = settle_size(params, extent, ref, None, radius)
    given = pieces  # the caller's list (``pieces`` may be rebound to laid-out copies)
    layout_used, layout_note = "modules", ""
    eps = tol.relative * ref
    if layout in ("auto", "sheet") and (material_loss or layout == "sheet"):
        not_closed = [
            u for u, closed in enumerate(ring_closed) if closed and res.kind[u] != "developable"
        ]
        if not_closed:
            listed = ", ".join(map(str, not_closed[:8])) + (", ..." if len(not_closed) > 8 else "")
            glued, layout_note = (
                None,
                (
                    f"the input is not developable at {len(not_closed)} vertices ({listed}): their "
                    "developments do not close, so their modules keep a cut"
                ),
            )
        else:
            glued, _, layout_note = glue_pieces(pieces, eps, pm)
        if glued is not None:
            pieces, layout_used = [glued], "sheet"
        elif layout == "sheet":
            raise SolverError(f"the modules do not form one sheet: {layout_note}")
    tab_h, gap, sheet_box, room = spacing(params, ref)
    net = layout == "net" or (layout == "auto" and layout_used == "modules")
    if net:
        pieces = net_pieces(pm, sol, mods.modules, mods.points, eps, sheet=room)
        layout_used = "net"
    labels_size = params.scale
    params, default = settle_size(asked, extent, ref, pieces, radius)
    if default is not None and sheet is not None and params.scale != labels_size:
        # the pieces ask for a larger size: fitted to the sheets again at it, if every
        # module fits one (else the labels' size stays, and the summary warns of them)
        try:
            larger = spacing(params, ref)
        except ParameterError:  # the gaps alone fill the sheet
            larger = None
        if larger is not None and all(
            fits_sheet(np.asarray(piece.points_2d), larger[3]) for piece in given
        ):
            tab_h, gap, sheet_box, room = larger
            if net:
                pieces = net_pieces(pm, sol, mods.modules, mods.points, eps, sheet=room)
        else:
            params, default = settle_size(asked, extent, ref, None, radius)
    elif sheet is None:  # the tabs at the size settled
        tab_h, gap, _, _ = spacing(params, ref)
    if net and release_pieces:  # the nets hold copies: the modules, and what built them, go
        given.clear()
        sol.frames = sol.classified = sol.solved = mods.modules = None
    if sheet is not None:
        pieces = [orient(piece) for piece in pieces]
        t = time.perf_counter()
        offsets, boxes, sheet_of, nesting = place_on_sheets(pieces, sheet_box, gap, params.nest)
        if timings is not None:
            timings["nest"] = time.perf_counter() - t
        pattern = assemble_pattern(pieces, offsets)
        pattern.annotations.sheets = boxes
        area = np.array([piece_area(piece) for piece in pieces])
        sheet_area = sheet_box[0] * sheet_box[1]
        nesting.update(use_figures(area, pieces, offsets, boxes, sheet_of, gap))
        sheet_stats = {
            "sheets": len(boxes),
            "sheet_size": [float(max(sheet_box)), float(min(sheet_box))],
            "pieces_per_sheet": np.bincount(sheet_of, minlength=len(boxes)).tolist(),
            "material_use": (
                np.bincount(sheet_of, weights=area, minlength=len(boxes)) / sheet_area
            ).tolist(),
            "nesting": nesting,
        }
    else:
        pattern = assemble_pattern(pieces, shelf_offsets(pieces, gap))
    if release_pieces:
        given.clear()
        pieces = None
    fab = {"cut_borders": 0, "tabs": 0, "tabs_reduced": 0, "untabbed": 0}
    if tabs:
        stage("glue tabs")
        t = time.perf_counter()
        fab = add_tabs_and_labels(pattern, tab_h)
        if timings is not None:
            timings["tabs"] = time.perf_counter() - t
    if sheet is not None:
        fab.update(sheet_stats)
    if default is not None:
        fab["default_size"] = default
    return pattern, layout_used, layout_note, fab, params


def place_on_sheets(pieces: list, sheet_box, gap: float, nest: str):
    """Translations placing oriented pieces on sheets, by the shelf packer or sparrow.

    sparrow's placement is checked (:func:`~filletfold.layout.nest.placement_errors`); a
    faulty one, or one on more sheets than the shelf packer's, is replaced by the shelf
    packer's, and the note says why.

    Returns
    -------
    offsets : (n_pieces, 2) float
    boxes : (n_sheets, 4) float
    sheet_of : (n_pieces,) int
    nesting : dict
        ``nester`` (``"shelf"`` or ``"sparrow"``), and for sparrow ``seconds`` (per run),
        ``runs``, ``seed``; ``note`` when sparrow's placement was not kept.
    """
    nester, seconds = choose_nester(nest, sheet_box)
    nesting = {"nester": nester}
    shelf = pack_on_sheets(pieces, sheet_box, gap)
    if nester == "sparrow":
        before = [piece.points_2d for piece in pieces]  # nest_on_sheets turns them
        offsets, boxes, sheet_of, runs = nest_on_sheets(pieces, sheet_box, gap, seconds=seconds)
        faults = placement_errors(pieces, offsets, boxes, sheet_of, gap)
        nesting.update(seconds=seconds, runs=runs, seed=SEED)
        if not faults and len(boxes) <= len(shelf[1]):
            return offsets, boxes, sheet_of, nesting
        for piece, points in zip(pieces, before, strict=True):
            piece.points_2d = points
        why = (
            f"sparrow's placement refused: {faults[0]}"
            if faults
            else f"sparrow used more sheets than the shelves ({len(boxes)} against {len(shelf[1])})"
        )
        nesting.update(nester="shelf", note=why)
    return (*shelf, nesting)
