"""Nesting: pieces placed on sheets by an irregular nester, the shelf packer as the fallback.

The nester is sparrow (a strip-packing solver for irregular polygons) through its Python
wrapper ``spyrrow``, an optional dependency (``pip install 'filletfold[nest]'``). Sheets are
filled first-fit by decreasing area (:func:`nest_on_sheets`): a sheet is opened with the largest
piece left, and each other piece joins it when sparrow strip-packs the sheet's pieces, on a
strip as high as the sheet, within one sheet width. Each piece is packed as its outline (holes
filled) grown by half the gap, so that placed pieces keep the gap between them and from the
sheet's edges, as on the shelves; the glue tabs, added after the placement, fit in that gap.
:func:`placement_errors` checks a placement from the pieces themselves.

sparrow's search stops on the clock (whole seconds per packing run), so what it finds depends
on the machine's load. Without a search budget (:data:`DEFAULT_SECONDS`) only its constructive
placement runs, with a fixed seed and one worker: the same input then gives the same placement
(and the same bytes) whatever the load. The shelf packer
(:func:`~filletfold.layout.fabrication.pack_on_sheets`) stays the default.
"""

from __future__ import annotations

import importlib.util

import numpy as np
import shapely
import shapely.affinity

from ..errors import ParameterError
from ..surface.faces import face_polygons
from ..surface.piece import Piece
from ..tolerances import tol
from .fabrication import pack_on_sheets

#: The nesters ``round_mesh(nest=...)`` and ``--nest`` accept.
NESTERS = ("shelf", "sparrow", "auto")
#: Seconds sparrow searches per packing run; 0: its constructive placement only, which is the
#: same whatever the machine's load (so the same input gives the same bytes).
DEFAULT_SECONDS = 0
#: sparrow's random seed (fixed: the same input gives the same placement when it converges).
SEED = 0
#: Turns a piece may take on the sheet (degrees): quarter turns keep each piece's smallest
#: bounding rectangle axis-aligned (as :func:`~filletfold.layout.fabrication.orient` leaves it).
ORIENTATIONS = (0.0, 90.0, 180.0, 270.0)
#: Segments per quarter circle of the grown outlines' rounded corners.
QUAD_SEGS = 2
#: Tolerance of the grown outlines' simplification, as a share of the gap (fewer corners make
#: sparrow faster; each piece then takes this much more room on every side).
SIMPLIFY = 0.25
#: Least room a grown outline must leave on the strip (a share of its height and width) to be
#: packed with others; a piece with less goes on a sheet of its own, as on the shelves.
ROOM = 0.02


def have_sparrow() -> bool:
    """Whether the nester (the ``spyrrow`` package, extra ``nest``) is installed."""
    return importlib.util.find_spec("spyrrow") is not None


def parse_nest(spec: str) -> tuple[str, int]:
    """The nester and its time budget from ``"shelf"``, ``"sparrow"``, ``"auto"`` or
    ``"sparrow:SECONDS"`` / ``"auto:SECONDS"``.

    Parameters
    ----------
    spec : str

    Returns
    -------
    name : str
        One of :data:`NESTERS`.
    seconds : int
        Seconds per packing run (:data:`DEFAULT_SECONDS` unless given; 0 for ``"shelf"``).

    Raises
    ------
    ParameterError
        Naming ``nest``.
    """
    text = str(spec).strip().lower()
    name, _, budget = text.partition(":")
    if name not in NESTERS or (name == "shelf" and budget):
        raise ParameterError(
            f"nest must be 'shelf', 'sparrow', 'auto' or 'sparrow:SECONDS', got {spec!r}",
            name="nest",
        )
    if name == "shelf":
        return name, 0
    if not budget:
        return name, DEFAULT_SECONDS
    if not budget.isdigit() or int(budget) < 1:
        raise ParameterError(
            f"the nester's time budget must be a whole number of seconds >= 1, got {budget!r}",
            name="nest",
        )
    return name, int(budget)


def choose_nester(spec: str, sheet) -> tuple[str, int]:
    """The packer to use for ``spec`` (see :func:`parse_nest`) and a sheet size or None.

    ``"auto"`` is sparrow when it is installed and there is a sheet, else the shelf packer;
    ``"sparrow"`` needs both.

    Returns
    -------
    name : {"shelf", "sparrow"}
    seconds : int

    Raises
    ------
    ParameterError
        Naming ``nest``: sparrow asked for without a sheet, or not installed.
    """
    name, seconds = parse_nest(spec)
    if name == "auto":
        return ("sparrow", seconds) if sheet is not None and have_sparrow() else ("shelf", 0)
    if name == "sparrow":
        if sheet is None:
            raise ParameterError(
                "nest 'sparrow' places the pieces on sheets: give a sheet size (--sheet)",
                name="nest",
            )
        if not have_sparrow():
            raise ParameterError(
                "nest 'sparrow' needs the spyrrow package: pip install 'filletfold[nest]'",
                name="nest",
            )
    return name, seconds


def piece_outline(piece: Piece) -> shapely.Polygon:
    """The piece's outer boundary as one polygon (its faces' union, holes filled).

    Faces that only touch at points give a multi-polygon: its convex hull is taken then.
    """
    p2, _ = piece.arrays()
    shape = shapely.union_all(shapely.make_valid(face_polygons(p2, piece.faces)))
    if shape.geom_type == "Polygon":
        return shapely.Polygon(shape.exterior)
    return shapely.convex_hull(shape)


def clearance_shape(outline: shapely.Polygon, gap: float) -> shapely.Polygon:
    """``outline`` grown by at least half of ``gap`` everywhere, with few corners.

    The rounded corners are chords (inside their circle by ``1 - cos(pi / (4 QUAD_SEGS))``)
    and the simplification cuts corners by up to its tolerance: the offset is enlarged by both.
    """
    step = SIMPLIFY * gap
    half = 0.5 * gap / np.cos(np.pi / (4 * QUAD_SEGS)) + step
    grown = shapely.buffer(outline, half, quad_segs=QUAD_SEGS)
    if grown.geom_type != "Polygon":
        grown = shapely.convex_hull(grown)
    simple = shapely.simplify(shapely.Polygon(grown.exterior), step, preserve_topology=True)
    return shapely.orient_polygons(simple) if hasattr(shapely, "orient_polygons") else simple


def turn(degrees: float) -> np.ndarray:
    """(2, 2) rotation by ``degrees`` counter-clockwise; quarter turns are exact."""
    q = degrees / 90.0
    if abs(q - round(q)) < 1e-12:
        c, s = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][round(q) % 4]
    else:
        a = np.radians(degrees)
        c, s = float(np.cos(a)), float(np.sin(a))
    return np.array([[c, -s], [s, c]])


def _strip_pack(shapes: list[np.ndarray], height: float, seconds: int, seed: int, orientations):
    """sparrow's placement of ``shapes`` ((k, 2) float, about the origin) on a strip.

    ``seconds`` 0: sparrow's constructive placement only (no search), which does not depend
    on the time it takes; else ``seconds`` of search (80 % exploring, 20 % compressing).

    Returns
    -------
    (rotation, translation) or None
        Degrees about the origin ((n,) float), then the translation ((n, 2) float); None when
        sparrow found no place for a shape.
    """
    import spyrrow

    items = [
        spyrrow.Item(
            str(k),
            [tuple(map(float, p)) for p in shape],
            demand=1,
            allowed_orientations=None if orientations is None else list(orientations),
        )
        for k, shape in enumerate(shapes)
    ]
    instance = spyrrow.StripPackingInstance("filletfold", strip_height=float(height), items=items)
    if seconds:
        budget = {"total_computation_time": int(seconds)}
    else:
        budget = {"total_computation_time": None, "exploration_time": 0, "compression_time": 0}
    config = spyrrow.StripPackingConfig(early_termination=True, num_workers=1, seed=seed, **budget)
    try:
        solution = instance.solve(config)
    except BaseException as exc:  # a Rust panic (pyo3's PanicException derives from it)
        if type(exc).__name__ != "PanicException":
            raise
        return None
    rotation = np.zeros(len(shapes))
    translation = np.zeros((len(shapes), 2))
    for placed in solution.placed_items:
        k = int(placed.id)
        rotation[k] = float(placed.rotation)
        translation[k] = placed.translation
    return rotation, translation


def _extent(shape: np.ndarray, rotation: float, translation) -> np.ndarray:
    """``(xmin, ymin, xmax, ymax)`` of ``shape`` turned by ``rotation``, then moved."""
    q = shape @ turn(rotation).T + translation
    return np.concatenate([q.min(axis=0), q.max(axis=0)])


def nest_on_sheets(
    pieces: list[Piece],
    sheet: tuple[float, float],
    gap: float,
    *,
    seconds: int = DEFAULT_SECONDS,
    seed: int = SEED,
    turns=ORIENTATIONS,
):
    """Place pieces on sheets with sparrow; turn them in place (rigidly), return translations.

    First fit by decreasing area: a sheet is opened with the largest piece left; every other
    piece left, largest first, joins it when sparrow packs the sheet's pieces and it within a
    sheet width, or else the shelf rows hold them on one sheet (their area rules out the
    hopeless ones first); then the next sheet.

    Parameters
    ----------
    pieces : list of Piece
        Oriented (:func:`~filletfold.layout.fabrication.orient`). Their 2D points are turned
        about their bounding box centre.
    sheet : (float, float)
        Width and height of a sheet (pattern units); used landscape, laid out left to right
        (as :func:`~filletfold.layout.fabrication.pack_on_sheets`).
    gap : float
        Clearance between pieces and from the sheet edges.
    seconds : int
        sparrow's search time per packing run (0: its constructive placement only).
    seed : int
    turns : sequence of float or None
        Allowed turns in degrees; None: any angle.

    Returns
    -------
    offsets : (n_pieces, 2) float
    boxes : (n_sheets, 4) float
        ``(xmin, ymin, xmax, ymax)`` of each sheet.
    sheet_of : (n_pieces,) int
    runs : int
        Packing runs made.

    Raises
    ------
    ParameterError
        Naming ``sheet``: a piece does not fit on a sheet.
    """
    w, h = max(sheet), min(sheet)
    n = len(pieces)
    outlines = [piece_outline(p) for p in pieces]
    centre = np.array([np.asarray(o.bounds).reshape(2, 2).mean(axis=0) for o in outlines])
    grown = [clearance_shape(o, gap) for o in outlines]
    shapes = [np.asarray(g.exterior.coords)[:-1] - c for g, c in zip(grown, centre, strict=True)]
    # the grown shapes go on a strip h - gap high and sheets w - gap wide: moved by half the
    # gap onto the sheet, every piece keeps the gap from the sheet's edges
    height, width = h - gap, w - gap
    slack = 1e-9 * w
    area = np.array([g.area for g in grown])
    rotation = np.zeros(n)
    place = np.zeros((n, 2))  # translation on the strip, after the rotation
    sheet_of = np.full(n, -1, dtype=np.int64)
    size = np.array([np.ptp(shape, axis=0) for shape in shapes]).reshape(-1, 2)
    # sparrow's constructive placement samples positions: a shape with less room than this
    # on the strip is not found a place (it gives up, "strip-width is running away")
    roomy = np.all(size <= np.array([width, height]) * (1 - ROOM), axis=1)
    left = [int(k) for k in np.argsort(-area, kind="stable")]
    n_sheets = runs = 0
    while left:
        first = left.pop(0)
        place[first] = -shapes[first].min(axis=0)
        sheet_of[first] = n_sheets
        if not roomy[first]:  # too tight for the grown shape: alone, the gap from the corner
            o = np.asarray(outlines[first].bounds) - np.tile(centre[first], 2)
            extent = o[2:] - o[:2]
            if np.any(extent + 2 * gap > np.array([w, h]) * (1 + tol.relative)):
                raise ParameterError(
                    f"piece {first + 1} ({extent[0]:.4g} x {extent[1]:.4g}) does not fit on the "
                    f"sheet ({w:.4g} x {h:.4g} in pattern units); use a larger sheet or a "
                    "smaller scale",
                    name="sheet",
                )
            place[first] = 0.5 * gap - o[:2]
            n_sheets += 1
            continue
        members, used = [first], area[first]
        for k in list(left):
            if not roomy[k] or used + area[k] > width * height:
                continue
            trial = [*members, k]
            packed = _strip_pack([shapes[j] for j in trial], height, seconds, seed, turns)
            runs += 1
            if packed is not None:
                rot, shift = packed
                moved = zip(trial, rot, shift, strict=True)
                extent = np.array([_extent(shapes[j], r, t) for j, r, t in moved])
                fits = (
                    extent[:, :2].min() >= -slack
                    and extent[:, 2].max() <= width + slack
                    and extent[:, 3].max() <= height + slack
                )
            if packed is None or not fits:  # the shelf rows may still hold them
                rows, boxes, _ = pack_on_sheets([pieces[j] for j in trial], (w, h), gap)
                if len(boxes) != 1:
                    continue
                rot, shift = np.zeros(len(trial)), rows + centre[trial] - 0.5 * gap
            members, used = trial, used + area[k]
            rotation[trial], place[trial] = rot, shift
            left.remove(k)
        sheet_of[members] = n_sheets
        n_sheets += 1
    step = w + 4 * gap
    offsets = np.zeros((n, 2))
    for k, piece in enumerate(pieces):
        p2, _ = piece.arrays()
        piece.points_2d = list((p2 - centre[k]) @ turn(rotation[k]).T)
        offsets[k] = place[k] + (sheet_of[k] * step + 0.5 * gap, 0.5 * gap)
    boxes = np.array([[s * step, 0.0, s * step + w, h] for s in range(n_sheets)]).reshape(-1, 4)
    return offsets, boxes, sheet_of, runs


def placement_errors(
    pieces: list[Piece], offsets: np.ndarray, boxes: np.ndarray, sheet_of, gap: float
) -> list[str]:
    """What is wrong with a placement: pieces closer than ``gap`` (or overlapping) on a
    sheet, pieces not inside their sheet by ``gap``. Empty when the placement is valid.

    Parameters
    ----------
    pieces : list of Piece
    offsets : (n_pieces, 2) float
    boxes : (n_sheets, 4) float
    sheet_of : (n_pieces,) int
    gap : float

    Returns
    -------
    list of str
        One line per fault, naming the pieces (1-based, as the part numbers).
    """
    tight = gap * (1 - 1e-6)
    shapes = [
        shapely.affinity.translate(piece_outline(p), float(d[0]), float(d[1]))
        for p, d in zip(pieces, offsets, strict=True)
    ]
    faults = []
    for k, shape in enumerate(shapes):
        x0, y0, x1, y1 = boxes[sheet_of[k]]
        room = shapely.box(x0 + tight, y0 + tight, x1 - tight, y1 - tight)
        if not room.covers(shape):
            faults.append(f"piece {k + 1} is not within its sheet {sheet_of[k] + 1} by the gap")
    tree = shapely.STRtree(shapes)
    pairs = tree.query(shapes, predicate="dwithin", distance=tight)
    for a, b in zip(*pairs, strict=True):
        if a < b and sheet_of[a] == sheet_of[b]:
            faults.append(
                f"pieces {a + 1} and {b + 1} are {shapes[a].distance(shapes[b]):.4g} apart "
                f"(gap {gap:.4g})"
            )
    return faults


def use_figures(area: np.ndarray, pieces: list[Piece], offsets, boxes, sheet_of, gap) -> dict:
    """Material use of a placement on sheets.

    Returns
    -------
    dict
        ``material_use``: the pieces' area over the sheets' area; ``strip_use``: over a strip
        of the sheet's height as long as the sheets before the last plus the last sheet's used
        width (to its rightmost piece, plus the gap).
    """
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    n = len(boxes)
    w, h = boxes[0, 2] - boxes[0, 0], boxes[0, 3] - boxes[0, 1]
    last = [k for k in range(len(pieces)) if sheet_of[k] == n - 1]
    right = max(float(np.max(pieces[k].arrays()[0][:, 0] + offsets[k][0])) for k in last) - float(
        boxes[-1, 0]
    )
    total = float(np.sum(area))
    return {
        "material_use": float(total / (n * w * h)),
        "strip_use": float(total / (h * ((n - 1) * w + min(w, right + gap)))),
    }
