"""Sizes on paper: the one table of sheet sizes and the one table of length units.

Every writer and front end reads sheet names and drawing units through this module, so a sheet
or unit accepted by one path is accepted by all, with the same error when it is not.

A sheet is a name of :data:`SHEET_SIZES_MM` (any case) or a custom ``"WxH"`` size in
millimetres (``"600x400"``, ``"600 x 400 mm"``, ``"600×400"``). A unit is a key of
:data:`MM_PER_UNIT`; the cut files (DXF, SVG, PDF, and so the CLI) take the units of
:data:`CUT_FILE_UNITS`, or none.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable

from .errors import ParameterError

__all__ = [
    "AUTO_SIZE",
    "CUT_FILE_UNITS",
    "LEAST_SIZE_MM",
    "MIN_LABEL_MM",
    "MIN_PIECE_MM",
    "MM_PER_UNIT",
    "SHEET_SIZES_MM",
    "ceil_digits",
    "check_units",
    "parse_size",
    "sheet_size_mm",
]

#: Sheet sizes (width, height) in millimetres, portrait, by the name the user writes.
SHEET_SIZES_MM = {
    "A4": (210.0, 297.0),
    "A3": (297.0, 420.0),
    "A2": (420.0, 594.0),
    "A1": (594.0, 841.0),
    "Letter": (215.9, 279.4),
    "Legal": (215.9, 355.6),
}
#: Millimetres per length unit.
MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "pt": 25.4 / 72.0}
#: The units every cut file can carry (DXF has no code for points).
CUT_FILE_UNITS = ("mm", "cm", "m", "in")

#: Pieces that span less than this on the sheet (mm) are too small to cut and fold (the
#: summary warns; the default size makes none).
MIN_PIECE_MM = 3.0
#: Labels lower than this on the sheet (mm) are hard to read (the summary warns; the default
#: size makes none).
MIN_LABEL_MM = 2.0
#: The default size: the least largest side (mm) of an object made at the default size, a
#: model held in the hand.
LEAST_SIZE_MM = 100.0
#: The ``size`` that asks for the default: the least size at which the object can be built
#: (see :func:`filletfold.layout.arrange.default_size`).
AUTO_SIZE = "auto"

_NUMBER = r"(\d+(?:\.\d*)?|\.\d+)"
_SIZE = re.compile(rf"\s*{_NUMBER}\s*(mm|cm|m|in)?\s*")
_CUSTOM = re.compile(rf"\s*{_NUMBER}\s*[xX×]\s*{_NUMBER}\s*(?:mm)?\s*")


def sheet_size_mm(sheet: str, *, name: str = "sheet") -> tuple[float, float]:
    """Width and height (mm) of a sheet: a name of :data:`SHEET_SIZES_MM` or ``"WxH"`` in mm.

    Parameters
    ----------
    sheet : str
        ``"A4"``, ``"A3"``, ``"A2"``, ``"A1"``, ``"Letter"``, ``"Legal"`` (any case) or a
        custom size ``"WxH"`` in millimetres.
    name : str
        The parameter named in the error (``"sheet"``, or ``"page"`` for the PDF writer).

    Returns
    -------
    (float, float)
        Width and height in millimetres (portrait for the named sizes).

    Raises
    ------
    ParameterError
        For a value that is not a string, an unknown name, a malformed custom size or one
        that is not positive.
    """
    if not isinstance(sheet, str):
        raise ParameterError(f"{name} must be a string, got {type(sheet).__name__}", name=name)
    key = sheet.strip().lower()
    for known, size in SHEET_SIZES_MM.items():
        if key == known.lower():
            return size
    m = _CUSTOM.fullmatch(sheet)
    if not m:
        raise ParameterError(
            f"{name} must be one of {', '.join(SHEET_SIZES_MM)} or 'WxH' in millimetres "
            f"(e.g. '600x400'), got {sheet!r}",
            name=name,
        )
    width, height = float(m.group(1)), float(m.group(2))
    if not (width > 0 and height > 0 and math.isfinite(width) and math.isfinite(height)):
        raise ParameterError(f"{name} size must be positive, got {sheet!r}", name=name)
    return width, height


def check_units(units: str, choices: Iterable[str] = CUT_FILE_UNITS, *, unitless: bool) -> str:
    """``units`` if it is one of ``choices`` (or ``""`` with ``unitless``), else an error.

    Parameters
    ----------
    units : str
    choices : iterable of str
        Keys of :data:`MM_PER_UNIT` that the caller accepts.
    unitless : bool
        Whether ``""`` (no unit) is accepted too.

    Returns
    -------
    str
        ``units``; look its length up in :data:`MM_PER_UNIT` (unless it is ``""``).

    Raises
    ------
    ParameterError
        Naming ``units`` and listing what is accepted.
    """
    choices = tuple(choices)
    if (units == "" and unitless) or (units in choices and units != ""):
        return units
    listed = ", ".join(choices) + (" or '' (unitless)" if unitless else "")
    raise ParameterError(f"units must be one of {listed}, got {units!r}", name="units")


def parse_size(size) -> tuple[float, str]:
    """A physical length such as ``"300mm"``, ``"30 cm"``, ``"0.3m"`` or ``"12in"`` (a bare
    number is millimetres): its value in millimetres and the unit it was written in.

    Raises
    ------
    ParameterError
        Not a positive number with one of the units of :data:`CUT_FILE_UNITS`.
    """
    if isinstance(size, bool) or not isinstance(size, str | int | float):
        raise ParameterError(f"size must be a length such as '300mm', got {size!r}", name="size")
    m = _SIZE.fullmatch(str(size))
    value = float(m.group(1)) if m else float("nan")
    if not (m and math.isfinite(value) and value > 0):
        raise ParameterError(
            f"size must be a positive length with a unit of {', '.join(CUT_FILE_UNITS)} "
            f"(e.g. '300mm'), got {size!r}",
            name="size",
        )
    unit = m.group(2) or "mm"
    return value * MM_PER_UNIT[unit], unit


def ceil_digits(x: float, digits: int = 2) -> float:
    """``x`` > 0 rounded up to ``digits`` significant digits (``ceil_digits(614.2) == 620``):
    a size a person can state."""
    step = 10.0 ** (math.floor(math.log10(x)) - digits + 1)
    return math.ceil(round(x / step, 9)) * step
