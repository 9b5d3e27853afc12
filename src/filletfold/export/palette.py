"""Colours of the drawn pictures, the one table shared by the PDF and PNG writers.

The edge colours are the ones Origami Simulator reads from an SVG (mountain red, valley blue,
border/cut black). The SVG and DXF follow a cutter preset instead
(:mod:`~filletfold.export.presets`: pens with colours, layers, widths); the SVG uses
:data:`SHEET_COLOR` for its sheet outlines.
"""

from __future__ import annotations

__all__ = ["ASSIGNMENT_COLOR", "LABEL_COLOR", "SHEET_COLOR", "TAB_HINGE_COLOR"]

#: Stroke colour of each edge assignment.
ASSIGNMENT_COLOR = {"M": "#ff0000", "V": "#0000ff", "B": "#000000", "F": "#dddddd"}
#: Tab hinges (the fold between a glue tab and its piece), drawn dashed.
TAB_HINGE_COLOR = "#00a000"
#: Outlines of the sheets of material.
SHEET_COLOR = "#999999"
#: Labels (part numbers, seam labels).
LABEL_COLOR = "#404040"
