"""Cutter presets: how the SVG and DXF say cut, score and engrave.

Shops differ in how a file asks for a cut, a score or an engraving: by stroke colour (laser
software maps each colour to a power and speed), by DXF layer, by line width (lasers want a
hairline), by dashed lines (a plotter or cutting machine scores a dashed line), or by cutting
the fold lines through in short pieces (card: perforated folds). A :class:`Preset` holds one
:class:`Pen` per kind of line and the few drawing options that go with it; :data:`PRESETS`
holds the named ones and :func:`get_preset` looks a name up.

=====================  ===========================================================================
preset                 what it is for
=====================  ===========================================================================
``print``              the default of ``pattern.svg`` and ``pattern.dxf``: a drawing to print
                       and cut by hand or on a cutting machine that reads colours, in the
                       conventional crease-pattern colours (cut black, mountain red, valley
                       blue, tab hinge magenta dashed, labels grey, 0.3 mm), each layer's edges
                       joined into paths, legend and scale bar; no facet lines (they are not
                       cut or scored, and ``design.fold`` holds the triangulation); the DXF is
                       that of ``origami-simulator``
``origami-simulator``  the SVG as Origami Simulator imports it: the colours Origami
                       Simulator reads (mountain red, valley blue, cut black, facet yellow, hinge
                       magenta), ``stroke-opacity`` = |fold angle| / 180, facet (``F``)
                       lines; the DXF has layers ``CUT``/``MOUNTAIN``/``VALLEY``/``TAB``/
                       ``LABEL`` in ACI 7/1/5/6/8, the SVG's colours (the tab hinge magenta in
                       both: ACI 3 would be ``#00ff00``, the simulator's cut)
``laser``              a generic laser cutter: hairlines (0.01 mm), cut red, mountain score blue,
                       valley score green, tab score magenta, labels black (engrave); DXF layers
                       ``CUT``, ``SCORE_MOUNTAIN``, ``SCORE_VALLEY``, ``SCORE_TAB``, ``ENGRAVE``
                       with true colours
``plotter``            a plotter or cutting machine: 0.25 mm lines, cut black, score lines dashed
                       (mountain 4 mm on 2 mm off, valley and tab 2 on 2), as a dash style (SVG
                       ``stroke-dasharray``, a DXF linetype)
``card``               card stock: 0.1 mm lines, fold lines perforated, i.e. drawn as short cut
                       pieces with gaps in the geometry itself (mountain 2 mm cut 1 mm tie,
                       valley and tab 1 on 1), so a cutter that ignores line styles still
                       perforates
=====================  ===========================================================================

Lengths of dashes and perforations are printed millimetres: in the SVG those of its printed
size, in the DXF its drawing unit (``units``; unitless, read as millimetres).
"""

from __future__ import annotations

import dataclasses
import math

from ..errors import ParameterError
from .palette import KERF_COLOR

__all__ = [
    "DEFAULT_PRESET",
    "DXF_LINEWEIGHTS",
    "PRESETS",
    "RESOLUTION_MM",
    "Pen",
    "Preset",
    "dxf_lineweight",
    "get_preset",
    "hex_rgb",
    "making_pens",
    "score_preset",
]

#: Finest printed length (mm) the coordinates of a cut file resolve (a preset's
#: ``resolution_mm``): a micrometre, finer than any printer or cutter (a laser's spot is
#: 0.1-0.2 mm); digits beyond it carry nothing.
RESOLUTION_MM = 1e-3
#: The preset of ``pattern.svg`` and ``pattern.dxf`` when none is given.
DEFAULT_PRESET = "print"
#: The line weights a DXF can carry (hundredths of a millimetre); 0 is the thinnest line.
DXF_LINEWEIGHTS = (0, 5, 9, 13, 15, 18, 20, 25, 30, 35, 40, 50, 53, 60, 70, 80, 90, 100, 106)


def hex_rgb(color: str) -> tuple[int, int, int]:
    """``(r, g, b)`` of a ``"#rrggbb"`` colour."""
    return int(color[1:3], 16), int(color[3:5], 16), int(color[5:7], 16)


def dxf_lineweight(width_mm: float) -> int:
    """The DXF line weight (hundredths of a mm) closest to ``width_mm``; a hairline (under
    0.025 mm) is 0, the thinnest line a DXF can ask for."""
    return min(DXF_LINEWEIGHTS, key=lambda w: (abs(w - 100.0 * width_mm), w))


def _check_pair(value, what: str) -> None:
    if value is None:
        return
    ok = (
        isinstance(value, tuple)
        and len(value) == 2
        and all(isinstance(x, int | float) and math.isfinite(x) and x > 0 for x in value)
    )
    if not ok:
        raise ParameterError(f"{what} must be two positive lengths (mm), got {value!r}", name=what)


@dataclasses.dataclass(frozen=True)
class Pen:
    """How one kind of line is drawn.

    Parameters
    ----------
    color : str
        ``"#rrggbb"``: the SVG stroke (for labels, the fill); the DXF layer's true colour when
        the preset has ``true_color``.
    layer : str
        DXF layer name.
    aci : int
        DXF layer colour (AutoCAD colour index, 1-255).
    width_mm : float
        Line width in millimetres: the SVG ``stroke-width`` and the DXF layer line weight
        (:func:`dxf_lineweight`).
    dash_mm : (float, float), optional
        ``(dash, gap)``: a dashed line style, the SVG ``stroke-dasharray`` and a DXF linetype;
        the geometry stays whole.
    perforation_mm : (float, float), optional
        ``(cut, gap)``: the line is drawn as separate pieces of length ``cut`` with ``gap``
        between them (:func:`~filletfold.export.paths.dash_polylines`), in the geometry itself.
    dash_share : float, optional
        A dash style of dash = gap = this share of the drawing's larger side (the DXF linetype
        ``DASHED`` of the tab hinges, as it was before presets).
    """

    color: str
    layer: str
    aci: int
    width_mm: float
    dash_mm: tuple[float, float] | None = None
    perforation_mm: tuple[float, float] | None = None
    dash_share: float | None = None

    def __post_init__(self):
        c = self.color
        if not (
            isinstance(c, str)
            and len(c) == 7
            and c[0] == "#"
            and all(ch in "0123456789abcdef" for ch in c[1:])
        ):
            raise ParameterError(
                f"pen colour must be '#rrggbb' (lower case), got {c!r}", name="color"
            )
        if not (isinstance(self.layer, str) and self.layer and self.layer.isprintable()):
            raise ParameterError(f"pen layer must be a name, got {self.layer!r}", name="layer")
        if not (isinstance(self.aci, int) and 1 <= self.aci <= 255):
            raise ParameterError(f"pen ACI colour must be 1-255, got {self.aci!r}", name="aci")
        w = self.width_mm
        if not (isinstance(w, int | float) and math.isfinite(w) and w > 0):
            raise ParameterError(f"pen width_mm must be positive, got {w!r}", name="width_mm")
        _check_pair(self.dash_mm, "dash_mm")
        _check_pair(self.perforation_mm, "perforation_mm")
        styles = [self.dash_mm, self.perforation_mm, self.dash_share]
        if sum(s is not None for s in styles) > 1:
            raise ParameterError(
                "a pen is dashed, perforated or dashed by share, not several", name="dash_mm"
            )


@dataclasses.dataclass(frozen=True)
class Preset:
    """A named set of pens and drawing options for ``pattern.svg`` and ``pattern.dxf``.

    Parameters
    ----------
    name, description : str
    cut : Pen
        ``B`` edges (borders and cuts) and the cut part of each glue-tab outline.
    mountain, valley : Pen
        ``M`` and ``V`` edges.
    tab : Pen
        The tab hinges (the fold between a glue tab and its piece).
    label : Pen
        Labels (part numbers, seam labels): filled text, engraved or drawn.
    flat : Pen
        ``F`` edges (facets inside a developable patch), when they are drawn.
    flat_edges : bool
        The SVG draws the ``F`` edges (Origami Simulator then keeps the triangulation; the DXF
        writes them only when asked).
    angle_opacity : bool
        The SVG gives each mountain and valley line ``stroke-opacity`` = |fold angle| / 180
        (Origami Simulator's target fold angle); the lines are then one ``<line>`` per edge.
    join_lines : bool
        The SVG joins the edges of a layer end to end into ``<polyline>`` paths (what cutter
        software wants, and what keeps a dash style running along a curve); else one
        ``<line>`` per edge.
    annotations : bool
        The SVG carries the scale bar, legend and sheet outlines (inside ``<defs>``, shown by
        ``<use>``, so that a stroke reader never sees them); a cutter preset leaves them out,
        so that nothing is cut or engraved that is not the pattern.
    true_color : bool
        The DXF layers carry the pens' colours as true colours besides the ACI.
    resolution_mm : float, optional
        The finest printed length the SVG's coordinates resolve (:func:`~filletfold.export.svg.
        svg_decimals`): a micrometre by default, finer than any printer or cutter; ``None``
        keeps 8 significant digits of the drawing (``origami-simulator``, whose import and
        tools compare the drawing with ``design.fold`` to 1e-6 of its size).
    """

    name: str
    description: str
    cut: Pen
    mountain: Pen
    valley: Pen
    tab: Pen
    label: Pen
    flat: Pen
    flat_edges: bool = False
    angle_opacity: bool = False
    join_lines: bool = True
    annotations: bool = False
    true_color: bool = True
    resolution_mm: float | None = RESOLUTION_MM

    def __post_init__(self):
        r = self.resolution_mm
        if r is not None and not (isinstance(r, int | float) and math.isfinite(r) and r > 0):
            raise ParameterError(
                f"preset resolution_mm must be positive, got {r!r}", name="resolution_mm"
            )
        layers = [p.layer for p in self.pens().values()]
        if len(set(layers)) != len(layers):
            raise ParameterError(f"preset {self.name!r}: two pens share a layer", name="layer")

    def pens(self) -> dict[str, Pen]:
        """The pens by role: ``cut``, ``mountain``, ``valley``, ``tab``, ``label``, ``flat``."""
        return {f: getattr(self, f) for f in ("cut", "mountain", "valley", "tab", "label", "flat")}


#: The pens of ``print`` and ``origami-simulator``: Origami Simulator's colours (the
#: conventional crease-pattern colours), DXF layers in ACI colours.
_SIMULATOR_PENS = {
    "cut": Pen("#000000", "CUT", 7, 0.3),
    "mountain": Pen("#ff0000", "MOUNTAIN", 1, 0.3),
    "valley": Pen("#0000ff", "VALLEY", 5, 0.3),
    "tab": Pen("#ff00ff", "TAB", 6, 0.3, dash_share=0.005),
    "label": Pen("#404040", "LABEL", 8, 0.3),
    "flat": Pen("#ffff00", "FLAT", 2, 0.1),
}
_PRINT = Preset(
    name="print",
    description="to print and cut: cut black, mountain red, valley blue, tab hinge magenta "
    "(default)",
    **_SIMULATOR_PENS,
    annotations=True,
    true_color=False,
)
_OS = Preset(
    name="origami-simulator",
    description="Origami Simulator's SVG colours and fold-angle opacities",
    **_SIMULATOR_PENS,
    flat_edges=True,
    angle_opacity=True,
    join_lines=False,
    annotations=True,
    true_color=False,
    resolution_mm=None,
)
_LASER = Preset(
    name="laser",
    description="generic laser cutter: hairlines, cut red, scores blue/green/magenta, "
    "engrave black",
    cut=Pen("#ff0000", "CUT", 1, 0.01),
    mountain=Pen("#0000ff", "SCORE_MOUNTAIN", 5, 0.01),
    valley=Pen("#00ff00", "SCORE_VALLEY", 3, 0.01),
    tab=Pen("#ff00ff", "SCORE_TAB", 6, 0.01),
    label=Pen("#000000", "ENGRAVE", 7, 0.01),
    flat=Pen("#cccccc", "FLAT", 9, 0.01),
)
_PLOTTER = Preset(
    name="plotter",
    description="plotter or cutting machine: cut black, dashed score lines",
    cut=Pen("#000000", "CUT", 7, 0.25),
    mountain=Pen("#ff0000", "SCORE_MOUNTAIN", 1, 0.25, dash_mm=(4.0, 2.0)),
    valley=Pen("#0000ff", "SCORE_VALLEY", 5, 0.25, dash_mm=(2.0, 2.0)),
    tab=Pen("#00a000", "SCORE_TAB", 3, 0.25, dash_mm=(2.0, 2.0)),
    label=Pen("#404040", "LABEL", 8, 0.25),
    flat=Pen("#cccccc", "FLAT", 9, 0.1),
)
_CARD = Preset(
    name="card",
    description="card stock: fold lines perforated (cut pieces with ties)",
    cut=Pen("#000000", "CUT", 7, 0.1),
    mountain=Pen("#ff0000", "PERF_MOUNTAIN", 1, 0.1, perforation_mm=(2.0, 1.0)),
    valley=Pen("#0000ff", "PERF_VALLEY", 5, 0.1, perforation_mm=(1.0, 1.0)),
    tab=Pen("#00a000", "PERF_TAB", 3, 0.1, perforation_mm=(1.0, 1.0)),
    label=Pen("#404040", "LABEL", 8, 0.1),
    flat=Pen("#cccccc", "FLAT", 9, 0.1),
)

#: The named presets, the default first.
PRESETS: dict[str, Preset] = {p.name: p for p in (_PRINT, _OS, _LASER, _PLOTTER, _CARD)}


def get_preset(preset: str | Preset | None = None) -> Preset:
    """The :class:`Preset` of a name (``None``: :data:`DEFAULT_PRESET`), or ``preset`` itself.

    Raises
    ------
    ParameterError
        For an unknown name (the message lists the names).
    """
    if preset is None:
        return PRESETS[DEFAULT_PRESET]
    if isinstance(preset, Preset):
        return preset
    if isinstance(preset, str) and preset.strip().lower() in PRESETS:
        return PRESETS[preset.strip().lower()]
    raise ParameterError(
        f"unknown preset {preset!r}: choose from {', '.join(PRESETS)}", name="preset"
    )


def making_pens(preset: Preset) -> dict[str, Pen]:
    """The pens of a sheet material's making paths (:mod:`~filletfold.layout.making`) in a
    preset: a relief is cut through like the borders (the cut pen, whole even where the cut
    pen perforates, on layer ``RELIEF``); a kerf groove is cut part way, from the front
    (orange, ``KERF_FRONT``) or the back (violet, ``KERF_BACK``: the drawing as seen from the
    front; the sheet is turned over to cut it), at the cut pen's width."""
    cut = preset.cut
    w = cut.width_mm
    return {
        "relief": dataclasses.replace(
            cut, layer="RELIEF", perforation_mm=None, dash_mm=None, dash_share=None
        ),
        "kerf-front": Pen(KERF_COLOR["kerf-front"], "KERF_FRONT", 30, w),
        "kerf-back": Pen(KERF_COLOR["kerf-back"], "KERF_BACK", 200, w),
    }


def score_preset(preset: Preset, layers: dict[str, str] | None) -> Preset:
    """``preset`` with its mountain and valley pens on the score layers ``layers``
    (:func:`~filletfold.layout.making.score_layers`: ``SCORE_FRONT``, ``SCORE_BACK``), or
    itself when ``layers`` is None."""
    if not layers:
        return preset
    return dataclasses.replace(
        preset,
        mountain=dataclasses.replace(preset.mountain, layer=layers["mountain"]),
        valley=dataclasses.replace(preset.valley, layer=layers["valley"]),
    )
