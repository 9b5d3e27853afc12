"""JSON encoding of design reports (numpy-aware, NaN-safe, deterministic)."""

from __future__ import annotations

import dataclasses
import enum
import itertools
import json
import math
from collections.abc import Mapping
from json.encoder import encode_basestring_ascii as _quote
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
        fast = _plain_dict(obj)
        if fast is not None:
            return fast
        out = {}
        for k, v in obj.items():
            key = _key(k, where)
            out[key] = to_json_data(v, f"{where}.{key}" if where else key)
        return out
    if isinstance(obj, list | tuple):
        fast = _plain_list(obj)
        if fast is not None:
            return fast
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


#: Exact types :func:`to_json_data` passes through unchanged.
_AS_IS = frozenset({int, str, bool, type(None)})


def _plain_list(items) -> list | None:
    """:func:`to_json_data` of a list or tuple of numbers, strings, booleans and None, or of
    lists of those, all at once; None for anything else."""
    kinds = set(map(type, items))
    if kinds <= _AS_IS:
        return list(items)
    if kinds <= _AS_IS | {float}:
        return [v if type(v) is not float or math.isfinite(v) else None for v in items]
    if kinds <= {list, tuple}:
        inner = set(map(type, itertools.chain.from_iterable(items)))
        if inner <= _AS_IS:
            return [list(v) for v in items]
        if inner <= _AS_IS | {float}:
            return [
                [x if type(x) is not float or math.isfinite(x) else None for x in v] for v in items
            ]
    return None


def _plain_dict(obj: Mapping) -> dict | None:
    """:func:`to_json_data` of a dict with string keys whose values are numbers, strings,
    booleans, None, or lists that :func:`_plain_list` takes, all at once; None for anything
    else (the records of a report: one dict per vertex or edge)."""
    if type(obj) is not dict or not set(map(type, obj)) <= {str}:
        return None
    out = {}
    for k, v in obj.items():
        kind = type(v)
        if kind in _AS_IS:
            out[k] = v
        elif kind is float:
            out[k] = v if math.isfinite(v) else None
        elif kind is list:
            v = _plain_list(v)
            if v is None:
                return None
            out[k] = v
        else:
            return None
    return out


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
    return _indented(to_json_data(report), "\n") + "\n"


#: Exact types whose JSON text is their ``repr`` (finite floats only, see :func:`_indented`).
_REPR_TYPES = frozenset({int, float})


def _indented(obj, newline: str) -> str:
    """``json.dumps(obj, indent=2, allow_nan=False)`` of JSON data (dicts with string keys,
    lists, strings, numbers, booleans, None), with lists of numbers or strings written in one
    go; ``newline`` is a newline and the indentation of ``obj``'s line."""
    inner = newline + "  "
    if isinstance(obj, dict):
        if not obj:
            return "{}"
        items = [_quote(k) + ": " + _indented(v, inner) for k, v in obj.items()]
        return "{" + inner + ("," + inner).join(items) + newline + "}"
    if isinstance(obj, list):
        if not obj:
            return "[]"
        kinds = set(map(type, obj))
        if kinds <= _REPR_TYPES and (float not in kinds or all(map(math.isfinite, obj))):
            items = map(repr, obj)
        elif kinds == {str}:
            items = map(_quote, obj)
        else:
            items = (_indented(v, inner) for v in obj)
        return "[" + inner + ("," + inner).join(items) + newline + "]"
    kind = type(obj)
    if kind is str:
        return _quote(obj)
    if kind is int or (kind is float and math.isfinite(obj)):
        return repr(obj)
    return json.dumps(obj, allow_nan=False)
