"""JSON encoding of design reports (numpy-aware, NaN-safe, deterministic).

Long lists of records (one dict per vertex or per edge) are written column by column, each
column's values formatted at once (see :class:`Records`), not record by record.
"""

from __future__ import annotations

import dataclasses
import enum
import functools
import itertools
import json
import math
import operator
from collections.abc import Mapping, Sequence
from json.encoder import encode_basestring_ascii as _quote
from pathlib import PurePath

import numpy as np

from ..errors import ExportError

__all__ = ["Records", "report_json", "to_json_data"]


class Records:
    """A list of records (dicts with string keys) held as one column per key.

    The JSON form of a :class:`Records` is the list of its records (:meth:`dicts`);
    :func:`report_json` writes it a column at a time.

    Parameters
    ----------
    columns : mapping of str to sequence
        At least one key; key -> (n,) the key's value in every record, keys in the records'
        order. A numpy array (n,) or (n, k) gives each record a number or a row.
    present : mapping of str to (n,) bool, optional
        Key -> whether each record has the key (default: every record has every key); where a
        record has not, its value in ``columns`` is not written (None is a good filler).
    nulls : mapping of str to (n,) bool, optional
        Key -> whether each record's value is None instead of its value in ``columns``.

    Raises
    ------
    ExportError
        When there is no column, a mask names no column, or lengths differ.
    """

    __slots__ = ("columns", "nulls", "present")

    def __init__(
        self,
        columns: Mapping[str, Sequence],
        present: Mapping | None = None,
        nulls: Mapping | None = None,
    ):
        self.columns = dict(columns)
        self.present = {k: np.asarray(v, dtype=bool) for k, v in (present or {}).items()}
        self.nulls = {k: np.asarray(v, dtype=bool) for k, v in (nulls or {}).items()}
        masks = {**self.present, **self.nulls}
        sizes = set(map(len, itertools.chain(self.columns.values(), masks.values())))
        if not self.columns or len(sizes) != 1 or not set(masks) <= set(self.columns):
            raise ExportError("records need at least one column, all of one length")

    def __len__(self) -> int:
        return len(next(iter(self.columns.values())))

    def column(self, key: str) -> list:
        """The values of ``key`` as the records hold them (rows of an array as lists, None
        where :attr:`nulls` says so), for every record, whether it has the key or not."""
        values = self.columns[key]
        values = values.tolist() if isinstance(values, np.ndarray) else list(values)
        if key in self.nulls:
            for i in np.flatnonzero(self.nulls[key]).tolist():
                values[i] = None
        return values

    def dicts(self) -> list[dict]:
        """The records as dicts, each with the keys it has, in column order.

        Returns
        -------
        list of dict
        """
        keys = list(self.columns)
        rows = zip(*map(self.column, keys), strict=True)
        if not self.present:
            return [dict(zip(keys, row, strict=True)) for row in rows]
        every = [True] * len(self)
        has = zip(
            *(self.present[k].tolist() if k in self.present else every for k in keys), strict=True
        )
        return [
            {k: v for k, v, h in zip(keys, row, flags, strict=True) if h}
            for row, flags in zip(rows, has, strict=True)
        ]

    @classmethod
    def from_dicts(cls, items: Sequence) -> Records | None:
        """The records of dicts whose string keys come in one common order (each dict may
        lack some keys); None for anything else (no dict, no key, keys in clashing orders).

        Parameters
        ----------
        items : sequence of dict

        Returns
        -------
        Records or None
        """
        if not items or set(map(type, items)) != {dict}:
            return None
        orders = set(map(tuple, items))
        keys = list(dict.fromkeys(itertools.chain.from_iterable(sorted(orders, key=len)[::-1])))
        position = {k: i for i, k in enumerate(keys)}
        for order in orders:
            if {type(k) for k in order} - {str}:
                return None
            at = [position[k] for k in order]
            if at != sorted(at):
                return None
        if not keys:
            return None
        every = set.intersection(*map(set, orders))
        columns = {k: [d.get(k) for d in items] for k in keys}
        present = {k: [k in d for d in items] for k in keys if k not in every}
        return cls(columns, present)


def _numeric_array(obj) -> bool:
    """Whether ``obj`` is a numpy array of numbers or booleans, 1-D or 2-D (written in bulk)."""
    return isinstance(obj, np.ndarray) and obj.ndim in (1, 2) and obj.dtype.kind in "biuf"


def to_json_data(obj, where: str = ""):
    """A JSON-ready copy of ``obj``.

    numpy arrays become (nested) lists, numpy scalars Python numbers, NaN and infinities
    ``None``; mappings keep their key order (keys become strings: numbers and booleans as JSON
    writes them); tuples become lists, sets sorted lists; dataclasses become dicts of their
    fields; paths become strings; enums their value; :class:`Records` lists of dicts.

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
    return _data(obj, where, records=False)


def python_scalar(obj):
    """``obj`` with a numpy scalar made the Python one, and an ``int`` subclass (an ``IntEnum``,
    say) a plain ``int``; anything else as it is."""
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, int) and not isinstance(obj, bool):
        return int(obj)
    return obj


def _data(obj, where: str, records: bool):
    """:func:`to_json_data`; with ``records``, lists of dicts and :class:`Records` become
    :class:`Records` of JSON data (what :func:`_indented` writes a column at a time)."""
    if isinstance(obj, Records):
        return _records_data(obj, where) if records else _data(obj.dicts(), where, False)
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind not in "biufUSO":
            raise ExportError(f"report value at {where or 'top level'} is a {obj.dtype} array")
        if records and _numeric_array(obj):
            return obj
        obj = obj.tolist()
    obj = python_scalar(obj)
    if obj is None or isinstance(obj, bool | str | int):
        return obj
    if isinstance(obj, float):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, enum.Enum):
        return _data(obj.value, where, records)
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
            out[key] = _data(v, f"{where}.{key}" if where else key, records)
        return out
    if isinstance(obj, list | tuple):
        if records:
            table = Records.from_dicts(obj)
            if table is not None:
                return _records_data(table, where)
            if _ragged(obj):
                return list(obj)
        fast = _plain_list(obj)
        if fast is not None:
            return fast
        return [_data(v, f"{where}[{i}]", records) for i, v in enumerate(obj)]
    if isinstance(obj, set | frozenset):
        items = [_data(v, f"{where}{{}}", records) for v in obj]
        try:
            return sorted(items)
        except TypeError:
            raise ExportError(f"report set at {where or 'top level'} mixes types") from None
    raise ExportError(
        f"report value at {where or 'top level'} has no JSON form ({type(obj).__name__})"
    )


def _records_data(table: Records, where: str) -> Records:
    """:class:`Records` of the JSON data of each column (see :func:`_data`), a column at a time
    where :func:`_plain_list` takes it."""
    columns = {}
    for key, values in table.columns.items():
        if isinstance(values, np.ndarray):
            columns[key] = _data(values, f"{where}.{key}", True)
            continue
        fast = _plain_list(values)
        columns[key] = (
            fast
            if fast is not None
            else [_data(v, f"{where}[{i}].{key}", True) for i, v in enumerate(values)]
        )
    return Records(columns, table.present, table.nulls)


def _ragged(items) -> bool:
    """Whether ``items`` are 1-D numpy arrays of numbers of one kind (rows of several lengths,
    such as polygons, written in bulk)."""
    if not items or set(map(type, items)) != {np.ndarray}:
        return False
    kinds = {d.kind for d in set(map(operator.attrgetter("dtype"), items))}
    return (
        set(map(operator.attrgetter("ndim"), items)) == {1}
        and len(kinds) == 1
        and kinds <= set("biuf")
    )


#: Exact types :func:`to_json_data` passes through unchanged.
_AS_IS = frozenset({int, str, bool, type(None)})


def _plain_list(items) -> list | None:
    """:func:`to_json_data` of a list or tuple of numbers, strings, booleans and None, or of
    lists (and None) of those, all at once; None for anything else."""
    kinds = set(map(type, items))
    if kinds <= _AS_IS:
        return list(items)
    if kinds <= _AS_IS | {float}:
        return [v if type(v) is not float or math.isfinite(v) else None for v in items]
    if kinds <= {list, tuple, type(None)}:
        inner = set(map(type, itertools.chain.from_iterable(filter(None, items))))
        if inner <= _AS_IS:
            return [None if v is None else list(v) for v in items]
        if inner <= _AS_IS | {float}:
            return [
                None
                if v is None
                else [x if type(x) is not float or math.isfinite(x) else None for x in v]
                for v in items
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
        dataclasses, :class:`Records` (see :func:`to_json_data`).

    Returns
    -------
    str
        ``json.dumps(to_json_data(report), indent=2)``: indented by 2, keys in the report's
        order, NaN and infinities as ``null``, ASCII, ending with a newline.

    Raises
    ------
    ExportError
        When a value has no JSON form.
    """
    return _indented(_data(report, "", records=True), "\n") + "\n"


def _indented(obj, newline: str) -> str:
    """``json.dumps(obj, indent=2, allow_nan=False)`` of JSON data (dicts with string keys,
    lists, strings, numbers, booleans, None; also :class:`Records`, and numpy arrays and lists
    of arrays as :func:`to_json_data` writes them), the items of a list written together (see
    :func:`_item_texts`); ``newline`` is a newline and the indentation of ``obj``'s line."""
    inner = newline + "  "
    if isinstance(obj, dict):
        if not obj:
            return "{}"
        parts = ["{"]
        for k, v in obj.items():
            parts += (inner, _quote(k), ": ", _indented(v, inner), ",")
        parts[-1] = newline + "}"
        return "".join(parts)
    if isinstance(obj, list | Records | np.ndarray):
        if not len(obj):
            return "[]"
        items = _item_texts(obj, inner)
        items[0] = "[" + inner + items[0]  # brackets on the items: the text is copied once
        items[-1] += newline + "]"
        return ("," + inner).join(items)
    kind = type(obj)
    if kind is str:
        return _quote(obj)
    if kind is int or (kind is float and math.isfinite(obj)):
        return repr(obj)
    return json.dumps(obj, allow_nan=False)


def _item_texts(items, newline: str) -> list[str]:
    """:func:`_indented` of every item of a list (record of a :class:`Records`, row of an
    array) at ``newline``: lists of numbers, strings and None, lists of such lists, arrays and
    lists of 1-D arrays in bulk; lists of dicts a column at a time."""
    if isinstance(items, Records):
        return _record_texts(items, newline)
    if isinstance(items, np.ndarray):
        if items.ndim == 1:
            return _number_texts(items)
        return _row_texts(_number_texts(items.ravel()), [items.shape[1]] * len(items), newline)
    kinds = set(map(type, items))
    texts = None
    if kinds <= _SCALARS:
        texts = _scalar_texts(items, kinds)
    elif kinds <= {list, type(None)}:
        texts = _list_texts(items, newline)
    elif kinds == {np.ndarray} and _ragged(items):
        values = _number_texts(np.concatenate(items))
        texts = _row_texts(values, list(map(len, items)), newline)
    elif kinds == {dict}:
        table = Records.from_dicts(items)
        texts = None if table is None else _record_texts(table, newline)
    if texts is None:
        texts = [_indented(v, newline) for v in items]
    return texts


#: Exact types of JSON scalars.
_SCALARS = frozenset({int, float, str, bool, type(None)})
#: JSON text of the values whose ``repr`` is not it.
_LITERALS = {"None": "null", "True": "true", "False": "false"}
#: ``repr`` of the floats JSON has no text for.
_NON_FINITE = frozenset({"nan", "inf", "-inf"})


def _scalar_texts(items: list, kinds: set) -> list[str] | None:
    """JSON text of every item of a list of scalars (``kinds``: the items' types): strings
    (with None) quoted, numbers (with None and booleans) as ``repr``; None when strings and
    numbers mix.

    Raises
    ------
    ValueError
        For a NaN or infinite float, as ``json.dumps(allow_nan=False)``.
    """
    if str in kinds:
        if not kinds <= {str, type(None)}:
            return None
        quoted = {v: "null" if v is None else _quote(v) for v in set(items)}
        return list(map(quoted.__getitem__, items))
    if float in kinds and kinds <= {float, type(None)}:
        x = np.array(items, dtype=np.float64)  # None: NaN, written null
        if np.count_nonzero(~np.isfinite(x)) != items.count(None):
            _raise_non_finite(items)
        return _number_texts(x)
    texts = list(map(repr, items))
    if kinds & {bool, type(None)}:
        texts = list(map(_LITERALS.get, texts, texts))
    if float in kinds and not _NON_FINITE.isdisjoint(texts):
        _raise_non_finite(items)
    return texts


def _raise_non_finite(items: list) -> None:
    """Raise ``json.dumps``'s ValueError for the first NaN or infinite float of ``items``."""
    json.dumps(next(v for v in items if type(v) is float and not math.isfinite(v)), allow_nan=False)


def _number_texts(x: np.ndarray) -> list[str]:
    """JSON text of every value of a 1-D numeric array, as :func:`to_json_data` and JSON
    write it: ``repr``, ``null`` for NaN and infinities, ``true``/``false``; floats formatted
    once per distinct value when values repeat (see :func:`_distinct_floats`)."""
    if x.dtype.kind == "b":
        return np.where(x, "true", "false").tolist()
    if x.dtype.kind != "f":
        return list(map(repr, x.tolist()))
    repeated = _distinct_floats(x)
    if repeated is None:
        texts = list(map(repr, x.tolist()))
        for i in np.flatnonzero(~np.isfinite(x)).tolist():
            texts[i] = "null"
        return texts
    value, at = repeated
    distinct = np.array(list(map(repr, value.tolist())), dtype=object)
    distinct[~np.isfinite(value)] = "null"
    return distinct[at].tolist()


#: Values :func:`_distinct_floats` looks at first to judge whether an array's values repeat.
_SAMPLE = 1 << 15


def _distinct_floats(x: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The distinct values of a float array and where each value is among them, when the
    values repeat enough for formatting only the distinct ones to pay; None otherwise.

    Parameters
    ----------
    x : (n,) float

    Returns
    -------
    distinct : (d,) float
        Told apart by their bits (``-0.0`` is not ``0.0``), ``2 d <= n``.
    at : (n,) int
        ``x == distinct[at]`` bit for bit.
    None
        When the values are mostly distinct (judged on a sample of :data:`_SAMPLE` values of a
        longer array, then on all).
    """
    bits = np.ascontiguousarray(x, dtype=np.float64).view(np.int64)
    sample = bits[:: max(1, len(bits) // _SAMPLE)]
    if len(sample) < len(bits) and 10 * len(np.unique(sample)) > 9 * len(sample):
        return None
    distinct, at = np.unique(bits, return_inverse=True)
    if 2 * len(distinct) > len(bits):
        return None
    return distinct.view(np.float64), at.ravel()


@functools.cache
def _row_template(size: int, newline: str) -> str:
    """``%`` template of a list of ``size`` items on their own lines (``newline``: its line)."""
    if size == 0:
        return "[]"
    inner = newline + "  "
    return "[" + inner + ("%s," + inner) * (size - 1) + "%s" + newline + "]"


def _row_texts(values: list[str], sizes: list[int], newline: str) -> list[str]:
    """The texts of lists (at ``newline``) of ``sizes`` items each, the items' texts
    ``values`` one list after the other."""
    if not sizes:
        return []
    template = {k: _row_template(k, newline) for k in set(sizes)}
    # one template for every row, split at NUL (never in JSON text: json escapes it)
    return ("\0".join(map(template.__getitem__, sizes)) % tuple(values)).split("\0")


def _list_texts(rows: list, newline: str) -> list[str] | None:
    """:func:`_indented` of every item of a list of lists of scalars and None; None when the
    rows' items mix numbers and strings, or are not all scalars."""
    full = [r for r in rows if r is not None]
    flat = list(itertools.chain.from_iterable(full))
    kinds = set(map(type, flat))
    values = _scalar_texts(flat, kinds) if kinds <= _SCALARS else None
    if values is None:
        return None
    texts = _row_texts(values, list(map(len, full)), newline)
    if len(full) < len(rows):
        it = iter(texts)
        texts = ["null" if r is None else next(it) for r in rows]
    return texts


def _record_texts(table: Records, newline: str) -> list[str]:
    """:func:`_indented` of every record of a :class:`Records` of JSON data, its columns
    formatted one at a time (``newline``: the records' line)."""
    inner = newline + "  "
    columns = []
    for key, values in table.columns.items():
        texts = _item_texts(values, inner)
        if key in table.nulls:
            texts = _masked(texts, table.nulls[key], "null")
        head = inner + _quote(key) + ": "
        texts = list(map(head.__add__, texts))
        if key in table.present:  # a record without the key: no text (dropped below)
            texts = _masked(texts, ~table.present[key], "")
        columns.append(texts)
    bodies = map(",".join, map(functools.partial(filter, None), zip(*columns, strict=True)))
    return ["{" + b + newline + "}" if b else "{}" for b in bodies]


def _masked(texts: list[str], mask: np.ndarray, text: str) -> list[str]:
    """``texts`` with ``text`` where ``mask`` (bool, same length) is true."""
    if not mask.any():
        return texts
    out = np.array(texts, dtype=object)
    out[mask] = text
    return out.tolist()
