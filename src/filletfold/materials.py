"""Sheet materials: thickness, the least radius a bend may have, and the neutral axis.

A design is a surface; a real sheet has a thickness ``t`` and bends only so tightly before it
cracks, springs back or (card) buckles. :data:`MATERIALS` holds presets (``--material NAME``;
``docs/materials.md`` gives the basis of every value), :func:`resolve_material` applies the
overrides (``--thickness``, ``--min-bend-radius``, ``--k-factor``).

The surface of the design is the sheet's middle surface: a bend of radius ``r`` there has its
inner surface at ``r - t/2``, so a bend may be no tighter than :meth:`Material.bend_floor_mm`
``= min_bend_radius + t/2``. The edge stage raises every fillet below it (when the size is
given) or the default size grows until none is (``--size`` not given); see
:func:`~filletfold.pipeline.edge_stage`.

All lengths are millimetres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import ParameterError

__all__ = [
    "MATERIALS",
    "Kerf",
    "Material",
    "din6935_k_factor",
    "material_table",
    "resolve_material",
]


def din6935_k_factor(inner_radius_mm: float, thickness_mm: float) -> float:
    """The neutral axis of a bend as a fraction of the thickness from its inner surface, by
    DIN 6935's correction factor ``k = 0.65 + 0.5 log10(r/t)`` (1 for ``r/t > 5``), the
    neutral axis lying ``k t / 2`` from the inner surface: so 0.5 for wide bends, about 0.33 for
    a bend of radius ``t``, never under 0.25 here (``r/t`` under about 0.4)."""
    if thickness_mm <= 0:
        return 0.5
    ratio = inner_radius_mm / thickness_mm
    if ratio > 5:
        return 0.5
    k = 0.65 + 0.5 * math.log10(max(ratio, 1e-12))
    return min(max(k / 2, 0.25), 0.5)


@dataclass(frozen=True)
class Kerf:
    """How a rigid sheet is kerfed to bend (``making = "kerf"``): straight grooves along the
    rulings of every bend, on its inner (concave) side, ``depth_mm`` deep (a skin of
    ``thickness - depth`` stays), ``width_mm`` wide (the tool), at least ``land_mm`` of sheet
    between two grooves.

    The model (the kerf-bending relation of woodworking: a groove of width ``w`` and depth
    ``d`` that closes turns the sheet by ``2 atan(w / 2d)``, so a bend of radius ``R`` takes
    a groove every ``R w / d``): each groove closes by at most :meth:`turn_max`, the least of
    that closure and ``w / skin_radius_mm`` (the skin bends over the groove's width, no
    tighter than ``skin_radius_mm``). A bend turning by ``phi`` over an arc of length ``A``
    gets ``n = ceil(phi / turn_max)`` grooves ``A / n`` apart, each turning it by ``phi / n``;
    two grooves must leave ``land_mm`` between them: ``r phi / n >= w + land``. That holds
    for every bend of ``n >= 2`` grooves at :meth:`min_radius` ``= 2 (w + land) /
    turn_max`` (the worst bend turns by a little more than one groove's turn: two grooves
    share it); a bend of many grooves needs only ``(w + land) (1 + turn_max / phi) /
    turn_max``, which a floor per bend would allow (not yet: one floor holds for all).
    """

    width_mm: float
    depth_mm: float
    land_mm: float
    skin_radius_mm: float

    def turn_max(self) -> float:
        """The most one groove turns the sheet (radians)."""
        close = 2.0 * math.atan(self.width_mm / (2.0 * self.depth_mm))
        return min(close, self.width_mm / self.skin_radius_mm)

    def min_radius(self) -> float:
        """The least radius (mm) at which every kerfed bend leaves ``land_mm`` between its
        grooves: ``2 (w + land) / turn_max`` (the class docstring)."""
        return 2.0 * (self.width_mm + self.land_mm) / self.turn_max()

    def as_dict(self) -> dict:
        return {
            "width_mm": self.width_mm,
            "depth_mm": self.depth_mm,
            "land_mm": self.land_mm,
            "skin_radius_mm": self.skin_radius_mm,
            "turn_max_deg": math.degrees(self.turn_max()),
            "min_radius_mm": self.min_radius(),
        }


@dataclass(frozen=True)
class Material:
    """One sheet material.

    Attributes
    ----------
    name : str
    thickness_mm : float
    min_bend_radius_mm : float
        The least radius of the bend's inner surface.
    k_factor : float
        The neutral axis's distance from the inner surface, as a fraction of the thickness.
    making : str
        How its creases and bends are made: ``"score"`` (paper, card, polypropylene: score the
        crease lines), ``"relief"`` (sheet metal: brake or roll the bends, relieve the
        corners where bends meet) or ``"kerf"`` (plywood, acrylic: cuts along the rulings).
    description : str
    kerf : Kerf or None
        The grooves of a ``"kerf"`` material; its :meth:`Kerf.min_radius` is the material's
        ``min_bend_radius_mm``.
    """

    name: str
    thickness_mm: float
    min_bend_radius_mm: float
    k_factor: float
    making: str
    description: str = ""
    kerf: Kerf | None = None

    def bend_floor_mm(self) -> float:
        """The least radius a bend of the design's surface (the sheet's middle) may have:
        ``min_bend_radius + thickness / 2``."""
        return self.min_bend_radius_mm + self.thickness_mm / 2

    def as_dict(self) -> dict:
        """The report's account of it."""
        return {
            "name": self.name,
            "thickness_mm": self.thickness_mm,
            "min_bend_radius_mm": self.min_bend_radius_mm,
            "k_factor": self.k_factor,
            "making": self.making,
            "bend_floor_mm": self.bend_floor_mm(),
            **({"kerf": self.kerf.as_dict()} if self.kerf is not None else {}),
        }


def _metal(name, t, r_over_t, description) -> Material:
    r = r_over_t * t
    return Material(name, t, r, din6935_k_factor(r, t), "relief", description)


def _kerfed(name, t, kerf: Kerf, description) -> Material:
    return Material(name, t, kerf.min_radius(), 0.5, "kerf", description, kerf)


#: 3 mm birch plywood grooved 2 mm deep by a 1/8 in (3.2 mm) router bit, 2 mm of wood left
#: between grooves, the 1 mm skin bent no tighter than 25 mm over a groove: a groove turns
#: the sheet by at most 7.3 degrees, a bend is no tighter than 81.3 mm.
_PLYWOOD_KERF = Kerf(width_mm=3.2, depth_mm=2.0, land_mm=2.0, skin_radius_mm=25.0)


#: The presets of ``--material`` (values and their basis: ``docs/materials.md``).
MATERIALS: dict[str, Material] = {
    m.name: m
    for m in (
        Material("paper-120gsm", 0.15, 0.0, 0.5, "score", "office or drawing paper, 120 g/m2"),
        Material("card-300gsm", 0.40, 1.0, 0.5, "score", "card stock, 300 g/m2"),
        Material("polypropylene-0.5mm", 0.5, 0.0, 0.5, "score", "polypropylene sheet, 0.5 mm"),
        _metal("aluminium-1mm", 1.0, 1.0, "aluminium 5052-H32, 1 mm"),
        _metal("steel-0.8mm", 0.8, 1.0, "cold-rolled mild steel (DC01), 0.8 mm"),
        _kerfed(
            "plywood-3mm", 3.0, _PLYWOOD_KERF, "birch plywood, 3 mm, kerfed (unkerfed: 150 mm)"
        ),
    )
}


def material_table() -> list[dict]:
    """Every preset's account (:meth:`Material.as_dict` and its description), for
    ``filletfold materials``."""
    return [{**m.as_dict(), "description": m.description} for m in MATERIALS.values()]


def _length(value, name: str, *, zero: bool) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(f"{name} must be a number of millimetres, got {value!r}", name=name)
    value = float(value)
    if not math.isfinite(value) or value < 0 or (value == 0 and not zero):
        what = "at least 0" if zero else "more than 0"
        raise ParameterError(f"{name} must be {what} millimetres, got {value!r}", name=name)
    return value


def resolve_material(
    name: str | None,
    thickness: float | None = None,
    min_bend_radius: float | None = None,
    k_factor: float | None = None,
) -> Material | None:
    """The material of ``--material NAME`` with the overrides given (None: that of the preset);
    the overrides alone describe a sheet of their own (``"custom"``: thickness 0, any bend,
    k-factor 0.5 where not given). None when nothing is given: no material, the paper of
    zero thickness the method assumes.

    Raises
    ------
    ParameterError
        An unknown name (the presets are listed), or a length that is not a finite number of
        millimetres (thickness > 0, bend radius >= 0), a k-factor outside [0, 1].
    """
    t = _length(thickness, "thickness", zero=False)
    r = _length(min_bend_radius, "min_bend_radius", zero=True)
    if k_factor is not None:
        if isinstance(k_factor, bool) or not isinstance(k_factor, int | float):
            raise ParameterError(f"k-factor must be a number, got {k_factor!r}", name="k_factor")
        if not 0 <= float(k_factor) <= 1:
            raise ParameterError(f"k-factor must be in [0, 1], got {k_factor!r}", name="k_factor")
    if name is None:
        if t is None and r is None and k_factor is None:
            return None
        base = Material("custom", 0.0, 0.0, 0.5, "score", "a sheet given by its figures")
    else:
        if not isinstance(name, str) or name not in MATERIALS:
            raise ParameterError(
                f"unknown material {name!r}: choose from {', '.join(MATERIALS)}", name="material"
            )
        base = MATERIALS[name]
    return Material(
        base.name,
        base.thickness_mm if t is None else t,
        base.min_bend_radius_mm if r is None else r,
        base.k_factor if k_factor is None else float(k_factor),
        base.making,
        base.description,
        base.kerf,
    )
