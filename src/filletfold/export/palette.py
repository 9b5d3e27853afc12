"""Colours of the drawn pictures, the one table shared by the PDF and PNG writers.

The edge colours are the ones Origami Simulator reads from an SVG (mountain red, valley blue,
border/cut black). The SVG and DXF follow a cutter preset instead
(:mod:`~filletfold.export.presets`: pens with colours, layers, widths); the SVG uses
:data:`SHEET_COLOR` for its sheet outlines.
"""

from __future__ import annotations

__all__ = [
    "ASSIGNMENT_COLOR",
    "KERF_COLOR",
    "LABEL_COLOR",
    "PATCH_COLOR",
    "SHEET_COLOR",
    "TAB_HINGE_COLOR",
]

#: Stroke colour of each edge assignment.
ASSIGNMENT_COLOR = {"M": "#ff0000", "V": "#0000ff", "B": "#000000", "F": "#dddddd"}
#: Tab hinges (the fold between a glue tab and its piece), drawn dashed: magenta, the
#: default preset's (Origami Simulator's hinge), as in the default SVG and DXF.
TAB_HINGE_COLOR = "#ff00ff"
#: Outlines of the sheets of material.
SHEET_COLOR = "#999999"
#: Labels (part numbers, seam labels).
LABEL_COLOR = "#404040"
#: Base colour (RGB, 0..1) of each patch kind in the folded preview: cone orange, cylinder blue,
#: conical fillet teal, flat face piece green.
PATCH_COLOR = {
    "cone": (0.96, 0.62, 0.25),
    "cylinder": (0.35, 0.6, 0.9),
    "fillet": (0.24, 0.78, 0.78),
    "face": (0.45, 0.78, 0.45),
}
#: The kerf grooves of a sheet material, cut from the front and from the back (the presets'
#: pens, :func:`~filletfold.export.presets.making_pens`).
KERF_COLOR = {"kerf-front": "#ff8000", "kerf-back": "#8000ff"}
