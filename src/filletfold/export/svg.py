"""SVG drawing of the flat crease pattern, to print, cut, or load into Origami Simulator.

Each edge is a ``<line>`` carrying its own ``stroke`` colour, in one group per assignment:
mountain ``#ff0000``, valley ``#0000ff``, border/cut ``#000000`` (the colours Origami Simulator
reads) and, optionally, flat ``#dddddd``. The y axis is flipped so the drawing is not mirrored.
The scale bar and legend below the drawing are filled shapes without stroke and text, in a
separate ``annotation`` group, so stroke-colour readers (Origami Simulator, laser software)
ignore them.

A pattern's annotations are drawn when present: the cut part of each glue-tab outline black
(group ``tab-cut``), the tab hinges green ``#00a000`` dashed (``tab-hinge``; not Origami
Simulator's cut green ``#00ff00``), the sheet outlines thin grey ``#999999`` (``sheets``) and
the labels as filled text, rotated, in the ``annotation`` group (``labels``).
"""

from __future__ import annotations

import itertools
import math
from xml.sax.saxutils import escape

import numpy as np

from ..errors import ParameterError
from ..surface.pattern import CreasePattern
from ..surface.validate import validate_pattern
from ..units import MM_PER_UNIT, check_units
from .palette import ASSIGNMENT_COLOR, LABEL_COLOR, SHEET_COLOR, TAB_HINGE_COLOR
from .paths import label_positions, pattern_extent, tab_cut_paths

__all__ = ["nice_length", "pattern_svg"]

#: Group id and legend label of each edge assignment, in drawing order (bottom first).
_GROUPS = (
    ("F", "flat", "flat"),
    ("B", "border", "border / cut"),
    ("V", "valley", "valley"),
    ("M", "mountain", "mountain"),
)
#: Printed size (mm) of the larger side of the drawing when no unit is given.
_UNITLESS_MM = 200.0
_MARGIN_MM = 10.0
_FONT_MM = 3.5
_SWATCH_MM = 8.0


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
    stroke_mm: float = 0.3,
    flat_edges: bool = False,
    angle_opacity: bool = False,
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
    stroke_mm : float
        Printed line width in millimetres.
    flat_edges : bool
        Also draw ``F`` edges, very light grey, in a ``flat`` group.
    angle_opacity : bool
        Set each mountain and valley line's ``opacity`` to ``|fold angle| / 180``, which Origami
        Simulator reads as the target fold angle.

    Returns
    -------
    str
        The SVG document (UTF-8, ends with a newline). Same input, same bytes.

    Raises
    ------
    ParameterError
        For an unknown ``units`` or a non-positive ``stroke_mm``.
    ExportError
        When the pattern is inconsistent.
    """
    check_units(units, MM_PER_UNIT, unitless=True)
    if not (isinstance(stroke_mm, int | float) and math.isfinite(stroke_mm) and stroke_mm > 0):
        raise ParameterError(
            f"stroke_mm must be a positive number, got {stroke_mm!r}", name="stroke_mm"
        )
    validate_pattern(pattern)
    return _pattern_svg(pattern, units, stroke_mm, flat_edges, angle_opacity)


def _pattern_svg(pattern, units="", stroke_mm=0.3, flat_edges=False, angle_opacity=False) -> str:
    """:func:`pattern_svg` of a pattern and arguments already checked."""
    v = pattern.vertices_2d
    lo, hi = pattern_extent(pattern)
    size = hi - lo
    extent = float(size.max())
    if extent <= 0:
        extent = 1.0
    mm_per_user = MM_PER_UNIT[units] if units else _UNITLESS_MM / extent
    user = 1.0 / mm_per_user  # user units per mm
    margin = _MARGIN_MM * user
    font = _FONT_MM * user
    decimals = max(0, 8 - math.floor(math.log10(extent + 2 * margin)))
    fmt = _formatter(decimals)

    # drawing coordinates: x right, y down, pattern's top-left at (margin, margin)
    x = v[:, 0] - lo[0] + margin
    y = hi[1] - v[:, 1] + margin
    used = np.zeros(len(v), dtype=bool)  # only the ends of edges are drawn
    used[np.asarray(pattern.edges, dtype=np.int64).ravel()] = True
    xs = np.full(len(v), "", dtype=object)
    ys = np.full(len(v), "", dtype=object)
    xs[used] = _format_all(x[used], decimals)
    ys[used] = _format_all(y[used], decimals)

    edges = np.asarray(pattern.edges, dtype=np.int64)
    assign = np.asarray(pattern.edge_assignment)
    angle = np.asarray(pattern.edge_fold_angle, dtype=np.float64)
    sw = fmt(stroke_mm * user)

    body = []
    legend = []
    for code, gid, label in _GROUPS:
        if code == "F" and not flat_edges:
            continue
        color = ASSIGNMENT_COLOR[code]
        legend.append((color, label))
        body.append(f'<g id="{gid}" stroke-width="{sw}" stroke-linecap="round" fill="none">')
        sel = np.flatnonzero(assign == code)
        if len(sel):
            a, b = edges[sel, 0], edges[sel, 1]
            cols = [xs[a], ys[a], xs[b], ys[b]]
            line = f'<line x1="%s" y1="%s" x2="%s" y2="%s" stroke="{color}"/>\n'
            if angle_opacity and code in ("M", "V"):
                line = line[:-3] + ' opacity="%.4f"/>\n'
                cols.append(np.minimum(np.abs(angle[sel]) / 180.0, 1.0))
            values = np.stack(cols, axis=1).ravel().tolist()
            body.append((line * len(sel))[:-1] % tuple(values))
        body.append("</g>")
    body.extend(_annotation_groups(pattern, lo, hi, margin, decimals, sw))

    # scale bar and legend below the drawing
    draw_w = float(size[0]) + 2 * margin
    draw_h = float(size[1]) + 2 * margin
    bar = nice_length(max(float(size[0]), extent * 0.2) / 5.0)
    bar_h = 1.0 * user
    bar_y = draw_h
    label = f"{bar:g} {units}".rstrip()
    ann = ['<g id="annotation" stroke="none">']
    ann.append(
        f'<g id="scale-bar"><rect x="{fmt(margin)}" y="{fmt(bar_y)}" width="{fmt(bar)}" '
        f'height="{fmt(bar_h)}" fill="#000000"/>'
    )
    ann.append(
        f'<text x="{fmt(margin + bar + 2 * user)}" y="{fmt(bar_y + bar_h)}" '
        f'font-family="sans-serif" font-size="{fmt(font)}" fill="#000000">'
        f"{escape(label)}</text></g>"
    )
    leg_y = bar_y + bar_h + 2 * font
    xcur = margin
    ann.append('<g id="legend" font-family="sans-serif" fill="#000000">')
    for color, text in legend:
        ann.append(
            f'<rect x="{fmt(xcur)}" y="{fmt(leg_y - 0.5 * font)}" '
            f'width="{fmt(_SWATCH_MM * user)}" height="{fmt(max(stroke_mm, 0.5) * user)}" '
            f'fill="{color}"/>'
        )
        xcur += (_SWATCH_MM + 2.0) * user
        ann.append(
            f'<text x="{fmt(xcur)}" y="{fmt(leg_y)}" font-size="{fmt(font)}">{escape(text)}</text>'
        )
        xcur += (0.62 * _FONT_MM * len(text) + 6.0) * user
    ann.append("</g>")
    ann.extend(_label_group(pattern, lo, hi, margin, decimals))
    ann.append("</g>")

    total_w = max(
        draw_w, xcur + margin, margin + bar + (2 + 0.62 * _FONT_MM * len(label)) * user + margin
    )
    total_h = leg_y + font + margin
    head = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" '
        f'width="{total_w * mm_per_user:.3f}mm" height="{total_h * mm_per_user:.3f}mm" '
        f'viewBox="0 0 {fmt(total_w)} {fmt(total_h)}">',
        "<title>filletfold crease pattern</title>",
        f"<desc>mountain red, valley blue, cut black; units: {escape(units or 'none')}</desc>",
    ]
    return "\n".join([*head, *body, *ann, "</svg>"]) + "\n"


def _annotation_groups(pattern, lo, hi, margin, decimals, sw) -> list[str]:
    """SVG groups of the sheet outlines, tab cut paths and tab hinges (empty when none), their
    numbers formatted in bulk (:func:`_format_all`)."""
    ann = pattern.annotations
    fmt = _formatter(decimals)

    def x_of(x: np.ndarray) -> list[str]:
        return _format_all(x - lo[0] + margin, decimals)

    def y_of(y: np.ndarray) -> list[str]:
        return _format_all(hi[1] - y + margin, decimals)

    out = []
    sheets = np.asarray(ann.sheets, dtype=np.float64).reshape(-1, 4)
    if len(sheets):
        out.append(f'<g id="sheets" stroke="{SHEET_COLOR}" stroke-width="{sw}" fill="none">')
        x0, y0, x1, y1 = sheets.T
        rect = f'<rect x="%s" y="%s" width="%s" height="%s" stroke="{SHEET_COLOR}"/>'
        columns = (
            x_of(x0),
            y_of(y1),
            _format_all(x1 - x0, decimals),
            _format_all(y1 - y0, decimals),
        )
        out.append(_rows(rect, columns))
        out.append("</g>")
    paths = tab_cut_paths(ann)
    if paths:
        color = ASSIGNMENT_COLOR["B"]
        out.append(
            f'<g id="tab-cut" stroke-width="{sw}" stroke-linecap="round" '
            'stroke-linejoin="round" fill="none">'
        )
        q = np.concatenate([pts for pts, _ in paths])
        shapes = [(closed, len(pts)) for pts, closed in paths]
        template = {
            (closed, k): f'<{"polygon" if closed else "polyline"} points="'
            + " ".join(["%s,%s"] * k)
            + f'" stroke="{color}"/>'
            for closed, k in set(shapes)
        }
        values = tuple(
            itertools.chain.from_iterable(zip(x_of(q[:, 0]), y_of(q[:, 1]), strict=True))
        )
        out.append("\n".join(map(template.__getitem__, shapes)) % values)
        out.append("</g>")
    if len(ann.tab_hinges):
        out.append(
            f'<g id="tab-hinge" stroke-width="{sw}" stroke-dasharray="{fmt(6 * float(sw))} '
            f'{fmt(4 * float(sw))}" fill="none">'
        )
        h = np.array([np.asarray(h, dtype=np.float64).reshape(2, 2) for h in ann.tab_hinges])
        line = f'<line x1="%s" y1="%s" x2="%s" y2="%s" stroke="{TAB_HINGE_COLOR}"/>'
        columns = (x_of(h[:, 0, 0]), y_of(h[:, 0, 1]), x_of(h[:, 1, 0]), y_of(h[:, 1, 1]))
        out.append(_rows(line, columns))
        out.append("</g>")
    return out


def _rows(template: str, columns) -> str:
    """``template`` (``%s`` slots, one per column) filled with each row of ``columns`` (lists
    of texts of one length), one line per row."""
    n = len(columns[0])
    return "\n".join([template] * n) % tuple(
        itertools.chain.from_iterable(zip(*columns, strict=True))
    )


def _label_group(pattern, lo, hi, margin, decimals) -> list[str]:
    """The ``labels`` group: filled text, centred on each anchor, rotated (empty when none)."""
    labels = pattern.annotations.labels
    if not labels:
        return []
    out = [
        f'<g id="labels" font-family="sans-serif" fill="{LABEL_COLOR}" text-anchor="middle" '
        'dominant-baseline="central">'
    ]
    position = label_positions(labels)
    tx = _format_all(position[:, 0] - lo[0] + margin, decimals)
    ty = _format_all(hi[1] - position[:, 1] + margin, decimals)
    size = _format_all(np.array([float(lb.height) for lb in labels], dtype=np.float64), decimals)
    angle = np.array([lb.angle for lb in labels], dtype=object)
    turned = np.flatnonzero(angle.astype(bool))  # the truth of each angle, as it is
    rot = [""] * len(labels)
    turns = _format_all(np.array([-float(a) for a in angle[turned]], dtype=np.float64), decimals)
    for i, r in zip(turned.tolist(), turns, strict=True):
        rot[i] = f' transform="rotate({r} {tx[i]} {ty[i]})"'
    kinds = [str(lb.kind) for lb in labels]
    texts = [str(lb.text) for lb in labels]
    escaped = {t: escape(t) for t in {*kinds, *texts}}
    out.extend(
        f'<text x="{x}" y="{y}" font-size="{h}" class="{escaped[k]}"{r}>{escaped[t]}</text>'
        for x, y, h, k, r, t in zip(tx, ty, size, kinds, rot, texts, strict=True)
    )
    out.append("</g>")
    return out
