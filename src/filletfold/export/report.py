"""JSON encoding of design reports (numpy-aware, NaN-safe, deterministic)."""

from __future__ import annotations

import dataclasses
import enum
import json
import math
from collections.abc import Mapping
from pathlib import PurePath

import numpy as np

from ..errors import ExportError

__all__ = ["report_json", "to_json_data"]


def to_json_data(obj, where: str = ""):
    """A JSON-ready copy of ``obj``.

    numpy arrays become (nested) lists, numpy scalars Python numbers, NaN and infinities
    ``None``; mappings keep their key order (keys become strings: numbers and booleans as JSON
    writes them); tuples become lists, sets sorted lists; dataclasses become dicts of their
    fields; paths become strings; enums their value.

    Parameters
    ----------
    obj : object
    where : str
        Location of ``obj`` in the report, for error messages.

    Returns
    -------
    object
        Built from dict, list, str, int, float, bool and None only.

    Raises
    ------
    ExportError
        When a value has no JSON form (complex numbers, arbitrary objects...).
    """
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind not in "biufUSO":
            raise ExportError(f"report value at {where or 'top level'} is a {obj.dtype} array")
        obj = obj.tolist()
    elif isinstance(obj, np.generic):
        obj = obj.item()
    if obj is None or isinstance(obj, bool | str):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, enum.Enum):
        return to_json_data(obj.value, where)
    if isinstance(obj, PurePath):
        return str(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        obj = {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}
    if isinstance(obj, Mapping):
        out = {}
        for k, v in obj.items():
            key = _key(k, where)
            out[key] = to_json_data(v, f"{where}.{key}" if where else key)
        return out
    if isinstance(obj, list | tuple):
        return [to_json_data(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, set | frozenset):
        items = [to_json_data(v, f"{where}{{}}") for v in obj]
        try:
            return sorted(items)
        except TypeError:
            raise ExportError(f"report set at {where or 'top level'} mixes types") from None
    raise ExportError(
        f"report value at {where or 'top level'} has no JSON form ({type(obj).__name__})"
    )


def _key(k, where: str) -> str:
    """A mapping key as JSON writes it."""
    if isinstance(k, np.generic):
        k = k.item()
    if isinstance(k, str):
        return k
    if k is None or isinstance(k, bool | int | float):
        return json.dumps(k if not isinstance(k, float) or math.isfinite(k) else None)
    if isinstance(k, enum.Enum):
        return str(k.value)
    raise ExportError(f"report key {k!r} at {where or 'top level'} is not a string or number")


def report_json(report: Mapping) -> str:
    """Encode a report as JSON text.

    Parameters
    ----------
    report : mapping
        Any nesting of mappings, sequences, numbers, strings, numpy arrays and scalars,
        dataclasses (see :func:`to_json_data`).

    Returns
    -------
    str
        Indented by 2, keys in the report's order, NaN and infinities as ``null``, ASCII,
        ending with a newline.

    Raises
    ------
    ExportError
        When a value has no JSON form.
    """
    return json.dumps(to_json_data(report), indent=2, allow_nan=False) + "\n"
