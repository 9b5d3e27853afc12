"""PNG pictures of a design: the flat layout and a shaded view of the folded form.

Both are drawn with matplotlib's Agg renderer on a bare :class:`~matplotlib.figure.Figure` (no
pyplot, no display). Patch fills: cone orange, cylinder blue, flat face green (light tints in the
layout, shaded in the preview); creases mountain red, valley blue, borders black; tabs light
grey with a black outline and a green dashed hinge; sheets grey outlines; labels dark grey.
"""

from __future__ import annotations

import io
import math

import numpy as np

from ..errors import ParameterError
from ..surface.pattern import CreasePattern
from ..surface.validate import validate_pattern
from .palette import LABEL_COLOR, SHEET_COLOR, TAB_HINGE_COLOR
from .paths import edge_chains, edge_layer_masks, pattern_extent, tab_cut_paths

__all__ = ["LAYOUT_FILL", "PATCH_COLOR", "pattern_png", "preview_png"]

#: Base colour (RGB, 0..1) of each patch kind in the folded preview.
PATCH_COLOR = {
    "cone": (0.96, 0.62, 0.25),
    "cylinder": (0.35, 0.6, 0.9),
    "fillet": (0.24, 0.78, 0.78),
    "face": (0.45, 0.78, 0.45),
}
#: Light fill of each patch kind in the flat layout.
LAYOUT_FILL = {"cone": "#ffd8a8", "cylinder": "#cfe2ff", "fillet": "#c5f6f6", "face": "#d3f9d8"}
_OTHER_FILL = "#eeeeee"
_TAB_FILL = "#d9d9d9"
#: Crease colours of both pictures: a shade darker than the cut files' (thin lines on tints).
_EDGE_COLOR = {"CUT": "#000000", "MOUNTAIN": "#e00000", "VALLEY": "#0000e0"}
_DPI = 100.0
_PAD = 0.03


def _check_pixels(value, name: str) -> int:
    if (
        isinstance(value, bool)
        or not isinstance(value, int | np.integer)
        or not 16 <= value <= 20000
    ):
        raise ParameterError(f"{name} must be an integer in 16..20000, got {value!r}", name=name)
    return int(value)


def _kind(patch: str) -> str:
    return patch.split(" ")[0] if patch else ""


def _render(fig) -> bytes:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=_DPI, metadata={"Software": None})
    return buf.getvalue()


def pattern_png(pattern: CreasePattern, *, width_px: int = 1600) -> bytes:
    """A picture of the flat layout.

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`.
    width_px : int
        Image width in pixels; the height follows the layout's aspect ratio (kept between a
        quarter and four times the width).

    Returns
    -------
    bytes
        PNG image, white background, equal scale in x and y.

    Raises
    ------
    ParameterError
        For a width outside 16..20000.
    ExportError
        When the pattern is inconsistent.
    """
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.figure import Figure

    width_px = _check_pixels(width_px, "width_px")
    validate_pattern(pattern)
    lo, hi = pattern_extent(pattern)
    size = np.maximum(hi - lo, 1e-9)
    pad = _PAD * float(size.max())
    lo, hi, size = lo - pad, hi + pad, size + 2 * pad
    height_px = round(width_px * min(max(float(size[1] / size[0]), 0.25), 4.0))
    # equal scale: widen the shorter range to the image's aspect ratio
    centre = 0.5 * (lo + hi)
    half = 0.5 * max(size[0], size[1] * width_px / height_px) * np.array([1, height_px / width_px])
    fig = Figure(figsize=(width_px / _DPI, height_px / _DPI), dpi=_DPI, facecolor="white")
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
    ax.set_ylim(centre[1] - half[1], centre[1] + half[1])
    ax.set_axis_off()
    lw = max(0.4, width_px / 1600.0)

    v = pattern.vertices_2d
    ann = pattern.annotations
    sheets = np.asarray(ann.sheets, dtype=np.float64).reshape(-1, 4)
    if len(sheets):
        ax.add_collection(
            LineCollection(
                [[(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)] for x0, y0, x1, y1 in sheets],
                colors=SHEET_COLOR,
                linewidths=0.8 * lw,
            )
        )
    if ann.tabs:
        ax.add_collection(
            PolyCollection(
                [np.asarray(t, dtype=np.float64).reshape(-1, 2) for t in ann.tabs],
                facecolors=_TAB_FILL,
                edgecolors="none",
            )
        )
    fills = [LAYOUT_FILL.get(_kind(p), _OTHER_FILL) for p in pattern.face_patch]
    if pattern.faces:
        ax.add_collection(
            PolyCollection(
                [v[np.asarray(f)] for f in pattern.faces],
                facecolors=fills,
                edgecolors=fills,
                linewidths=0.3 * lw,
            )
        )
    for layer, mask in edge_layer_masks(pattern).items():
        lines = []
        for chain, closed in edge_chains(pattern.edges, mask):
            p = v[chain]
            lines.append(np.vstack([p, p[:1]]) if closed else p)
        if lines:
            ax.add_collection(LineCollection(lines, colors=_EDGE_COLOR[layer], linewidths=lw))
    cuts = [np.vstack([p, p[:1]]) if closed else p for p, closed in tab_cut_paths(ann)]
    if cuts:
        ax.add_collection(LineCollection(cuts, colors="#000000", linewidths=lw))
    if ann.tab_hinges:
        hinges = [np.asarray(h, dtype=np.float64).reshape(2, 2) for h in ann.tab_hinges]
        ax.add_collection(
            LineCollection(hinges, colors=TAB_HINGE_COLOR, linewidths=lw, linestyles=(0, (4, 3)))
        )
    units_per_px = 2 * half[0] / width_px
    for lb in ann.labels:
        pt = float(lb.height) / units_per_px * 72.0 / _DPI / 0.72
        if pt < 2.0:
            continue
        ax.text(
            *np.asarray(lb.position, dtype=np.float64).reshape(2),
            str(lb.text),
            rotation=float(lb.angle),
            rotation_mode="anchor",
            ha="center",
            va="center",
            fontsize=pt,
            color=LABEL_COLOR,
        )
    return _render(fig)


def preview_png(
    pattern: CreasePattern,
    *,
    width_px: int = 1200,
    elev: float = 25.0,
    azim: float = -60.0,
) -> bytes:
    """A shaded picture of the folded form.

    Each face is flat-shaded by the angle between its normal and a light above and to the left
    of the viewer (two-sided, with ambient light), in its patch's colour. Creases are drawn in
    3D where at least one face beside them faces the viewer (exact for convex forms).

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`.
    width_px : int
        Image width in pixels (the height is three quarters of it).
    elev, azim : float
        Viewing elevation and azimuth in degrees (matplotlib's convention).

    Returns
    -------
    bytes
        PNG image, white background, equal scale on the three axes, no axes drawn.

    Raises
    ------
    ParameterError
        For a width outside 16..20000 or a non-finite angle.
    ExportError
        When the pattern is inconsistent.
    """
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    width_px = _check_pixels(width_px, "width_px")
    for name, value in (("elev", elev), ("azim", azim)):
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
        ):
            raise ParameterError(f"{name} must be a finite number of degrees", name=name)
    validate_pattern(pattern)
    height_px = round(0.75 * width_px)
    fig = Figure(figsize=(width_px / _DPI, height_px / _DPI), dpi=_DPI, facecolor="white")
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0), projection="3d", proj_type="ortho")
    ax.set_axis_off()
    ax.view_init(elev=elev, azim=azim)
    ax.computed_zorder = False  # faces below, visible creases on top
    v3 = pattern.vertices_3d

    e, a = math.radians(elev), math.radians(azim)
    view = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
    up = np.array([-math.sin(e) * math.cos(a), -math.sin(e) * math.sin(a), math.cos(e)])
    left = np.cross(view, up)
    light = view + 0.6 * up + 0.4 * left
    light /= np.linalg.norm(light)

    if pattern.faces:
        normal = pattern.face_normal_3d()
        normal = np.nan_to_num(normal)
        shade = 0.35 + 0.65 * np.abs(normal @ light)
        base = np.array([PATCH_COLOR.get(_kind(p), (0.8, 0.8, 0.8)) for p in pattern.face_patch])
        colors = np.clip(base * shade[:, None], 0.0, 1.0)
        facing = normal @ view > 0
        # back faces first, front faces over them: exact for convex forms, where front faces
        # never overlap in the picture
        for sel, z in ((~facing, 0), (facing, 1)):
            idx = np.flatnonzero(sel)
            if len(idx):
                polys = Poly3DCollection(
                    [v3[np.asarray(pattern.faces[i])] for i in idx],
                    facecolors=colors[idx],
                    edgecolors=colors[idx],
                    linewidths=0.2,
                    zorder=z,
                )
                ax.add_collection3d(polys)
    else:
        facing = np.zeros(0, dtype=bool)

    ef = pattern.edge_faces
    if ef is None:
        visible = np.ones(len(pattern.edges), dtype=bool)
    else:
        ef = np.asarray(ef)
        visible = np.zeros(len(ef), dtype=bool)
        for side in (0, 1):
            f = ef[:, side]
            ok = f >= 0
            visible[ok] |= facing[f[ok]]
    lw = max(0.5, width_px / 1200.0)
    assign = np.asarray(pattern.edge_assignment)
    for code, color, width in (
        ("B", _EDGE_COLOR["CUT"], 0.7 * lw),
        ("V", _EDGE_COLOR["VALLEY"], lw),
        ("M", _EDGE_COLOR["MOUNTAIN"], lw),
    ):
        sel = (assign == code) & visible
        if sel.any():
            segs = v3[pattern.edges[sel]]
            lc = Line3DCollection(segs, colors=color, linewidths=width, zorder=3)
            ax.add_collection3d(lc)

    if len(v3):
        lo, hi = v3.min(axis=0), v3.max(axis=0)
    else:
        lo, hi = np.zeros(3), np.ones(3)
    span = np.maximum(hi - lo, 1e-3 * max(float((hi - lo).max()), 1e-9))
    mid = 0.5 * (lo + hi)
    ax.set_xlim(mid[0] - span[0] / 2, mid[0] + span[0] / 2)
    ax.set_ylim(mid[1] - span[1] / 2, mid[1] + span[1] / 2)
    ax.set_zlim(mid[2] - span[2] / 2, mid[2] + span[2] / 2)
    ax.set_box_aspect(tuple(span), zoom=1.2)
    # mplot3d's projection (a BLAS dot of finite data) now and then reports a spurious float
    # overflow; the picture is unaffected
    with np.errstate(over="ignore"):
        return _render(fig)
