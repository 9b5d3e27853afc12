"""SVG drawing of the flat crease pattern, to print, cut, or load into Origami Simulator.

The drawing follows a cutter preset (:mod:`filletfold.export.presets`). The default, ``print``,
is the drawing to print and cut: each layer's edges joined end to end into ``<polyline>`` (or
``<polygon>``) paths in the conventional colours (borders and cuts black, valley blue, mountain
red, tab hinges magenta), labels as filled ``<text>``, the scale bar, legend and sheet outlines
in ``<defs>``; the ``F`` edges (facets inside the curved patches, neither cut nor scored) are
left out: ``design.fold`` holds them.

``origami-simulator`` is a file Origami Simulator imports without a warning:

* each edge is a ``<line>`` carrying its own ``stroke`` colour, in one group per assignment:
  facet ``#ffff00`` (``F`` edges, group ``flat``), border/cut ``#000000``, valley ``#0000ff``,
  mountain ``#ff0000``, and each mountain and valley line has ``stroke-opacity`` =
  |fold angle| / 180 (the app's target fold angle);
* the tab hinges are magenta ``#ff00ff`` (the app's passive hinge), the cut part of each tab
  outline black (groups ``tab-hinge``, ``tab-cut``);
* the scale bar, legend and sheet outlines (groups ``scale-bar``, ``legend``, ``sheets``) sit in
  a ``<g id="annotation">`` inside ``<defs>``, drawn by a ``<use>``: the app removes ``<defs>``
  before it reads strokes, every other viewer shows them. Labels are filled ``<text>`` (group
  ``labels``), which the app does not read.

In every preset the viewBox is in units of :math:`10^{-j}` mm (``width``/``height`` give the
printed size), ``j >= 0`` the smallest that puts the two closest drawn points at least
:data:`MIN_POINT_SPACING` user units apart (ten times the app's 3-unit vertex merge tolerance),
so no two vertices collapse on import. Coordinates have at most 8 significant digits of the
drawing, and in the cut-file presets no more than resolve :data:`RESOLUTION_MM` of the printed
size (whole user units once ``j >= 3``); ``origami-simulator`` keeps the 8 digits.

The cutter presets (``laser``, ``plotter``, ``card``) draw joined paths too, their pens' widths
and colours, dashed score lines as a ``stroke-dasharray``, perforated ones as separate dash
pieces, and no legend, scale bar or sheet outlines (nothing is cut or engraved that is not the
pattern). The y axis is flipped so the drawing is not mirrored.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from xml.sax.saxutils import escape

import numpy as np

from ..errors import ParameterError
from ..layout.making import MAKING_KINDS
from ..surface.pattern import CreasePattern, LabelRows
from ..surface.validate import validate_pattern
from ..units import MM_PER_UNIT, check_units
from .palette import SHEET_COLOR
from .paths import (
    dash_polylines,
    edge_chains,
    pattern_extent,
    simplify_polylines,
    tab_cut_paths,
)
from .presets import RESOLUTION_MM, Pen, Preset, get_preset, making_pens

__all__ = [
    "MIN_POINT_SPACING",
    "RESOLUTION_MM",
    "nice_length",
    "pattern_svg",
    "svg_decimals",
    "svg_user_per_mm",
]

#: Group id, assignment and legend label of each edge group, in drawing order (bottom first).
_GROUPS = (
    ("F", "flat", "facet (flat)"),
    ("B", "border", "border / cut"),
    ("V", "valley", "valley"),
    ("M", "mountain", "mountain"),
)
#: Role of each assignment's pen in a preset.
_ROLE = {"F": "flat", "B": "cut", "V": "valley", "M": "mountain"}
#: Printed size (mm) of the larger side of the drawing when no unit is given.
_UNITLESS_MM = 200.0
_MARGIN_MM = 10.0
_FONT_MM = 3.5
_SWATCH_MM = 8.0
#: Smallest distance, in user units, between two distinct drawn points: ten times Origami
#: Simulator's default vertex merge tolerance (3 user units).
MIN_POINT_SPACING = 30.0
#: Largest viewBox side (user units) the spacing rule may ask for.
_MAX_USER_EXTENT = 1e7
#: Decimals of a label's rotation (degrees).
_ANGLE_DECIMALS = 2
#: Points closer than this share of the drawing's size are one point (round-off).
_SAME_POINT = 1e-9


def nice_length(target: float) -> float:
    """The round length ``{1, 2, 5} * 10**k`` closest to ``target`` on a log scale.

    Parameters
    ----------
    target : float
        Positive length.

    Returns
    -------
    float
    """
    if not (target > 0 and math.isfinite(target)):
        raise ParameterError(f"scale bar length must be positive, got {target}", name="target")
    k = math.floor(math.log10(target))
    candidates = [m * 10.0**e for e in (k - 1, k, k + 1) for m in (1, 2, 5)]
    return min(candidates, key=lambda c: abs(math.log(c / target)))


def _formatter(decimals: int):
    """A deterministic number formatter with ``decimals`` fixed decimals, zeros stripped."""

    def fmt(x: float) -> str:
        s = f"{x:.{decimals}f}"
        if "." in s:
            s = s.rstrip("0").rstrip(".")
        return "0" if s in ("-0", "") else s

    return fmt


def _format_all(x: np.ndarray, decimals: int) -> list[str]:
    """``_formatter(decimals)`` of every value of ``x`` (k,), formatted in bulk."""
    if len(x) == 0:
        return []
    out = ((f"%.{decimals}f\n" * len(x)) % tuple(x.tolist()))[:-1].split("\n")
    if decimals > 0:  # strip trailing zeros and a trailing point
        out = [t.rstrip("0").rstrip(".") for t in out]
    # "-0" (a small negative) and "" are written "0"
    for i in np.flatnonzero(np.signbit(x) & (x > -(10.0**-decimals))).tolist():
        if out[i] in ("-0", ""):
            out[i] = "0"
    return out


def pattern_svg(
    pattern: CreasePattern,
    *,
    units: str = "",
    preset: str | Preset | None = None,
    stroke_mm: float | None = None,
    flat_edges: bool | None = None,
    angle_opacity: bool | None = None,
) -> str:
    """The flat layout of a crease pattern as an SVG document.

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`.
    units : str
        Length unit of the pattern coordinates: ``"mm"``, ``"cm"``, ``"m"``, ``"in"``, ``"pt"``,
        or ``""`` (no physical unit: the larger side is printed 200 mm long). Sets the printed
        size (``width``/``height`` in mm) and the scale bar label.
    preset : str or Preset, optional
        Cutter preset (:data:`~filletfold.export.presets.PRESETS`); default ``print``.
    stroke_mm : float, optional
        Printed width of every line in millimetres (default: the preset's pens).
    flat_edges : bool, optional
        Draw the ``F`` edges, in a ``flat`` group (default: the preset's).
    angle_opacity : bool, optional
        Give each mountain and valley line ``stroke-opacity`` = ``|fold angle| / 180``, which
        Origami Simulator reads as the target fold angle (default: the preset's).

    Returns
    -------
    str
        The SVG document (UTF-8, ends with a newline). Same input, same bytes.

    Raises
    ------
    ParameterError
        For an unknown ``units`` or ``preset``, or a non-positive ``stroke_mm``.
    ExportError
        When the pattern is inconsistent.
    """
    check_units(units, MM_PER_UNIT, unitless=True)
    preset = get_preset(preset)
    if stroke_mm is not None and not (
        isinstance(stroke_mm, int | float) and math.isfinite(stroke_mm) and stroke_mm > 0
    ):
        raise ParameterError(
            f"stroke_mm must be a positive number, got {stroke_mm!r}", name="stroke_mm"
        )
    validate_pattern(pattern)
    return _pattern_svg(pattern, units, preset, stroke_mm, flat_edges, angle_opacity)


def svg_decimals(size: float, user: float, resolution_mm: float | None = RESOLUTION_MM) -> int:
    """Decimals of the SVG's coordinates: the fewer of 8 significant digits of ``size`` (the
    drawing's larger side in user units) and those that resolve ``resolution_mm`` at ``user``
    user units per printed millimetre (``user`` a power of ten).

    Parameters
    ----------
    size, user : float
        Positive.
    resolution_mm : float, optional
        The finest printed length to resolve (a preset's
        :attr:`~filletfold.export.presets.Preset.resolution_mm`); ``None``: the 8 digits alone.

    Returns
    -------
    int
        ``>= 0``.
    """
    digits = 8 - math.floor(math.log10(size))
    if resolution_mm is not None:
        digits = min(digits, math.ceil(-math.log10(resolution_mm * user) - 1e-9))
    return max(0, digits)


def svg_user_per_mm(points: np.ndarray, mm_per_unit: float, extent: float) -> float:
    """User units per printed millimetre of :func:`pattern_svg`'s viewBox.

    Parameters
    ----------
    points : (k, 2) float
        The drawn points (edge ends, tab corners) in pattern units.
    mm_per_unit : float
        Printed millimetres per pattern unit.
    extent : float
        The drawing's larger side in pattern units.

    Returns
    -------
    float
        ``10**j`` for the smallest ``j >= 0`` at which the two closest distinct points are at
        least :data:`MIN_POINT_SPACING` user units apart (points within ``1e-9`` of ``extent``
        count as one), but no larger than keeps ``extent`` under ``1e7`` user units.
    """
    from scipy.spatial import cKDTree

    # the distinct points: sorted as complex numbers (x, y), twice as fast as rows
    xy = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 2))
    z = np.unique(xy.view(np.complex128).ravel())
    p = np.stack([z.real, z.imag], axis=1)
    j = 0
    if len(p) > 1:
        d, _ = cKDTree(p).query(p, k=2)
        d = d[:, 1][d[:, 1] > _SAME_POINT * extent]
        if len(d):
            j = max(0, math.ceil(math.log10(MIN_POINT_SPACING / (float(d.min()) * mm_per_unit))))
    cap = math.floor(math.log10(_MAX_USER_EXTENT / max(extent * mm_per_unit, 1e-300)))
    return 10.0 ** max(0, min(j, cap))


def _pattern_svg(
    pattern, units="", preset=None, stroke_mm=None, flat_edges=None, angle_opacity=None
) -> str:
    """:func:`pattern_svg` of a pattern and arguments already checked."""
    return "".join(
        _pattern_svg_chunks(pattern, units, preset, stroke_mm, flat_edges, angle_opacity)
    )


def _pattern_svg_chunks(
    pattern, units="", preset=None, stroke_mm=None, flat_edges=None, angle_opacity=None
) -> Iterator[str]:
    """:func:`_pattern_svg`'s text a group at a time, each group drawn when its turn comes:
    written as it comes (:func:`~filletfold.export.atomic.write_outputs`), a large design's
    drawing is never whole in memory, only its largest group."""
    preset = get_preset(preset)
    flat_edges = preset.flat_edges if flat_edges is None else bool(flat_edges)
    angle_opacity = preset.angle_opacity if angle_opacity is None else bool(angle_opacity)
    v = pattern.vertices_2d
    lo, hi = pattern_extent(pattern)
    size = hi - lo
    extent = float(size.max())
    if extent <= 0:
        extent = 1.0
    mm_per_unit = MM_PER_UNIT[units] if units else _UNITLESS_MM / extent
    edges = np.asarray(pattern.edges, dtype=np.int64).reshape(-1, 2)
    assign = np.asarray(pattern.edge_assignment)
    angle = np.asarray(pattern.edge_fold_angle, dtype=np.float64)
    ann = pattern.annotations
    drawn = (assign != "F") | flat_edges
    paths = tab_cut_paths(ann)
    hinges = np.array(
        [np.asarray(h, dtype=np.float64).reshape(2, 2) for h in ann.tab_hinges]
    ).reshape(-1, 2, 2)
    points = np.concatenate(
        [v[np.unique(edges[drawn])], *[q for q, _ in paths], hinges.reshape(-1, 2)]
    )
    user = svg_user_per_mm(points, mm_per_unit, extent)  # user units per mm
    del points
    k = mm_per_unit * user  # user units per pattern unit
    margin = _MARGIN_MM * user
    font = _FONT_MM * user
    decimals = svg_decimals(extent * k + 2 * margin, user, preset.resolution_mm)
    fmt = _formatter(decimals)
    draw = _Drawing(lo, hi, k, margin, decimals, user, stroke_mm)

    groups = [g for g in _GROUPS if g[0] != "F" or flat_edges]
    legend = [(getattr(preset, _ROLE[code]).color, label) for code, _, label in groups]
    if len(hinges):
        legend.append((preset.tab.color, "tab hinge"))
    for kind in MAKING_KINDS:
        if any(m.kind == kind for m in ann.making):
            legend.append((making_pens(preset)[kind].color, kind.replace("-", " ")))

    def body() -> Iterator[str]:
        """The drawing's groups, each made when it is written."""
        for code, gid, _ in groups:
            pen = getattr(preset, _ROLE[code])
            mask = assign == code
            yield draw.group_open(gid, pen)
            if pen.perforation_mm is not None:
                dashes = draw.dashes(
                    [(v[c], closed) for c, closed in edge_chains(edges, mask)], pen.perforation_mm
                )
                yield draw.polylines([(q, False) for q in dashes], pen.color)
            elif (angle_opacity and code in ("M", "V")) or not preset.join_lines:
                sel = np.flatnonzero(mask)
                opacity = None
                if angle_opacity and code in ("M", "V"):
                    opacity = np.clip(np.abs(angle[sel]) / 180.0, 1e-6, 1.0)
                yield draw.lines(v[edges[sel, 0]], v[edges[sel, 1]], pen.color, opacity)
            else:
                chains = edge_chains(edges, mask)
                simple = simplify_polylines([(v[c], closed) for c, closed in chains])
                yield draw.polylines(
                    [(q, closed) for q, (_, closed) in zip(simple, chains, strict=True)],
                    pen.color,
                )
            yield "</g>"
        if paths:
            yield draw.group_open("tab-cut", preset.cut, join=True)
            yield draw.polylines(paths, preset.cut.color)
            yield "</g>"
        if len(hinges):
            pen = preset.tab
            yield draw.group_open("tab-hinge", pen)
            if pen.perforation_mm is not None:
                dashes = draw.dashes([(h, False) for h in hinges], pen.perforation_mm)
                yield draw.polylines([(q, False) for q in dashes], pen.color)
            else:
                yield draw.lines(hinges[:, 0], hinges[:, 1], pen.color)
            yield "</g>"
        pens = making_pens(preset)
        for kind in MAKING_KINDS:  # a sheet material's reliefs and kerf grooves
            made = [(m.points, m.closed) for m in ann.making if m.kind == kind]
            if made:
                yield draw.group_open(kind, pens[kind], join=True)
                yield draw.polylines(made, pens[kind].color)
                yield "</g>"
        yield from _label_group(pattern, draw, preset.label.color)

    draw_w = float(size[0]) * k + 2 * margin
    draw_h = float(size[1]) * k + 2 * margin
    total_w, total_h = draw_w, draw_h
    ann_text = []
    if preset.annotations:
        # scale bar and legend below the drawing, sheet outlines; all in <defs>, shown by <use>
        bar = nice_length(max(float(size[0]), extent * 0.2) / 5.0)
        bar_h = 1.0 * user
        bar_y = draw_h
        label = f"{bar:g} {units}".rstrip()
        ann_text = ["<defs>", '<g id="annotation" stroke="none">']
        ann_text.extend(draw.sheet_group(ann.sheets))
        ann_text.append(
            f'<g id="scale-bar"><rect x="{fmt(margin)}" y="{fmt(bar_y)}" width="{fmt(bar * k)}" '
            f'height="{fmt(bar_h)}" fill="#000000"/>'
        )
        ann_text.append(
            f'<text x="{fmt(margin + bar * k + 2 * user)}" y="{fmt(bar_y + bar_h)}" '
            f'font-family="sans-serif" font-size="{fmt(font)}" fill="#000000">'
            f"{escape(label)}</text></g>"
        )
        leg_y = bar_y + bar_h + 2 * font
        xcur = margin
        ann_text.append('<g id="legend" font-family="sans-serif" fill="#000000">')
        swatch_h = max(stroke_mm or preset.mountain.width_mm, 0.5) * user
        for color, text in legend:
            ann_text.append(
                f'<rect x="{fmt(xcur)}" y="{fmt(leg_y - 0.5 * font)}" '
                f'width="{fmt(_SWATCH_MM * user)}" height="{fmt(swatch_h)}" fill="{color}"/>'
            )
            xcur += (_SWATCH_MM + 2.0) * user
            ann_text.append(
                f'<text x="{fmt(xcur)}" y="{fmt(leg_y)}" font-size="{fmt(font)}">'
                f"{escape(text)}</text>"
            )
            xcur += (0.62 * _FONT_MM * len(text) + 6.0) * user
        ann_text.extend(["</g>", "</g>", "</defs>"])
        ann_text.append('<use href="#annotation" xlink:href="#annotation"/>')
        total_w = max(
            draw_w,
            xcur + margin,
            margin + bar * k + (2 + 0.62 * _FONT_MM * len(label)) * user + margin,
        )
        total_h = leg_y + font + margin
    xlink = ' xmlns:xlink="http://www.w3.org/1999/xlink"' if preset.annotations else ""
    colours = ", ".join(
        f"{role} {pen.color}" for role, pen in preset.pens().items() if role != "flat"
    )
    head = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg"{xlink} version="1.1" '
        f'width="{total_w / user:.3f}mm" height="{total_h / user:.3f}mm" '
        f'viewBox="0 0 {fmt(total_w)} {fmt(total_h)}">',
        "<title>filletfold crease pattern</title>",
        f"<desc>preset {escape(preset.name)}: {colours}; units: {escape(units or 'none')}; "
        f"{fmt(user)} user units per mm</desc>",
    ]
    for part in head:
        yield part + "\n"
    for part in body():
        yield part + "\n"
    for part in [*ann_text, "</svg>"]:
        yield part + "\n"


class _Drawing:
    """Pattern coordinates to SVG text: the y flip, scale, margin and number format."""

    def __init__(self, lo, hi, k, margin, decimals, user, stroke_mm):
        self.lo, self.hi, self.k, self.margin = lo, hi, k, margin
        self.decimals, self.user, self.stroke_mm = decimals, user, stroke_mm
        self.fmt = _formatter(decimals)

    def x(self, x: np.ndarray) -> list[str]:
        return _format_all(
            (np.asarray(x, dtype=np.float64) - self.lo[0]) * self.k + self.margin, self.decimals
        )

    def y(self, y: np.ndarray) -> list[str]:
        return _format_all(
            (self.hi[1] - np.asarray(y, dtype=np.float64)) * self.k + self.margin, self.decimals
        )

    def width(self, pen: Pen) -> float:
        """A pen's stroke width in user units."""
        return (self.stroke_mm or pen.width_mm) * self.user

    def group_open(self, gid: str, pen: Pen, join: bool = False) -> str:
        """The opening tag of a group drawn with ``pen`` (width, dash style)."""
        extra = ""
        if pen.perforation_mm is None:
            if pen.dash_mm is not None:
                extra = (
                    f' stroke-dasharray="{self.fmt(pen.dash_mm[0] * self.user)} '
                    f'{self.fmt(pen.dash_mm[1] * self.user)}"'
                )
            elif pen.dash_share is not None:
                d = self.fmt(pen.dash_share * (self.hi - self.lo).max() * self.k)
                extra = f' stroke-dasharray="{d} {d}"'
        if join:
            extra += ' stroke-linejoin="round"'
        return (
            f'<g id="{gid}" stroke-width="{self.fmt(self.width(pen))}" stroke-linecap="round"'
            f'{extra} fill="none">'
        )

    def lines(self, a: np.ndarray, b: np.ndarray, color: str, opacity=None) -> str:
        """One ``<line>`` per segment ``a[i]``-``b[i]`` (pattern units), with
        ``stroke-opacity`` when given."""
        if len(a) == 0:
            return ""
        cols = [self.x(a[:, 0]), self.y(a[:, 1]), self.x(b[:, 0]), self.y(b[:, 1])]
        if opacity is None:
            line = f'<line x1="%s" y1="%s" x2="%s" y2="%s" stroke="{color}"/>'
        else:
            line = f'<line x1="%s" y1="%s" x2="%s" y2="%s" stroke="{color}" stroke-opacity="%s"/>'
            cols.append([f"{o:.6f}" for o in np.asarray(opacity).tolist()])
        return _rows(line, cols)

    def polylines(self, paths: list, color: str) -> str:
        """One ``<polyline>`` per open path, ``<polygon>`` per closed one (pattern units)."""
        paths = [(np.asarray(q, dtype=np.float64).reshape(-1, 2), c) for q, c in paths]
        paths = [(q, c) for q, c in paths if len(q) > 1]
        if not paths:
            return ""
        q = np.concatenate([pts for pts, _ in paths])
        shapes = [(closed, len(pts)) for pts, closed in paths]
        template = {
            (closed, n): f'<{"polygon" if closed else "polyline"} points="'
            + " ".join(["%s,%s"] * n)
            + f'" stroke="{color}"/>'
            for closed, n in set(shapes)
        }
        values = tuple(
            itertools.chain.from_iterable(zip(self.x(q[:, 0]), self.y(q[:, 1]), strict=True))
        )
        return "\n".join(map(template.__getitem__, shapes)) % values

    def dashes(self, paths: list, perforation_mm) -> list[np.ndarray]:
        """The perforation dashes of paths (pattern units), lengths given in printed mm."""
        cut, gap = (x * self.user / self.k for x in perforation_mm)
        return [d for q, closed in paths for d in dash_polylines(q, closed, cut, gap)]

    def sheet_group(self, sheets) -> list[str]:
        """The ``sheets`` group: one grey ``<rect>`` per sheet outline (empty when none)."""
        sheets = np.asarray(sheets, dtype=np.float64).reshape(-1, 4)
        if not len(sheets):
            return []
        x0, y0, x1, y1 = sheets.T
        sw = self.fmt(self.width(Pen(SHEET_COLOR, "SHEETS", 8, 0.3)))
        rect = f'<rect x="%s" y="%s" width="%s" height="%s" stroke="{SHEET_COLOR}"/>'
        columns = (
            self.x(x0),
            self.y(y1),
            _format_all((x1 - x0) * self.k, self.decimals),
            _format_all((y1 - y0) * self.k, self.decimals),
        )
        return [
            f'<g id="sheets" stroke="{SHEET_COLOR}" stroke-width="{sw}" fill="none">',
            _rows(rect, columns),
            "</g>",
        ]


def _rows(template: str, columns) -> str:
    """``template`` (``%s`` slots, one per column) filled with each row of ``columns`` (lists
    of texts of one length), one line per row."""
    n = len(columns[0])
    return "\n".join([template] * n) % tuple(
        itertools.chain.from_iterable(zip(*columns, strict=True))
    )


def _label_group(pattern, draw: _Drawing, color: str) -> list[str]:
    """The ``labels`` group: filled text, centred on each anchor, rotated (empty when none),
    in one ``<g class="KIND" font-size="SIZE">`` per run of labels of one kind and size."""
    labels = pattern.annotations.labels
    if not labels:
        return []
    out = [
        f'<g id="labels" font-family="sans-serif" fill="{color}" stroke="none" '
        'text-anchor="middle" dominant-baseline="central">'
    ]
    rows = LabelRows.of(labels)
    tx = draw.x(rows.position[:, 0])
    ty = draw.y(rows.position[:, 1])
    size = _format_all(rows.height * draw.k, draw.decimals)
    turned = np.flatnonzero(rows.angle != 0)
    rot = [""] * len(rows)
    turns = _format_all(-rows.angle[turned], _ANGLE_DECIMALS)
    for i, r in zip(turned.tolist(), turns, strict=True):
        rot[i] = f' transform="rotate({r} {tx[i]} {ty[i]})"'
    kinds = list(map(str, rows.kind))
    texts = list(map(str, rows.text))
    escaped = {t: escape(t) for t in {*kinds, *texts}}
    # a run of labels of one kind and size shares one group: its class and font size are
    # written once, not on each of the tens of thousands of labels of a large design
    style = list(zip(kinds, size, strict=True))
    starts = [i for i in range(len(style)) if i == 0 or style[i] != style[i - 1]]
    for lo, hi in zip(starts, [*starts[1:], len(style)], strict=True):
        k, h = style[lo]
        out.append(f'<g class="{escaped[k]}" font-size="{h}">')
        out.extend(
            f'<text x="{tx[i]}" y="{ty[i]}"{rot[i]}>{escaped[texts[i]]}</text>'
            for i in range(lo, hi)
        )
        out.append("</g>")
    out.append("</g>")
    return out
