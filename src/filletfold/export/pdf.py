"""Printable PDF of the flat crease pattern at true scale, tiled over pages.

The drawing is printed so that one pattern length unit is ``scale`` ``units`` on paper. It is cut
into *regions*: one per sheet of material when the pattern's annotations have sheets (what is
drawn on each sheet, tiled on its own pages: pieces lie a tab and a gap inside their sheet, so
a sheet the size of the page prints on one page; anything outside every sheet is not printed),
otherwise one region around everything (pattern, tabs, labels). Each
region, grown by :data:`REGION_PAD_MM` on every side, is tiled from its top-left corner by tiles
the size of the printable area (the page minus ``margin_mm`` on each side), in rows top to bottom
and columns left to right: ``ceil(width / tile_width) * ceil(height / tile_height)`` pages per
region. Tiles abut exactly (no overlap): trim each page along its thin grey frame and butt the
frames together, aligning the corner crosses (registration marks). Each page says which region,
row and column it is; the first page also carries a scale bar.

Lines: mountain red, valley blue, borders/cuts black, tab outlines black and tab hinges green
dashed, sheet outlines grey, labels dark grey. Pages are portrait (custom ``"WxH"`` sizes are used
as given), or landscape for a sheet that takes fewer pages so. The output is deterministic (no
creation date).
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass

import numpy as np

from ..arrays import run_starts
from ..errors import ParameterError
from ..surface.pattern import CreasePattern
from ..surface.validate import validate_pattern
from ..tolerances import tol
from ..units import MM_PER_UNIT, check_units, sheet_size_mm
from .dxf import check_scale
from .palette import ASSIGNMENT_COLOR, KERF_COLOR, LABEL_COLOR, SHEET_COLOR, TAB_HINGE_COLOR
from .paths import drawn_points, edge_chains, edge_layer_masks, pattern_extent, tab_cut_paths
from .svg import nice_length

__all__ = ["MAX_PAGES", "REGION_PAD_MM", "Tile", "pattern_pages", "pattern_pdf"]

#: Blank border (mm) added around each region before it is tiled.
REGION_PAD_MM = 2.0
#: Most pages one PDF may have (a guard against a mistyped scale).
MAX_PAGES = 400
_PT_PER_MM = 1.0 / MM_PER_UNIT["pt"]
_LINE_MM = 0.25
_MARK_MM = 5.0
_FONT_PT = 8.0
_FRAME = "#b0b0b0"


@dataclass(frozen=True)
class Tile:
    """One page of the tiled drawing.

    Attributes
    ----------
    region : int
        Index of the region (sheet) the page belongs to.
    row, col : int
        Position of the tile in its region, from 1, rows top to bottom.
    rows, cols : int
        Tiles of the region.
    box : (4,) tuple of float
        ``(xmin, ymin, xmax, ymax)`` of the tile in drawing millimetres.
    landscape : bool
        Whether the page is turned (a sheet of material that takes fewer pages so).
    """

    region: int
    row: int
    col: int
    rows: int
    cols: int
    box: tuple
    landscape: bool = False


def _check_units(units: str) -> float:
    """Millimetres per ``units``; a :class:`ParameterError` for a unit not printable."""
    return MM_PER_UNIT[check_units(units, MM_PER_UNIT, unitless=False)]


def pdf_tiles(
    pattern: CreasePattern,
    *,
    page: str = "A4",
    units: str = "mm",
    scale: float = 1.0,
    margin_mm: float = 10.0,
) -> list[Tile]:
    """The pages of :func:`pattern_pdf`, in order (see the module docstring for the rule).

    Parameters
    ----------
    pattern : CreasePattern
    page, units, scale, margin_mm
        As for :func:`pattern_pdf`.

    Returns
    -------
    list of Tile

    Raises
    ------
    ParameterError
        For an invalid page, unit, scale or margin, or more than :data:`MAX_PAGES` pages.
    """
    width, height = sheet_size_mm(page, name="page")
    k = _check_units(units) * check_scale(scale)
    if isinstance(margin_mm, bool) or not isinstance(margin_mm, int | float):
        raise ParameterError(f"margin_mm must be a number, got {margin_mm!r}", name="margin_mm")
    if not (math.isfinite(margin_mm) and 0 <= margin_mm and 2 * margin_mm < min(width, height)):
        raise ParameterError(
            f"margin_mm must be >= 0 and leave a printable area on a {width:g} x {height:g} mm "
            f"page, got {margin_mm!r}",
            name="margin_mm",
        )
    tw, th = width - 2 * margin_mm, height - 2 * margin_mm
    sheets = np.asarray(pattern.annotations.sheets, dtype=np.float64).reshape(-1, 4)
    if len(sheets):
        regions = _sheet_contents(pattern, sheets) * k
    else:
        lo, hi = pattern_extent(pattern)
        regions = np.array([[*(lo * k), *(hi * k)]])
    tiles = []
    for r, (x0, y0, x1, y1) in enumerate(regions):
        x0, y0, x1, y1 = (
            x0 - REGION_PAD_MM,
            y0 - REGION_PAD_MM,
            x1 + REGION_PAD_MM,
            y1 + REGION_PAD_MM,
        )
        cols, rows = _grid(x1 - x0, y1 - y0, tw, th)
        turned = bool(len(sheets)) and (  # a sheet of material on pages of its own turn
            math.prod(_grid(x1 - x0, y1 - y0, th, tw)) < cols * rows
        )
        pw, ph = (th, tw) if turned else (tw, th)
        if turned:
            cols, rows = _grid(x1 - x0, y1 - y0, pw, ph)
        if len(tiles) + rows * cols > MAX_PAGES:
            raise ParameterError(
                f"the PDF would need more than {MAX_PAGES} {width:g} x {height:g} mm pages; "
                "use a smaller scale or a larger page",
                name="scale",
            )
        for i in range(rows):
            for j in range(cols):
                box = (x0 + j * pw, y1 - (i + 1) * ph, x0 + (j + 1) * pw, y1 - i * ph)
                box = tuple(float(b) for b in box)
                tiles.append(Tile(r, i + 1, j + 1, rows, cols, box, turned))
    return tiles


def _grid(w: float, h: float, tw: float, th: float) -> tuple[int, int]:
    """Columns and rows of pages of printable area ``tw`` x ``th`` that tile a region
    ``w`` x ``h``."""
    return max(1, math.ceil(w / tw - tol.relative)), max(1, math.ceil(h / th - tol.relative))


def _sheet_contents(pattern: CreasePattern, sheets: np.ndarray) -> np.ndarray:
    """(n, 4) the box of what is drawn on each sheet (within it; the sheet where nothing
    is): pieces lie inside their sheet by a tab and a gap, so a sheet the size of the page
    prints on one page (its box would need four, the printer's margins taken off)."""
    pts = drawn_points(pattern, sheets=False)
    out = sheets.copy()
    for r, (x0, y0, x1, y1) in enumerate(sheets):
        on = pts[(pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1)]
        if len(on):
            out[r] = [*on.min(axis=0), *on.max(axis=0)]
    return out


def pattern_pdf(
    pattern: CreasePattern,
    *,
    page: str = "A4",
    units: str = "mm",
    scale: float = 1.0,
    margin_mm: float = 10.0,
) -> bytes:
    """The flat layout at true scale, tiled over printable pages.

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`; its annotations are
        drawn when present.
    page : str
        A sheet of :func:`~filletfold.units.sheet_size_mm` (``"A4"``, ``"A1"``, ``"Letter"``,
        ``"600x400"``, ...).
    units : str
        ``"mm"``, ``"cm"``, ``"m"``, ``"in"`` or ``"pt"``: the printed unit of
        ``scale`` pattern units (one pattern unit is printed ``scale`` ``units`` long).
    scale : float
        Positive.
    margin_mm : float
        Unprinted border of each page, on every side.

    Returns
    -------
    bytes
        The PDF (starts with ``%PDF``); one page per :class:`Tile` of :func:`pdf_tiles`. Same
        input, same bytes.

    Raises
    ------
    ParameterError
        For an invalid page, unit, scale or margin, or too many pages.
    ExportError
        When the pattern is inconsistent.
    """
    from matplotlib.backends.backend_pdf import PdfPages

    pages = pattern_pages(pattern, page=page, units=units, scale=scale, margin_mm=margin_mm)
    buf = io.BytesIO()
    with PdfPages(buf, metadata={"CreationDate": None, "Creator": "filletfold"}) as pdf:
        for fig in pages:
            pdf.savefig(fig)
    return buf.getvalue()


def pattern_pages(
    pattern: CreasePattern,
    *,
    page: str = "A4",
    units: str = "mm",
    scale: float = 1.0,
    margin_mm: float = 10.0,
):
    """The pages of :func:`pattern_pdf`, one matplotlib Figure at a time (checked first: the
    same errors; a picture of a page: ``fig.savefig(...)``)."""
    tiles = pdf_tiles(pattern, page=page, units=units, scale=scale, margin_mm=margin_mm)
    validate_pattern(pattern)
    return _pages(pattern, tiles, page, units, float(scale), margin_mm)


def _pages(pattern, tiles, page, units, scale, margin_mm):
    width, height = sheet_size_mm(page, name="page")
    layers = _drawing_mm(pattern, MM_PER_UNIT[units] * scale)
    n_regions = 1 + max(t.region for t in tiles)
    for number, tile in enumerate(tiles):
        w, h = (height, width) if tile.landscape else (width, height)
        fig = _page_figure(layers, tile, w, h, margin_mm)
        head = f"row {tile.row} / col {tile.col}"
        if n_regions > 1:
            head = f"sheet {tile.region + 1} / {n_regions} - {head}"
        fig.axes[0].text(
            margin_mm,
            h - 0.5 * margin_mm,
            f"{head}    (page {number + 1} of {len(tiles)}; trim at the grey frame, "
            "abut, align the crosses)",
            fontsize=_FONT_PT,
            va="center",
            ha="left",
            color="#000000",
        )
        if number == 0:
            _scale_bar(fig.axes[0], units, scale, margin_mm, w)
        yield fig


def _drawing_mm(pattern: CreasePattern, k: float) -> dict:
    """Polylines (in drawing mm) of every layer, and the labels; ``BOXES`` the polylines'
    boxes per layer (:func:`_line_boxes`), ``LABEL_AT`` (k, 2) and ``LABEL_HEIGHT`` (k,) the
    labels' anchors and heights, to find what a page shows."""
    v = pattern.vertices_2d * k
    out = {}
    for layer, mask in edge_layer_masks(pattern).items():
        lines = []
        for chain, closed in edge_chains(pattern.edges, mask):
            p = v[chain]
            lines.append(np.vstack([p, p[:1]]) if closed else p)
        out[layer] = lines
    ann = pattern.annotations
    out["CUT"] = out["CUT"] + [
        np.vstack([p, p[:1]]) * k if closed else np.asarray(p) * k
        for p, closed in tab_cut_paths(ann)
    ]
    out["TAB"] = [np.asarray(h, dtype=np.float64).reshape(2, 2) * k for h in ann.tab_hinges]
    for m in ann.making:  # a sheet material's reliefs (cut) and kerf grooves
        p = np.asarray(m.points, dtype=np.float64) * k
        layer = "CUT" if m.kind == "relief" else m.kind.upper().replace("-", "_")
        out.setdefault(layer, []).append(np.vstack([p, p[:1]]) if m.closed else p)
    sheets = np.asarray(ann.sheets, dtype=np.float64).reshape(-1, 4) * k
    out["SHEET"] = [
        np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]]) for x0, y0, x1, y1 in sheets
    ]
    out["LABEL"] = [
        (
            np.asarray(lb.position, dtype=np.float64).reshape(2) * k,
            str(lb.text),
            float(lb.angle),
            float(lb.height) * k,
        )
        for lb in ann.labels
    ]
    out["BOXES"] = {layer: _line_boxes(out[layer]) for layer in out if layer != "LABEL"}
    out["LABEL_AT"] = np.array([pos for pos, _, _, _ in out["LABEL"]]).reshape(-1, 2)
    out["LABEL_HEIGHT"] = np.array([h for _, _, _, h in out["LABEL"]], dtype=np.float64)
    return out


def _line_boxes(lines: list) -> np.ndarray:
    """(k, 4) ``(xmin, ymin, xmax, ymax)`` of each of the polylines ``lines`` (each (m, 2),
    m >= 1)."""
    if not lines:
        return np.zeros((0, 4))
    points = np.concatenate(lines)
    start = run_starts([len(p) for p in lines])[:-1]
    return np.c_[np.minimum.reduceat(points, start), np.maximum.reduceat(points, start)]


def _in_box(lines: list, boxes: np.ndarray, box) -> list:
    """The polylines whose bounding box (a row of ``boxes``, :func:`_line_boxes`) meets
    ``box``."""
    x0, y0, x1, y1 = box
    meets = (boxes[:, 2] >= x0) & (boxes[:, 0] <= x1) & (boxes[:, 3] >= y0) & (boxes[:, 1] <= y1)
    return [lines[i] for i in np.flatnonzero(meets).tolist()]


def _page_figure(layers: dict, tile: Tile, width: float, height: float, margin: float):
    """One page: the tile's part of the drawing clipped to the printable area, frame, marks."""
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    fig = Figure(figsize=(width / MM_PER_UNIT["in"], height / MM_PER_UNIT["in"]))
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_xlim(0.0, width)
    ax.set_ylim(0.0, height)
    ax.set_axis_off()
    x0, y0, x1, y1 = tile.box
    tw, th = x1 - x0, y1 - y0
    shift = np.array([margin - x0, margin - y0])
    clip = Rectangle((margin, margin), tw, th, transform=ax.transData, fill=False)
    lw = _LINE_MM * _PT_PER_MM
    styles = [
        ("SHEET", SHEET_COLOR, 0.5 * lw, "solid"),
        ("CUT", ASSIGNMENT_COLOR["B"], lw, "solid"),
        ("VALLEY", ASSIGNMENT_COLOR["V"], lw, "solid"),
        ("MOUNTAIN", ASSIGNMENT_COLOR["M"], lw, "solid"),
        ("TAB", TAB_HINGE_COLOR, lw, (0, (4, 3))),
        ("KERF_FRONT", KERF_COLOR["kerf-front"], lw, "solid"),
        ("KERF_BACK", KERF_COLOR["kerf-back"], lw, "solid"),
    ]
    for layer, color, width_pt, style in styles:
        if layer not in layers:
            continue
        lines = _in_box(layers[layer], layers["BOXES"][layer], tile.box)
        if not lines:
            continue
        lc = LineCollection(
            [p + shift for p in lines], colors=color, linewidths=width_pt, linestyles=style
        )
        lc.set_capstyle("round")
        lc.set_joinstyle("round")
        ax.add_collection(lc)
        lc.set_clip_path(clip)
    at, reach = layers["LABEL_AT"], 5 * layers["LABEL_HEIGHT"]
    near = (x0 - reach <= at[:, 0]) & (at[:, 0] <= x1 + reach)
    near &= (y0 - reach <= at[:, 1]) & (at[:, 1] <= y1 + reach)
    for i in np.flatnonzero(near).tolist():
        pos, text, angle, h = layers["LABEL"][i]
        t = ax.text(
            *(pos + shift),
            text,
            rotation=angle,
            rotation_mode="anchor",
            ha="center",
            va="center",
            fontsize=max(h * _PT_PER_MM / 0.72, 1.0),
            color=LABEL_COLOR,
        )
        t.set_clip_path(clip)
    ax.add_patch(
        Rectangle(
            (margin, margin), tw, th, fill=False, edgecolor=_FRAME, linewidth=0.1 * _PT_PER_MM
        )
    )
    arm = min(_MARK_MM, 0.25 * min(tw, th))
    marks = []
    for cx, cy in (
        (margin, margin),
        (margin + tw, margin),
        (margin, margin + th),
        (margin + tw, margin + th),
    ):
        marks.append([(cx - arm, cy), (cx + arm, cy)])
        marks.append([(cx, cy - arm), (cx, cy + arm)])
    ax.add_collection(LineCollection(marks, colors="#000000", linewidths=0.15 * _PT_PER_MM))
    return fig


def _scale_bar(ax, units: str, scale: float, margin: float, width: float) -> None:
    """A bar of a round length in ``units`` in the bottom margin, with its label."""
    mm_per = MM_PER_UNIT[units]
    bar = nice_length(min(50.0, 0.4 * (width - 2 * margin)) / mm_per)
    length_mm = bar * mm_per
    y = 0.35 * margin
    h = min(1.5, 0.2 * max(margin, 1.0))
    from matplotlib.patches import Rectangle

    ax.add_patch(Rectangle((margin, y), length_mm, h, facecolor="#000000", edgecolor="none"))
    text = f"{bar:g} {units}"
    if scale != 1.0:
        text += f"  (= {bar / scale:g} pattern units; scale {scale:g} {units} per unit)"
    ax.text(margin + length_mm + 2.0, y + 0.5 * h, text, fontsize=_FONT_PT, va="center")
