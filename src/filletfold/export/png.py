"""PNG pictures of a design: the flat layout and a shaded view of the folded form.

The layout is drawn with matplotlib's Agg renderer on a bare :class:`~matplotlib.figure.Figure`
(no pyplot, no display); the folded form by the z-buffer of :mod:`filletfold.export.render`,
with hidden surfaces and hidden lines removed. Patch fills: cone orange, cylinder blue, conical
fillet teal, flat face green (light tints in the layout, shaded in the preview); creases
mountain red, valley blue, borders black (seams between pieces grey in the preview); tabs light
grey with a black outline and a green dashed hinge; sheets grey outlines; labels dark grey.
"""

from __future__ import annotations

import io
import math

import numpy as np

from ..errors import ParameterError
from ..surface.patch import patch_kind
from ..surface.pattern import CreasePattern
from ..surface.triangulate import triangulate_faces
from ..surface.validate import validate_pattern
from .palette import KERF_COLOR, LABEL_COLOR, PATCH_COLOR, SHEET_COLOR, TAB_HINGE_COLOR
from .paths import edge_chains, edge_layer_masks, pattern_extent, tab_cut_paths

__all__ = [
    "DEFAULT_VIEW",
    "LAYOUT_FILL",
    "PATCH_COLOR",
    "VIEWS",
    "face_shades",
    "parse_view",
    "pattern_png",
    "preview_png",
]

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
    fills = [LAYOUT_FILL.get(patch_kind(p), _OTHER_FILL) for p in pattern.face_patch]
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
    reliefs = [np.asarray(m.points) for m in ann.making if m.kind == "relief"]
    if reliefs:  # cut out: white, outlined as cuts
        ax.add_collection(
            PolyCollection(reliefs, facecolors="#ffffff", edgecolors="#000000", linewidths=lw)
        )
    for kind, color in KERF_COLOR.items():
        grooves = [np.asarray(m.points) for m in ann.making if m.kind == kind]
        if grooves:
            ax.add_collection(LineCollection(grooves, colors=color, linewidths=lw))
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


#: Default view of the folded preview: azimuth and elevation in degrees (matplotlib's
#: convention: the eye at azimuth 0 is on +x, at 90 on +y; elevation 90 looks down from +z).
DEFAULT_VIEW = (-60.0, 25.0)
#: Named views of :func:`preview_png` (azimuth, elevation): ``back`` is the default turned
#: half round, ``top`` looks down, ``side`` along +y.
VIEWS = {"front": DEFAULT_VIEW, "back": (120.0, 25.0), "top": (-90.0, 90.0), "side": (-90.0, 0.0)}
#: Shading: ambient + key * |n . light| + headlight * |n . eye| (a light at the eye).
_AMBIENT, _KEY, _HEAD = 0.3, 0.5, 0.2
_BACK_SIDE = 0.8  # the back of a face (seen through a hole, or inside an open shell) darker
_SEAM_COLOR = "#606060"


def parse_view(view, up: str = "z") -> tuple[float, float, str]:
    """Azimuth, elevation (degrees) and up axis of a view.

    Parameters
    ----------
    view : str or sequence
        ``"NAME"`` (one of :data:`VIEWS`) or ``"AZIMUTH,ELEVATION"``, either followed by
        ``",x"``, ``",y"`` or ``",z"`` (the axis up in the picture, default z: see
        :func:`~filletfold.export.render.view_frame`); or a sequence ``(azim, elev)`` or
        ``(azim, elev, up)``.
    up : str
        The up axis of a view that names none (a design's ``up``).

    Raises
    ------
    ParameterError
        For anything else, naming ``view``.
    """
    if isinstance(view, str):
        parts = [p.strip().lower() for p in view.split(",")]
    elif isinstance(view, list | tuple):
        parts = [p.strip().lower() if isinstance(p, str) else p for p in view]
    else:
        parts = []
    if len(parts) in (2, 3) and parts[-1] in ("x", "y", "z"):
        up = parts.pop()
    values: tuple = ()
    if len(parts) == 1 and parts[0] in VIEWS:
        values = VIEWS[parts[0]]
    elif len(parts) == 2:
        try:
            values = tuple(float(p) for p in parts)
        except (TypeError, ValueError):
            values = ()
    if len(values) != 2 or not all(math.isfinite(v) for v in values):
        raise ParameterError(
            f"view must be {', '.join(VIEWS)} or 'AZIMUTH,ELEVATION' in degrees, optionally "
            f"followed by ',y' or ',x' (the axis up in the picture), got {view!r}",
            name="view",
        )
    return float(values[0]), float(values[1]), up


def _rgb(hex_color: str) -> tuple[float, float, float]:
    h = hex_color.lstrip("#")
    return tuple(int(h[i : i + 2], 16) / 255.0 for i in (0, 2, 4))


def face_shades(pattern: CreasePattern, azim: float, elev: float, up: str = "z") -> np.ndarray:
    """(n_faces,) brightness of each face of the folded form seen from a view (the
    ``preview.png`` shading): ambient, plus a light above and to the left of the viewer and
    one at the viewer, two-sided, the back of a face darker."""
    from .render import view_frame

    right, upward, eye = view_frame(azim, elev, up)
    light = eye + 0.6 * upward - 0.4 * right
    light /= np.linalg.norm(light)
    normal = np.nan_to_num(pattern.face_normal_3d())
    facing = normal @ eye
    shade = _AMBIENT + _KEY * np.abs(normal @ light) + _HEAD * np.abs(facing)
    return np.where(facing < 0.0, _BACK_SIDE * shade, shade)


def preview_png(
    pattern: CreasePattern,
    *,
    width_px: int = 1000,
    elev: float = DEFAULT_VIEW[1],
    azim: float = DEFAULT_VIEW[0],
    up: str = "z",
) -> bytes:
    """A shaded picture of the folded form, hidden surfaces and hidden lines removed.

    Drawn by :func:`filletfold.export.render.render` (a numpy z-buffer, supersampled twice):
    each face in its patch's colour (:data:`~filletfold.export.palette.PATCH_COLOR`),
    flat-shaded by the angle between its normal and a light above and to the left of the viewer
    and one at the viewer (two-sided, with ambient light; the back of a face is darker); over
    them the visible creases (mountain red, valley blue), the sheet's outline (black) and the
    seams between pieces (grey, thinner).

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`.
    width_px : int
        Image width in pixels (the height is three quarters of it).
    elev, azim : float
        Viewing elevation and azimuth in degrees (matplotlib's convention; default
        :data:`DEFAULT_VIEW`, :data:`VIEWS` has named ones).
    up : {"z", "y", "x"}
        The axis up in the picture (:func:`~filletfold.export.render.view_frame`).

    Returns
    -------
    bytes
        PNG image, white background, orthographic, fitted to the form; the same pattern and
        view give the same bytes.

    Raises
    ------
    ParameterError
        For a width outside 16..20000, a non-finite angle or another up axis.
    ExportError
        When the pattern is inconsistent.
    """
    from .render import png_bytes, render

    width_px = _check_pixels(width_px, "width_px")
    for name, value in (("elev", elev), ("azim", azim)):
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float | np.floating | np.integer)
            or not math.isfinite(value)
        ):
            raise ParameterError(f"{name} must be a finite number of degrees", name=name)
    if up not in ("x", "y", "z"):
        raise ParameterError(f"up must be 'x', 'y' or 'z', got {up!r}", name="up")
    validate_pattern(pattern)
    height_px = round(0.75 * width_px)
    triangles, tri_face = triangulate_faces(pattern.vertices_2d, pattern.faces)
    if len(pattern.face_patch):
        color_of = {
            p: PATCH_COLOR.get(patch_kind(p), (0.8, 0.8, 0.8)) for p in set(pattern.face_patch)
        }
        base = np.array([color_of[p] for p in pattern.face_patch], dtype=np.float64)
        shade = face_shades(pattern, float(azim), float(elev), up)
        face_color = np.clip(base * shade[:, None], 0.0, 1.0)
    else:
        face_color = np.zeros((0, 3))
    colors = face_color[tri_face]

    v3 = pattern.vertices_3d
    assign = np.asarray(pattern.edge_assignment)
    edge_faces = None if pattern.edge_faces is None else np.asarray(pattern.edge_faces)
    seam = pattern.cut_mask() if len(assign) else np.zeros(0, dtype=bool)
    lw = max(1.0, width_px / 800.0)
    lines = []
    for sel, color, width in (
        (seam, _SEAM_COLOR, 0.7 * lw),
        ((assign == "B") & ~seam, _EDGE_COLOR["CUT"], lw),
        (assign == "V", _EDGE_COLOR["VALLEY"], lw),
        (assign == "M", _EDGE_COLOR["MOUNTAIN"], lw),
    ):
        faces = None if edge_faces is None else edge_faces[sel]
        lines.append((v3[pattern.edges[sel]], faces, _rgb(color), width))
    image = render(
        v3,
        triangles,
        colors,
        triangle_face=tri_face,
        lines=lines,
        width=width_px,
        height=height_px,
        azim=float(azim),
        elev=float(elev),
        up=up,
    )
    return png_bytes(image)
