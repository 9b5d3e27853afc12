"""The output files of a design, by format: the one place that builds them.

Formats and their files:

=========  ===============================  =================================================
format     files                            content
=========  ===============================  =================================================
``fold``   ``design.fold``                  FOLD 1.2: crease pattern + folded form
``json``   ``report.json``                  the design report (needs the design, not only
                                            the pattern)
``obj``    ``folded.obj``                   the folded form
``svg``    ``pattern.svg``                  the flat layout (Origami Simulator colours)
``dxf``    ``pattern.dxf``                  cut file, layers CUT/MOUNTAIN/VALLEY/TAB/LABEL
``pdf``    ``pattern.pdf``                  true-scale print, tiled on pages
``png``    ``pattern.png``, ``preview.png`` pictures of the layout and the folded form
=========  ===============================  =================================================

Real size: ``scale`` drawing units per pattern length unit, in ``units``. DXF and SVG are
drawn at ``scale`` (the SVG printed in ``units``; unitless, its larger side is 200 mm). The PDF
needs a physical size: with ``units`` it prints at ``scale`` ``units`` per pattern unit; without
``units`` but with a ``scale`` it reads the scaled drawing in millimetres; with neither, it
scales the drawing to fill one page (:func:`fit_page_scale`). FOLD, OBJ and PNG keep the
design's own coordinates.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping

import numpy as np

from ..errors import ParameterError
from ..surface.pattern import Annotations, CreasePattern, Label
from ..surface.validate import validated_faces
from ..units import check_units, sheet_size_mm
from .dxf import check_scale, pattern_dxf
from .fold import _fold_document, fold_json
from .obj import _folded_obj
from .paths import pattern_extent
from .pdf import REGION_PAD_MM, pattern_pdf
from .png import parse_view, pattern_png, preview_png
from .svg import _pattern_svg

__all__ = [
    "ALL_FORMATS",
    "DEFAULT_FORMATS",
    "FORMAT_FILES",
    "cut_files",
    "fit_page_scale",
    "output_names",
    "parse_formats",
    "scaled_pattern",
]

#: Files written for each format, in writing order.
FORMAT_FILES = {
    "fold": ("design.fold",),
    "json": ("report.json",),
    "obj": ("folded.obj",),
    "svg": ("pattern.svg",),
    "dxf": ("pattern.dxf",),
    "pdf": ("pattern.pdf",),
    "png": ("pattern.png", "preview.png"),
}
#: Every format, in canonical order (what ``"all"`` means).
ALL_FORMATS = tuple(FORMAT_FILES)
#: What ``filletfold round`` and :meth:`Design.export` write by default.
DEFAULT_FORMATS = ("fold", "json", "obj", "svg")


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
        For an unknown format or an empty list.
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
        if not name:
            continue
        if name == "all":
            names.update(ALL_FORMATS)
        elif name in FORMAT_FILES:
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
    return dataclasses.replace(
        pattern,
        vertices_2d=pattern.vertices_2d * scale,
        annotations=Annotations(
            tabs=[np.asarray(t, dtype=np.float64) * scale for t in ann.tabs],
            tab_hinges=[np.asarray(h, dtype=np.float64) * scale for h in ann.tab_hinges],
            labels=[
                Label(
                    position=np.asarray(lb.position, dtype=np.float64) * scale,
                    text=lb.text,
                    angle=lb.angle,
                    height=lb.height * scale,
                    kind=lb.kind,
                )
                for lb in ann.labels
            ],
            sheets=np.asarray(ann.sheets, dtype=np.float64) * scale,
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
    view=None,
) -> dict:
    """Build the output files of ``formats`` for a crease pattern (nothing is written).

    Parameters
    ----------
    pattern : CreasePattern
    formats : str or iterable of str
        See :func:`parse_formats` and the module docstring.
    units : str
        ``""``, ``"mm"``, ``"cm"``, ``"m"`` or ``"in"``: the drawing unit of DXF, SVG and PDF.
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
        at a time); the pattern is still checked here, once.

    Returns
    -------
    dict of str to str or bytes (or to callables, with ``lazy``)
        File name to contents, in the order of :func:`output_names`. Text formats are ``str``,
        PDF and PNG ``bytes``.

    Raises
    ------
    ParameterError
        For an unknown format, unit or page, a non-positive scale, or ``json`` without a report.
    ExportError
        When the pattern is inconsistent.
    """
    formats = parse_formats(formats)
    azim, elev, up = parse_view("front" if view is None else view)
    check_units(units, unitless=True)
    scale_given = scale is not None
    scale = 1.0 if scale is None else check_scale(scale)
    if "pdf" in formats:
        sheet_size_mm(page, name="page")
    if "json" in formats and report is None:
        raise ParameterError(
            "report.json needs the whole design, not only its crease pattern "
            "(write it with 'filletfold round')",
            name="format",
        )
    faces = validated_faces(pattern)  # checked once here for fold, obj and svg

    from .report import report_json

    def fold():
        doc = _fold_document(pattern, faces, title=title, description=description, arrays=True)
        return fold_json(doc)

    def pdf():
        pdf_units, pdf_scale = units or "mm", scale
        if not units and not scale_given:
            pdf_scale = fit_page_scale(pattern, page)
        return pattern_pdf(pattern, page=page, units=pdf_units, scale=pdf_scale)

    builders = {
        "fold": {"design.fold": fold},
        "json": {"report.json": lambda: report if isinstance(report, str) else report_json(report)},
        "obj": {"folded.obj": lambda: _folded_obj(pattern, faces)},
        "svg": {"pattern.svg": lambda: _pattern_svg(scaled_pattern(pattern, scale), units=units)},
        "dxf": {"pattern.dxf": lambda: pattern_dxf(pattern, units=units, scale=scale)},
        "pdf": {"pattern.pdf": pdf},
        "png": {
            "pattern.png": lambda: pattern_png(pattern),
            "preview.png": lambda: preview_png(pattern, azim=azim, elev=elev, up=up),
        },
    }
    out = {name: build for fmt in formats for name, build in builders[fmt].items()}
    return out if lazy else {name: build() for name, build in out.items()}
