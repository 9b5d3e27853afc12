"""DXF (R2010) cut file of the flat crease pattern, for laser cutters, plotters and CAD.

Layers, colours, line weights and line styles come from a cutter preset
(:mod:`filletfold.export.presets`). The default, ``print`` (as ``origami-simulator``), has these
layers and colours (ACI):

===========  =========  =======================================================================
layer        colour     content
===========  =========  =======================================================================
``CUT``      7          ``B`` edges (piece borders and cuts) and the cut part of each glue-tab
                        outline (the outline without its hinge)
``MOUNTAIN`` 1 red      ``M`` edges
``VALLEY``   5 blue     ``V`` edges
``TAB``      6 magenta  the tab hinges (the fold between a tab and its piece), linetype
                        ``DASHED``; the tab outline is *not* repeated here, so a machine that
                        cuts ``CUT`` and scores ``TAB`` never cuts a line twice
``LABEL``    8 grey     ``TEXT`` entities of the labels (centred on their anchor, rotated)
``FLAT``     2 yellow   ``F`` edges, only with ``flat_edges=True``
===========  =========  =======================================================================

The other presets rename the layers (e.g. ``SCORE_MOUNTAIN``, ``PERF_VALLEY``, ``ENGRAVE``),
give them true colours besides the ACI, and line weights (:func:`~filletfold.export.presets.
dxf_lineweight`; a laser hairline is weight 0). A pen with a dash style gets its own linetype
``DASH_<dash>_<gap>`` (lengths in millimetres, drawn in the drawing unit; unitless, read as
millimetres); a perforated pen's lines are written as separate dash pieces
(:func:`~filletfold.export.paths.dash_polylines`), one ``LWPOLYLINE`` each, so that a machine
that ignores linetypes still perforates.

Edges of one layer are chained end to end through vertices where exactly two of them meet
(:func:`~filletfold.export.paths.edge_chains`); each chain is cut at corners and spacing jumps
into runs (:func:`~filletfold.export.paths.chain_runs`). A smooth run of at least seven points
(turning at most 8 degrees per point, neighbouring segments within a factor 3 in length) is a
``SPLINE`` through its points (fit points plus the control points of the CAD-style
interpolation); everything else is an ``LWPOLYLINE``. Sheet outlines are not written (one DXF
holds every sheet). Besides these, the file has the standard layers ``0`` and ``Defpoints``
(empty).

The output is deterministic: entities are written in a fixed order with sequential handles, the
DXF's dates and GUIDs are fixed and its CLASSES section is sorted (ezdxf's own order depends on
the process's string hash seed).
"""

from __future__ import annotations

import io
import math

import numpy as np

from ..errors import ParameterError
from ..layout.making import MAKING_KINDS
from ..surface.pattern import CreasePattern
from ..surface.validate import validate_pattern
from ..units import MM_PER_UNIT, check_units
from .paths import (
    chain_runs,
    dash_polylines,
    edge_chains,
    edge_layer_masks,
    pattern_extent,
    tab_cut_paths,
)
from .presets import Preset, dxf_lineweight, get_preset, hex_rgb, making_pens

__all__ = ["DXF_INSUNITS", "LAYER_COLOR", "check_scale", "pattern_dxf"]

#: ``$INSUNITS`` code of each drawing unit ("" = unitless): of every cut-file unit.
DXF_INSUNITS = {"": 0, "in": 1, "mm": 4, "cm": 5, "m": 6}
#: ACI colour of each layer of the default preset, in the order the layers are created.
LAYER_COLOR = {pen.layer: pen.aci for pen in get_preset(None).pens().values()}
#: The preset role of each layer kind of :func:`~filletfold.export.paths.edge_layer_masks`.
_ROLE = {"CUT": "cut", "MOUNTAIN": "mountain", "VALLEY": "valley", "FLAT": "flat"}


def check_scale(scale) -> float:
    """``scale`` as a float; a :class:`ParameterError` unless it is a positive finite number."""
    if isinstance(scale, bool) or not isinstance(scale, int | float):
        raise ParameterError(f"scale must be a positive number, got {scale!r}", name="scale")
    if not (math.isfinite(scale) and scale > 0):
        raise ParameterError(f"scale must be a positive number, got {scale!r}", name="scale")
    return float(scale)


def pattern_dxf(
    pattern: CreasePattern,
    *,
    units: str = "",
    scale: float = 1.0,
    flat_edges: bool = False,
    preset: str | Preset | None = None,
) -> str:
    """The flat layout of a crease pattern as a DXF R2010 document.

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`; its annotations (tabs,
        hinges, labels) are drawn when present.
    units : str
        Drawing unit written to ``$INSUNITS``: ``""`` (unitless), ``"mm"``, ``"cm"``, ``"m"`` or
        ``"in"``.
    scale : float
        Drawing units per pattern length unit: every coordinate and text height is multiplied
        by it.
    flat_edges : bool
        Also write the ``F`` edges, on the preset's flat layer (``FLAT``).
    preset : str or Preset, optional
        Cutter preset (:data:`~filletfold.export.presets.PRESETS`); default
        ``print``, whose layers are the table above.

    Returns
    -------
    str
        The DXF text. Same input, same text.

    Raises
    ------
    ParameterError
        For an unknown ``units`` or ``preset``, or a ``scale`` that is not a positive number.
    ExportError
        When the pattern is inconsistent.
    """
    import ezdxf

    check_units(units, unitless=True)
    scale = check_scale(scale)
    preset = get_preset(preset)
    validate_pattern(pattern)

    fixed = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True  # fixed dates, GUIDs and markers
    try:
        doc = ezdxf.new("R2010", setup=False)
        _fill(doc, pattern, units, scale, flat_edges, preset)
        _sort_classes(doc)
        stream = io.StringIO()
        doc.write(stream)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = fixed
    return stream.getvalue()


def _sort_classes(doc) -> None:
    """Register the DXF's ``CLASS`` entries now, in sorted order.

    On writing, ezdxf adds a class for each entity type in use, taken from a ``set`` of type
    names: in an order that changes with Python's string hash seed, i.e. from one process to
    the next. Registered and sorted here, the CLASSES section is the same in every run (writing
    adds none).
    """
    from collections import OrderedDict

    doc.commit_pending_changes()
    doc.classes.add_required_classes(doc.dxfversion)
    doc.classes.classes = OrderedDict(sorted(doc.classes.classes.items()))


def _fill(
    doc, pattern: CreasePattern, units: str, scale: float, flat_edges: bool, preset: Preset
) -> None:
    """Add the header variables, layers and entities of :func:`pattern_dxf` to ``doc``."""
    from ezdxf.enums import TextEntityAlignment

    doc.header["$INSUNITS"] = DXF_INSUNITS[units]
    doc.header["$MEASUREMENT"] = 0 if units == "in" else 1
    lo, hi = pattern_extent(pattern)
    size = max(float((hi - lo).max()) * scale, 1e-12)
    per_mm = 1.0 / MM_PER_UNIT[units] if units else 1.0  # drawing units per millimetre
    pens = preset.pens()
    if not flat_edges:
        del pens["flat"]
    kinds = {m.kind for m in pattern.annotations.making}
    making = making_pens(preset)
    for kind in MAKING_KINDS:  # the layers of a sheet material's reliefs and grooves
        if kind in kinds:
            pens[kind] = making[kind]
    for pen in pens.values():
        layer = doc.layers.add(pen.layer, color=pen.aci)
        if preset.true_color:
            layer.rgb = hex_rgb(pen.color)
        layer.dxf.lineweight = dxf_lineweight(pen.width_mm)
        if pen.dash_share is not None:
            dash = pen.dash_share * size
            if "DASHED" not in doc.linetypes:
                doc.linetypes.add(
                    "DASHED", pattern=[2 * dash, dash, -dash], description="Dashed __ __ __"
                )
            layer.dxf.linetype = "DASHED"
        elif pen.dash_mm is not None:
            on, off = pen.dash_mm
            name = f"DASH_{on:g}_{off:g}".replace(".", "_")
            if name not in doc.linetypes:
                doc.linetypes.add(
                    name,
                    pattern=[(on + off) * per_mm, on * per_mm, -off * per_mm],
                    description=f"Dashed {on:g} mm on, {off:g} mm off",
                )
            layer.dxf.linetype = name
    msp = doc.modelspace()

    def perforated(pen, paths) -> None:
        cut, gap = (x * per_mm for x in pen.perforation_mm)
        for pts, closed in paths:
            for dash in dash_polylines(pts, closed, cut, gap):
                msp.add_lwpolyline(
                    [(float(x), float(y)) for x, y in dash],
                    format="xy",
                    dxfattribs={"layer": pen.layer},
                )

    v2 = pattern.vertices_2d * scale
    for kind, mask in edge_layer_masks(pattern, flat_edges=flat_edges).items():
        pen = pens[_ROLE[kind]]
        chains = [(v2[chain], closed) for chain, closed in edge_chains(pattern.edges, mask)]
        if pen.perforation_mm is not None:
            perforated(pen, chains)
        else:
            for pts, closed in chains:
                _add_path(msp, pts, closed, pen.layer)
        if kind == "CUT":
            for pts, closed in tab_cut_paths(pattern.annotations):
                _add_path(msp, np.asarray(pts) * scale, closed, pen.layer)
    tab = pens["tab"]
    hinges = [
        np.asarray(h, dtype=np.float64).reshape(2, 2) * scale
        for h in pattern.annotations.tab_hinges
    ]
    if tab.perforation_mm is not None:
        perforated(tab, [(h, False) for h in hinges])
    else:
        for a, b in hinges:
            msp.add_line(tuple(a), tuple(b), dxfattribs={"layer": tab.layer})
    for m in pattern.annotations.making:  # a sheet material's reliefs and kerf grooves
        _add_path(msp, np.asarray(m.points) * scale, m.closed, making[m.kind].layer)
    for label in pattern.annotations.labels:
        pos = np.asarray(label.position, dtype=np.float64).reshape(2) * scale
        text = msp.add_text(
            str(label.text),
            height=float(label.height) * scale,
            rotation=float(label.angle),
            dxfattribs={"layer": pens["label"].layer},
        )
        text.set_placement(tuple(pos), align=TextEntityAlignment.MIDDLE_CENTER)
    doc.set_modelspace_vport(height=size * 1.1, center=tuple((lo + hi) / 2 * scale))


def _add_path(msp, points: np.ndarray, closed: bool, layer: str) -> None:
    """Write one path as its spline and polyline runs (see the module docstring)."""
    from ezdxf.math import fit_points_to_cad_cv

    for run, spline, run_closed in chain_runs(points, closed):
        if spline:
            fit = [(float(x), float(y), 0.0) for x, y in run]
            entity = msp.add_spline(fit, degree=3, dxfattribs={"layer": layer})
            entity.apply_construction_tool(fit_points_to_cad_cv(fit))
            entity.fit_points = fit
        else:
            msp.add_lwpolyline(
                [(float(x), float(y)) for x, y in run],
                format="xy",
                close=run_closed,
                dxfattribs={"layer": layer},
            )
