"""The output files of a design, by format: the one place that builds them.

Formats and their files:

=============  ===============================  =================================================
format         files                            content
=============  ===============================  =================================================
``fold``       ``design.fold``,                 FOLD 1.2: crease pattern + folded form; the
               ``annotations.json``             tabs, labels and sheets beside it
``simulator``  ``simulator.fold``,              FOLD 1.2 for Origami Simulator: the pattern
               ``simulator.svg``                coarsened and triangulated (see
                                                :mod:`~filletfold.surface.coarse`), and the
                                                same in the simulator's SVG colours
``json``       ``report.json``                  the design report (needs the design, not only
                                                the pattern)
``obj``        ``folded.obj``                   the folded form
``svg``        ``pattern.svg``                  the flat layout (by default Origami Simulator's
                                                colours; see ``preset``)
``dxf``        ``pattern.dxf``                  cut file, by default layers CUT/MOUNTAIN/VALLEY/
                                                TAB/LABEL (see ``preset``)
``pdf``        ``pattern.pdf``                  true-scale print, tiled on pages
``png``        ``pattern.png``, ``preview.png`` pictures of the layout and the folded form
``3dm``        ``pattern.3dm``, ``folded.3dm``  Rhino files of the pattern (layers CUT/MOUNTAIN/
                                                VALLEY/TAB/LABEL) and of the folded form (a mesh
                                                per patch, creases as curves); needs rhino3dm
``glb``        ``folded.glb``                   glTF binary of the folded form, a material per
                                                patch kind (``gltf`` is the same format)
``ply``        ``folded.ply``                   the folded form, welded triangles, face colours
``stl``        ``folded.stl``                   the folded form, welded triangles
=============  ===============================  =================================================

``all`` means every format whose library is installed: ``3dm`` only when rhino3dm imports
(:data:`OPTIONAL_FORMATS`; a warning says when it is left out), while asking for ``3dm`` without
it is an error.

Real size: ``scale`` drawing units per pattern length unit, in ``units``. DXF and SVG are
drawn at ``scale`` (the SVG printed in ``units``; unitless, its larger side is 200 mm). The PDF
needs a physical size: with ``units`` it prints at ``scale`` ``units`` per pattern unit; without
``units`` but with a ``scale`` it reads the scaled drawing in millimetres; with neither, it
scales the drawing to fill one page (:func:`fit_page_scale`). FOLD, OBJ and PNG keep the
design's own coordinates. A cutter ``preset`` (:mod:`~filletfold.export.presets`) sets the
colours, layers, line widths and dash or perforation of the SVG and DXF.

Both 3dm files are drawn at ``scale`` in ``units`` (the folded form too, so the two overlay at
one size). PLY and STL are scaled by ``scale`` too (the PLY names ``units`` in a comment), and
the GLB, whose unit is the metre, by ``scale`` and the unit in metres
(:func:`~filletfold.export.mesh3d.length_factor`); OBJ keeps the design's own coordinates.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib.util
import logging
import sys
from collections.abc import Iterable, Mapping

import numpy as np

from ..errors import ParameterError
from ..surface.pattern import Annotations, CreasePattern, LabelRows, PointRows
from ..surface.validate import validated_faces
from ..units import check_units, sheet_size_mm
from .dxf import check_scale, pattern_dxf
from .fold import (
    ANNOTATIONS_FILE,
    FOLD_DIGITS,
    _fold_document,
    annotations_json,
    fold_json_chunks,
)
from .obj import _folded_obj
from .paths import pattern_extent
from .pdf import REGION_PAD_MM, pattern_pdf
from .png import parse_view, pattern_png, preview_png
from .presets import Preset, get_preset
from .svg import _pattern_svg_chunks

__all__ = [
    "ALL_FORMATS",
    "DEFAULT_FORMATS",
    "FORMAT_ALIASES",
    "FORMAT_FILES",
    "OPTIONAL_FORMATS",
    "cut_files",
    "fit_page_scale",
    "output_names",
    "parse_formats",
    "scaled_pattern",
]

#: Files written for each format, in writing order.
FORMAT_FILES = {
    "fold": ("design.fold", "annotations.json"),
    "simulator": ("simulator.fold", "simulator.svg"),
    "json": ("report.json",),
    "obj": ("folded.obj",),
    "svg": ("pattern.svg",),
    "dxf": ("pattern.dxf",),
    "pdf": ("pattern.pdf",),
    "png": ("pattern.png", "preview.png"),
    "3dm": ("pattern.3dm", "folded.3dm"),
    "glb": ("folded.glb",),
    "ply": ("folded.ply",),
    "stl": ("folded.stl",),
}
#: Other names of formats.
FORMAT_ALIASES = {"gltf": "glb"}
#: Formats that need an optional library: format -> (module, the extra that installs it).
OPTIONAL_FORMATS = {"3dm": ("rhino3dm", "rhino")}
#: Every format, in canonical order (what ``"all"`` means, less the optional formats whose
#: library is not installed).
ALL_FORMATS = tuple(FORMAT_FILES)
#: What ``filletfold round`` and :meth:`Design.export` write by default.
DEFAULT_FORMATS = ("fold", "json", "obj", "svg")

_log = logging.getLogger(__name__)


def _installed(fmt: str) -> bool:
    """Whether the library of an optional format can be imported (without importing it)."""
    module = OPTIONAL_FORMATS[fmt][0]
    if module in sys.modules:  # imported already, or blocked (None)
        return sys.modules[module] is not None
    return importlib.util.find_spec(module) is not None


def parse_formats(formats: str | Iterable[str]) -> tuple[str, ...]:
    """Normalise a format list: ``"dxf,pdf"``, ``["svg", "png"]`` or ``"all"``.

    Parameters
    ----------
    formats : str or iterable of str
        Comma-separated names (spaces and case ignored) or a sequence of names; ``"all"``
        stands for every format.

    Returns
    -------
    tuple of str
        Distinct formats in the canonical order of :data:`ALL_FORMATS`.

    Raises
    ------
    ParameterError
        For an unknown format, an empty list, or an optional format (:data:`OPTIONAL_FORMATS`)
        named whose library is not installed. ``"all"`` leaves such a format out, with a
        warning.
    """
    if isinstance(formats, str):
        items = formats.split(",")
    else:
        try:
            items = list(formats)
        except TypeError:
            raise ParameterError(
                f"formats must be a string or a list of strings, got {type(formats).__name__}",
                name="format",
            ) from None
    names = set()
    for item in items:
        if not isinstance(item, str):
            raise ParameterError(f"format names must be strings, got {item!r}", name="format")
        name = item.strip().lower()
        name = FORMAT_ALIASES.get(name, name)
        if not name:
            continue
        if name == "all":
            missing = [f for f in OPTIONAL_FORMATS if not _installed(f)]
            for f in missing:
                module, extra = OPTIONAL_FORMATS[f]
                _log.warning(
                    "format %s left out of 'all': %s is not installed "
                    "(pip install 'filletfold[%s]')",
                    f,
                    module,
                    extra,
                )
            names.update(f for f in ALL_FORMATS if f not in missing)
        elif name in FORMAT_FILES:
            if name in OPTIONAL_FORMATS and not _installed(name):
                module, extra = OPTIONAL_FORMATS[name]
                raise ParameterError(
                    f"format {name} needs {module}: pip install 'filletfold[{extra}]'",
                    name="format",
                )
            names.add(name)
        else:
            raise ParameterError(
                f"unknown format {item.strip()!r}: choose from {', '.join(ALL_FORMATS)} or all",
                name="format",
            )
    if not names:
        raise ParameterError("no output format given", name="format")
    return tuple(f for f in ALL_FORMATS if f in names)


def output_names(formats: Iterable[str]) -> tuple[str, ...]:
    """The file names written for already-parsed ``formats``, in writing order."""
    return tuple(name for f in formats for name in FORMAT_FILES[f])


def _scaled_rows(rows, scale: float):
    """Tab outlines or hinges times ``scale``: a :class:`PointRows` as one, else a list."""
    if isinstance(rows, PointRows):
        return PointRows(rows.points * scale, rows.start)
    return [np.asarray(r, dtype=np.float64) * scale for r in rows]


def scaled_pattern(pattern: CreasePattern, scale: float) -> CreasePattern:
    """A copy of ``pattern`` whose flat layout and annotations are multiplied by ``scale``.

    The folded (3D) positions, faces and edge data are shared with ``pattern``.

    Parameters
    ----------
    pattern : CreasePattern
    scale : float
        Positive.

    Returns
    -------
    CreasePattern
    """
    scale = check_scale(scale)
    if scale == 1.0:
        return pattern
    ann = pattern.annotations
    labels = LabelRows.of(ann.labels)
    return dataclasses.replace(
        pattern,
        vertices_2d=pattern.vertices_2d * scale,
        annotations=Annotations(
            tabs=_scaled_rows(ann.tabs, scale),
            tab_hinges=_scaled_rows(ann.tab_hinges, scale),
            labels=LabelRows(
                labels.position * scale,
                labels.text,
                labels.angle,
                labels.height * scale,
                labels.kind,
            ),
            sheets=np.asarray(ann.sheets, dtype=np.float64) * scale,
            seams=ann.seams,
            making=[dataclasses.replace(m, points=m.points * scale) for m in ann.making],
        ),
    )


def fit_page_scale(pattern: CreasePattern, page: str = "A4", margin_mm: float = 10.0) -> float:
    """Millimetres per pattern unit that print the whole drawing on one page.

    Parameters
    ----------
    pattern : CreasePattern
    page : str
        See :func:`~filletfold.units.sheet_size_mm`.
    margin_mm : float
        The page margin of :func:`~filletfold.export.pdf.pattern_pdf`.

    Returns
    -------
    float
        The largest round-down scale (3 significant digits) at which the drawing, its tabs,
        labels and the region padding fit the printable area (with sheets: the largest sheet).
    """
    width, height = sheet_size_mm(page, name="page")
    room = np.array([width, height]) - 2 * margin_mm - 2 * REGION_PAD_MM
    sheets = np.asarray(pattern.annotations.sheets, dtype=np.float64).reshape(-1, 4)
    if len(sheets):
        size = (sheets[:, 2:] - sheets[:, :2]).max(axis=0)
    else:
        lo, hi = pattern_extent(pattern)
        size = hi - lo
    k = float(np.min(room / np.maximum(size, 1e-12)))
    if not k > 0:
        raise ParameterError(f"page {page!r} has no room for the drawing", name="page")
    digits = 2 - int(np.floor(np.log10(k)))
    return float(np.floor(k * 10.0**digits) / 10.0**digits)


def cut_files(
    pattern: CreasePattern,
    formats: str | Iterable[str] = DEFAULT_FORMATS,
    *,
    units: str = "",
    scale: float | None = None,
    page: str = "A4",
    title: str = "",
    description: str = "",
    report: Mapping | str | None = None,
    lazy: bool = False,
    preset: str | Preset | None = None,
    view=None,
    fold_extra: Mapping | None = None,
) -> dict:
    """Build the output files of ``formats`` for a crease pattern (nothing is written).

    Parameters
    ----------
    pattern : CreasePattern
    formats : str or iterable of str
        See :func:`parse_formats` and the module docstring.
    units : str
        ``""``, ``"mm"``, ``"cm"``, ``"m"`` or ``"in"``: the drawing unit of DXF, SVG, PDF,
        3DM, PLY and STL (the GLB is in metres).
    scale : float, optional
        Drawing units per pattern unit (default 1; see the module docstring for the PDF).
    page : str
        PDF page size (see :func:`~filletfold.units.sheet_size_mm`).
    title, description : str
        FOLD ``file_title`` and ``file_description``.
    report : mapping or str, optional
        The ``report.json`` content (a dict, or its text); required for the ``json`` format.
    view : str or (2,) float, optional
        The direction ``preview.png`` is seen from: ``front`` (the default), ``back``, ``top``,
        ``side`` or ``"AZIMUTH,ELEVATION"`` in degrees, optionally followed by ``",y"`` for a
        model whose up is +y (:func:`~filletfold.export.png.parse_view`).
    lazy : bool
        Return, for each file, a function without arguments that builds its contents (for
        :func:`~filletfold.export.atomic.write_outputs`, which then holds one file in memory
        at a time; the FOLD and SVG files' are iterators of text chunks, written as they
        come, so not even a whole file is); the pattern is still checked here, once.
    preset : str or Preset, optional
        Cutter preset of the SVG and DXF (:data:`~filletfold.export.presets.PRESETS`; default
        ``print``).
    fold_extra : mapping, optional
        More namespaced top-level keys of ``design.fold`` (``filletfold round`` adds the mesh's
        per-element data, :func:`~filletfold.export.outputs.mesh_fold_keys`).

    Returns
    -------
    dict of str to str or bytes (or to callables, with ``lazy``: of those, or of iterators of
    str)
        File name to contents, in the order of :func:`output_names`. Text formats are ``str``,
        PDF, PNG, 3DM, GLB, PLY and STL ``bytes``.

    Raises
    ------
    ParameterError
        For an unknown format, unit, page or preset, a non-positive scale, or ``json`` without
        a report.
    ExportError
        When the pattern is inconsistent.
    """
    formats = parse_formats(formats)
    azim, elev, up = parse_view("front" if view is None else view)
    check_units(units, unitless=True)
    scale_given = scale is not None
    scale = 1.0 if scale is None else check_scale(scale)
    preset = get_preset(preset)
    if "pdf" in formats:
        sheet_size_mm(page, name="page")
    if "json" in formats and report is None:
        raise ParameterError(
            "report.json needs the whole design, not only its crease pattern "
            "(write it with 'filletfold round')",
            name="format",
        )
    faces = validated_faces(pattern)  # checked once here for fold, obj and svg

    from .mesh3d import _folded_glb, _folded_ply, _folded_stl, length_factor
    from .report import report_json

    def fold():
        doc = _fold_document(
            pattern,
            faces,
            title=title,
            description=description,
            extra=fold_extra,
            arrays=True,
            annotations=False,
        )
        return fold_json_chunks(doc)  # written a key at a time (lazy)

    @functools.cache
    def coarse():
        from ..surface.coarse import simulator_pattern

        return simulator_pattern(pattern, digits=FOLD_DIGITS)  # fold angles as the file holds

    def simulator():
        from ..surface.coarse import SIM_MAX_TURN, SIM_MIN_ANGLE

        settings = {"max_turn": SIM_MAX_TURN, "min_angle": SIM_MIN_ANGLE}
        doc = _fold_document(
            coarse(),
            validated_faces(coarse()),
            title=title,
            description=description,
            extra={"filletfold:simulator": settings},
            arrays=True,
            annotations=False,
        )
        return fold_json_chunks(doc)  # written a key at a time (lazy)

    def simulator_svg():
        from ..surface.coarse import simulator_svg_pattern

        drawn = scaled_pattern(simulator_svg_pattern(coarse()), scale)
        return _pattern_svg_chunks(drawn, units=units, preset="origami-simulator")

    def pdf():
        pdf_units, pdf_scale = units or "mm", scale
        if not units and not scale_given:
            pdf_scale = fit_page_scale(pattern, page)
        return pattern_pdf(pattern, page=page, units=pdf_units, scale=pdf_scale)

    def rhino(which):
        def build():
            from . import rhino

            write = rhino.pattern_3dm if which == "pattern" else rhino.folded_3dm
            return write(pattern, units=units, scale=scale)

        return build

    builders = {
        "fold": {"design.fold": fold, ANNOTATIONS_FILE: lambda: annotations_json(pattern)},
        "simulator": {"simulator.fold": simulator, "simulator.svg": simulator_svg},
        "json": {"report.json": lambda: report if isinstance(report, str) else report_json(report)},
        "obj": {"folded.obj": lambda: _folded_obj(pattern, faces)},
        "svg": {
            "pattern.svg": lambda: _pattern_svg_chunks(  # written a group at a time (lazy)
                scaled_pattern(pattern, scale), units=units, preset=preset
            )
        },
        "dxf": {
            "pattern.dxf": lambda: pattern_dxf(pattern, units=units, scale=scale, preset=preset)
        },
        "pdf": {"pattern.pdf": pdf},
        "png": {
            "pattern.png": lambda: pattern_png(pattern),
            "preview.png": lambda: preview_png(pattern, azim=azim, elev=elev, up=up),
        },
        "3dm": {"pattern.3dm": rhino("pattern"), "folded.3dm": rhino("folded")},
        "glb": {"folded.glb": lambda: _folded_glb(pattern, length_factor(units, scale, gltf=True))},
        "ply": {"folded.ply": lambda: _folded_ply(pattern, units, length_factor(units, scale))},
        "stl": {"folded.stl": lambda: _folded_stl(pattern, length_factor(units, scale))},
    }
    out = {name: build for fmt in formats for name, build in builders[fmt].items()}
    if lazy:
        return out
    return {name: _whole(build()) for name, build in out.items()}


def _whole(data):
    """The contents of one file: text made in chunks joined."""
    return data if isinstance(data, str | bytes) else "".join(data)
