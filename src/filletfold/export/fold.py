"""FOLD 1.2 export of a crease pattern and its folded form.

The key frame (top level) is the flat crease pattern in 2D; ``file_frames[0]`` is the folded
form, inheriting everything from the key frame except its 3D ``vertices_coords``. Spec:
https://github.com/edemaine/fold/blob/main/doc/spec.md

Also home of :func:`validate_pattern`, the entry check every exporter runs on a
:class:`~filletfold.surface.pattern.CreasePattern`.
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Iterator, Mapping
from json.encoder import encode_basestring_ascii as _quote

import numpy as np

from ..arrays import run_owners, run_starts, split_runs
from ..errors import ExportError, ParameterError
from ..surface.pattern import Annotations, CreasePattern, LabelRows, edge_dihedrals, face_arrays
from ..surface.validate import validated_faces
from .paths import point_rows
from .report import python_scalar

__all__ = [
    "ANNOTATIONS_FILE",
    "FOLD_ANGLE_DECIMALS",
    "FOLD_DIGITS",
    "FOLD_SPEC",
    "NAMESPACE",
    "annotations_document",
    "annotations_json",
    "design_counts",
    "face_arrays",
    "file_creator",
    "fold_document",
    "fold_json",
    "fold_json_chunks",
    "has_annotations",
]

#: FOLD specification version written to ``file_spec``.
FOLD_SPEC = 1.2
#: Prefix of filletfold's custom FOLD keys.
NAMESPACE = "filletfold:"
#: The file beside ``design.fold`` that holds its cut-file annotations (tabs, tab hinges,
#: labels, sheets): FOLD readers have no use for them, and on a large design of modules they
#: are a third of the file (see :func:`annotations_json`).
ANNOTATIONS_FILE = "annotations.json"
#: Significant digits kept for floats in :func:`fold_json`.
FOLD_DIGITS = 12
#: Decimals of ``edges_foldAngle`` on ``F`` edges (degrees): a 1e-9 degree grid, the 12th
#: significant digit of an angle over 100 degrees (the folded coordinates' own rounding moves
#: such a measured dihedral more). M and V angles keep :data:`FOLD_DIGITS`.
FOLD_ANGLE_DECIMALS = 9


def file_creator() -> str:
    """``"filletfold <version>"`` or ``"filletfold"`` when the package has no version."""
    import filletfold

    version = getattr(filletfold, "__version__", None)
    return f"filletfold {version}" if version else "filletfold"


def fold_document(
    pattern: CreasePattern,
    *,
    title: str = "",
    description: str = "",
    extra: Mapping | None = None,
    annotations: bool = True,
) -> dict:
    """The FOLD 1.2 document of a crease pattern.

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`validate_pattern`.
    title, description : str
        ``file_title`` and ``file_description``.
    extra : mapping, optional
        More top-level keys, each namespaced ``"filletfold:..."``; values must be JSON data
        (numpy arrays and scalars are accepted by :func:`fold_json`).
    annotations : bool
        Whether the document holds the pattern's tabs, labels and sheets (the key
        ``filletfold:annotations``); ``design.fold`` does not: they go to
        :data:`ANNOTATIONS_FILE` (:func:`annotations_json`).

    Returns
    -------
    dict
        Keys in a fixed order: file metadata, key-frame metadata, ``vertices_coords`` (n, 2),
        ``edges_vertices`` (m, 2), ``edges_assignment`` (m,), ``edges_foldAngle`` (m,) degrees
        (valley positive; ``null`` on borders, the folded form's dihedral on ``F`` edges, see
        :func:`~filletfold.surface.pattern.edge_dihedrals`, rounded to
        :data:`FOLD_ANGLE_DECIMALS`), ``faces_vertices``
        (counter-clockwise),
        ``filletfold:faces_patch`` and ``filletfold:faces_piece`` (n_faces,),
        ``filletfold:pieces_vertex`` (n_pieces,),
        ``file_frames`` (the folded form: a child of the key frame with 3D ``vertices_coords``
        (n, 3)), ``filletfold:annotations`` when the pattern has any and ``annotations`` (see
        :func:`annotations_document`), then ``extra``.

    Raises
    ------
    ExportError
        When the pattern is inconsistent (see :func:`validate_pattern`).
    ParameterError
        When ``title``/``description`` are not strings or an ``extra`` key is not namespaced or
        clashes with a key of the document.
    """
    return _fold_document(
        pattern,
        validated_faces(pattern),
        title=title,
        description=description,
        extra=extra,
        annotations=annotations,
    )


def _fold_document(
    pattern: CreasePattern,
    faces: tuple[np.ndarray, np.ndarray],
    *,
    title: str = "",
    description: str = "",
    extra: Mapping | None = None,
    arrays: bool = False,
    annotations: bool = True,
) -> dict:
    """:func:`fold_document` of a pattern already checked (``faces`` from
    :func:`validated_faces`); with ``arrays`` the numbers stay numpy arrays (and the faces
    :class:`_RaggedInts`): the same text from :func:`fold_json`, without lists in between;
    without ``annotations`` the document has no ``filletfold:annotations`` (the files keep
    them in :data:`ANNOTATIONS_FILE`)."""
    for name, value in (("title", title), ("description", description)):
        if not isinstance(value, str):
            raise ParameterError(f"{name} must be a string, got {type(value).__name__}", name=name)
    flat, start = faces

    def as_data(x: np.ndarray):
        return x if arrays else x.tolist()

    if arrays:
        faces_vertices = _RaggedInts(flat, start)
    else:
        flat_list = flat.tolist()
        faces_vertices = list(map(flat_list.__getitem__, map(slice, start[:-1], start[1:])))

    doc = {
        "file_spec": FOLD_SPEC,
        "file_creator": file_creator(),
        "file_title": title,
        "file_description": description,
        "file_classes": ["singleModel"],
        "frame_classes": ["creasePattern"],
        "frame_attributes": ["2D"],
        "frame_unit": "unit",
        "vertices_coords": as_data(pattern.vertices_2d),
        "edges_vertices": as_data(np.asarray(pattern.edges, dtype=np.int64)),
        "edges_assignment": _assignment_data(pattern.edge_assignment, arrays),
        "edges_foldAngle": _fold_angle_data(pattern, arrays),
        "faces_vertices": faces_vertices,
        NAMESPACE + "faces_patch": list(map(str, pattern.face_patch)),
        NAMESPACE + "faces_piece": as_data(pattern.face_piece),
        NAMESPACE + "pieces_vertex": as_data(pattern.piece_vertex),
        "file_frames": [
            {
                "frame_classes": ["foldedForm"],
                "frame_parent": 0,
                "frame_inherit": True,
                "frame_attributes": ["3D"],
                "vertices_coords": as_data(pattern.vertices_3d),
            }
        ],
    }
    if annotations and has_annotations(pattern.annotations):
        doc[NAMESPACE + "annotations"] = (
            _annotations_data(pattern.annotations)
            if arrays
            else annotations_document(pattern.annotations)
        )
    for key, value in (extra or {}).items():
        if not isinstance(key, str) or not key.startswith(NAMESPACE) or key == NAMESPACE:
            raise ParameterError(
                f"extra FOLD key {key!r} must be namespaced as '{NAMESPACE}<name>'", name="extra"
            )
        if key in doc:
            raise ParameterError(
                f"extra FOLD key {key!r} clashes with a built-in key", name="extra"
            )
        doc[key] = value
    return doc


def _fold_angle_data(pattern: CreasePattern, raw: bool) -> list | _Raw:
    """``edges_foldAngle``: M and V edges as the pattern has them, F edges the folded form's
    dihedral (:func:`~filletfold.surface.pattern.edge_dihedrals`) rounded to
    :data:`FOLD_ANGLE_DECIMALS`, B edges ``null``;
    a list, or with ``raw`` JSON text."""
    angle = np.asarray(pattern.edge_fold_angle, dtype=np.float64).copy()
    assign = np.asarray(pattern.edge_assignment, dtype=str)
    flat = assign == "F"
    if flat.any():
        angle[flat] = edge_dihedrals(pattern)[flat]
    border = assign == "B"
    angle[border] = 0.0
    if not np.isfinite(angle).all():
        bad = int(np.nonzero(~np.isfinite(angle))[0][0])
        raise ExportError(f"pattern edge {bad} has no finite fold angle")
    # the facets' dihedrals are measured on the folded form, its crease angles are the design's
    angle[flat] = np.round(angle[flat], FOLD_ANGLE_DECIMALS)
    if not raw:
        items: list = angle.tolist()
        for e in np.nonzero(border)[0].tolist():
            items[e] = None
        return items
    if len(angle) == 0:
        return _Raw("[]")
    texts = _item_texts(angle)
    for e in np.nonzero(border)[0].tolist():
        texts[e] = "null"
    return _Raw("[" + ",".join(texts) + "]")


def _assignment_data(assignment, raw: bool) -> list | _Raw:
    """The assignments (checked to be ``M V B F``) as a list, or with ``raw`` as JSON text."""
    items = np.asarray(assignment, dtype=str).tolist()
    if not raw:
        return items
    return _Raw('["' + '","'.join(items) + '"]' if items else "[]")


def has_annotations(annotations: Annotations) -> bool:
    """Whether there is any tab, hinge, label or sheet to write."""
    return bool(
        len(annotations.tabs)
        or len(annotations.tab_hinges)
        or len(annotations.labels)
        or len(np.asarray(annotations.sheets).reshape(-1))
    )


def _annotation_arrays(annotations: Annotations) -> dict:
    """The annotations' numbers as arrays (see :func:`annotations_document`):
    ``tab_points`` (k, 2) and ``tab_size`` (n_tabs,), ``hinges`` (n_hinges, 2, 2),
    ``position`` (n_labels, 2), ``angle`` and ``height`` (n_labels,), ``sheets`` (n_sheets, 4).

    Raises
    ------
    TypeError, ValueError
        When a value is malformed (a hinge that is not 2 points, a label angle that is not a
        number, ...).
    """
    labels = LabelRows.of(annotations.labels)
    tab_points, tab_size = point_rows(annotations.tabs)
    hinge_points, hinge_size = point_rows(annotations.tab_hinges)
    if (hinge_size != 2).any():  # each hinge is read as reshape(2, 2): its error
        for h in annotations.tab_hinges:
            np.asarray(h, dtype=np.float64).reshape(2, 2)
    sheets = np.asarray(annotations.sheets, dtype=np.float64).reshape(-1, 4)
    return {
        "tab_points": tab_points,
        "tab_size": tab_size,
        "hinges": hinge_points.reshape(-1, 2, 2),
        "position": labels.position,
        "angle": labels.angle,
        "height": labels.height,
        "text": list(map(str, labels.text)),
        "kind": list(map(str, labels.kind)),
        "sheets": sheets,
    }


def _check_labels(numbers: dict) -> None:
    """Name the first label number that is not finite (the labels are written a column at a
    time, so the writer alone would name the column, not the label)."""
    for name in ("position", "angle", "height"):
        values = numbers[name].reshape(len(numbers["angle"]), 2 if name == "position" else 1)
        bad = np.argwhere(~np.isfinite(values))
        if len(bad):
            i, j = bad[0].tolist()
            where = f"{name}[{j}]" if name == "position" else name
            raise ExportError(
                f"FOLD value at {NAMESPACE}annotations.labels[{i}].{where} is not finite "
                f"({values[i, j]})"
            )


def hinge_refs(tab_points: np.ndarray, tab_size: np.ndarray, hinges: np.ndarray) -> np.ndarray:
    """For each hinge, the two points of its tab's outline it joins, when both are there.

    Parameters
    ----------
    tab_points : (k, 2) float
        The tab outlines' points, one outline after the other.
    tab_size : (n_tabs,) int
        Points of each outline.
    hinges : (n_hinges, 2, 2) float
        Hinge ``i`` belongs to tab ``i``.

    Returns
    -------
    (n_hinges, 2) int
        The index (within its outline) of the first outline point equal to each end of hinge
        ``i`` (bit for bit), or ``-1`` when there is none (or no tab ``i``).
    """
    n = len(hinges)
    out = np.full((n, 2), -1, dtype=np.int64)
    m = min(n, len(tab_size))
    if m == 0:
        return out
    size = np.asarray(tab_size[:m], dtype=np.int64)
    first = run_starts(size)[:-1]
    owner = run_owners(size)
    local = np.arange(int(size.sum())) - np.repeat(first, size)
    pts = tab_points[: int(size.sum())]
    for end in (0, 1):
        hit = np.flatnonzero((pts == hinges[owner, end]).all(axis=1))
        # the first hit of each tab: hits are in order, so the first of each owner
        tab, at = np.unique(owner[hit], return_index=True)
        out[tab, end] = local[hit[at]]
    return out


def _hinge_items(a: dict) -> list:
    """``tab_hinges`` of the annotations' JSON: each hinge as ``[i, j]``, the indices of the
    two points of its tab's outline it joins (the hinge is the outline's side on the piece's
    border), or as its two points ``[[x, y], [x, y]]`` when they are not both on its
    outline."""
    refs = hinge_refs(a["tab_points"], a["tab_size"], a["hinges"])
    found = (refs >= 0).all(axis=1)
    return [refs[k].tolist() if found[k] else a["hinges"][k].tolist() for k in range(len(refs))]


def annotations_document(annotations: Annotations) -> dict:
    """The JSON form of a pattern's annotations (the ``filletfold:annotations`` FOLD key).

    Parameters
    ----------
    annotations : Annotations

    Returns
    -------
    dict
        ``tabs``: list of tab outlines, each a list of ``[x, y]``; ``tab_hinges``: one item
        per tab, ``[i, j]`` (the indices of the two points of the tab's outline the hinge
        joins: the hinge is not written twice) or, for a hinge whose ends are not both points
        of its outline, ``[[x, y], [x, y]]``; ``labels``: the labels as parallel lists (one
        item per label), ``{"position": [[x, y], ...], "text": [...], "angle": [...]
        (degrees), "height": [...], "kind": [...]}``; ``sheets``: list of
        ``[xmin, ymin, xmax, ymax]``. All in pattern coordinates (written by
        :func:`fold_json` to :data:`FOLD_DIGITS`, as the pattern's points: a tab's base stays
        on its piece's border).

    Raises
    ------
    ExportError
        When a label's position, angle or height is not finite (naming the label).
    TypeError, ValueError
        When a value is malformed.
    """
    a = _annotation_arrays(annotations)
    _check_labels(a)
    sizes = a["tab_size"]
    tabs = split_runs(a["tab_points"], np.cumsum(sizes)[:-1]) if len(sizes) else []
    return {
        "tabs": [t.tolist() for t in tabs],
        "tab_hinges": _hinge_items(a),
        "labels": {
            "position": a["position"].tolist(),
            "text": a["text"],
            "angle": a["angle"].tolist(),
            "height": a["height"].tolist(),
            "kind": a["kind"],
        },
        "sheets": a["sheets"].tolist(),
    }


def _annotations_data(annotations: Annotations) -> dict:
    """:func:`annotations_document` for :func:`fold_json`, its numbers formatted in bulk as
    :class:`_Raw` text.

    When a number is not finite, the plain document instead, for :func:`_plain` (or
    :func:`annotations_document` itself) to name it.
    """
    a = _annotation_arrays(annotations)
    numbers = ("tab_points", "hinges", "position", "angle", "height", "sheets")
    if not all(np.isfinite(a[k]).all() for k in numbers):
        return annotations_document(annotations)
    sizes = a["tab_size"].tolist()
    tab_template = {k: _template((k, 2)) for k in set(sizes)}
    tabs = "[" + ",".join(map(tab_template.__getitem__, sizes)) + "]"
    return {
        "tabs": _Raw(_fill(tabs, a["tab_points"])),
        "tab_hinges": _Raw(_hinges_text(a)),
        "labels": {
            "position": _Raw(_float_text(a["position"])),
            "text": _Raw(_strings_text(a["text"])),
            "angle": _Raw(_float_text(a["angle"])),
            "height": _Raw(_float_text(a["height"])),
            "kind": _Raw(_strings_text(a["kind"])),
        },
        "sheets": _Raw(_float_text(a["sheets"])),
    }


def annotations_json(pattern: CreasePattern) -> str:
    """The text of :data:`ANNOTATIONS_FILE`: the cut-file annotations of the pattern that
    ``design.fold`` holds, as :func:`annotations_document` gives them, with the counts of
    the pattern they belong to.

    Parameters
    ----------
    pattern : CreasePattern

    Returns
    -------
    str
        A JSON object: ``"file_creator"``, ``"design"`` (:func:`design_counts`, which
        :func:`~filletfold.export.fold_read.read_fold` compares with ``design.fold``), then
        ``"tabs"``, ``"tab_hinges"``, ``"labels"`` and ``"sheets"`` (empty lists when there
        are none), and with glue tabs ``"seams"``: ``"pieces"`` (the pieces' names),
        ``"joins"`` (per label, the two pieces it joins, by index) and ``"tab_on"`` (per
        label, 0 or 1: the one that carries its tab; -1: no tab); with a sheet material's
        reliefs or kerf grooves ``"making"``: one ``{"kind", "patch", "closed", "points"}``
        each (:class:`~filletfold.layout.making.MakingPath`).

    Raises
    ------
    ExportError
        When an annotation number is not finite.
    """
    doc = {
        "file_creator": file_creator(),
        "design": design_counts(pattern),
        **_annotations_data(pattern.annotations),
    }
    seams = pattern.annotations.seams
    if seams is not None and len(seams):  # what the assembly guide needs, from the files
        doc["seams"] = {
            "pieces": seams.names,
            "joins": seams.pieces.tolist(),
            "tab_on": seams.tab_on.tolist(),
        }
    making = pattern.annotations.making
    if making:  # a sheet material's reliefs and kerf grooves (none: no key, as before)
        doc["making"] = [
            {
                "kind": m.kind,
                "patch": m.patch,
                "closed": bool(m.closed),
                "points": np.asarray(m.points, dtype=np.float64).tolist(),
            }
            for m in making
        ]
    return fold_json(doc, root="annotations")


def design_counts(pattern: CreasePattern) -> dict:
    """``{"vertices", "faces", "pieces"}`` of a pattern: what ties :data:`ANNOTATIONS_FILE`
    to its ``design.fold`` (the pieces counted by ``filletfold:pieces_vertex``)."""
    return {
        "vertices": len(pattern.vertices_2d),
        "faces": len(pattern.faces),
        "pieces": len(pattern.piece_vertex),
    }


def _hinges_text(a: dict) -> str:
    """Compact JSON of ``tab_hinges`` (see :func:`_hinge_items`), formatted in bulk."""
    refs = hinge_refs(a["tab_points"], a["tab_size"], a["hinges"])
    found = (refs >= 0).all(axis=1)
    items = [f"[{i},{j}]" for i, j in refs.tolist()]
    missing = np.flatnonzero(~found)
    for k, text in zip(missing.tolist(), _item_texts(a["hinges"][missing]), strict=True):
        items[k] = text
    return "[" + ",".join(items) + "]"


def _strings_text(items) -> str:
    """Compact JSON (ASCII) of a list of strings, as ``json.dumps`` writes it."""
    return "[" + ",".join(map(_quote, items)) + "]"


def _round(x: float) -> float:
    """``x`` rounded to :data:`FOLD_DIGITS` significant digits; ``-0.0`` becomes ``0.0``."""
    if not math.isfinite(x):
        raise ExportError(f"FOLD values must be finite, got {x}")
    r = float(f"{x:.{FOLD_DIGITS}g}")
    return 0.0 if r == 0 else r


class _RaggedInts:
    """Integer lists of several lengths, as :func:`face_arrays` (``flat``, ``start``)."""

    __slots__ = ("flat", "start")

    def __init__(self, flat: np.ndarray, start: np.ndarray):
        self.flat, self.start = flat, start

    def text(self) -> str:
        """Compact JSON: ``[[a,b,c],[d,e,f,g],...]``."""
        size = np.diff(self.start).tolist()
        spec = {k: "[" + ",".join(["%d"] * k) + "]" for k in set(size)}
        return ("[" + ",".join([spec[k] for k in size]) + "]") % tuple(self.flat.tolist())


class _Raw:
    """Compact JSON text of a value, ready to write (see :func:`_float_text`, :func:`_dump`)."""

    __slots__ = ("text",)

    def __init__(self, text: str):
        self.text = text


#: Exact types :func:`_plain` passes through unchanged.
_AS_IS = frozenset({int, str, bool, type(None)})


#: The slot of one number in the templates of :func:`_fill`.
_SLOT = "%.12g"


def _fill(template: str, x: np.ndarray) -> str:
    """``template`` with its number slots filled in bulk, each value as :func:`_round` and
    ``json.dumps`` write it.

    ``%.12g`` writes a normal float's 12-digit rounding with the digits of ``repr`` of that
    rounding (two different 12-digit decimals are never one double). It differs from ``repr``
    only for integral values (no ``.0``), from ``1e12`` on (exponent form) and below the normal
    range (subnormals keep fewer digits): zeros are written ``0.0``, the other few with
    ``repr`` of :func:`_round` itself (the values near those, too, to be safe).

    Parameters
    ----------
    template : str
        Text with one slot :data:`_SLOT` (``%.12g``) per value of ``x`` and no other ``%``
        (no text from the data: JSON punctuation and whitespace only, never ``nan``).
    x : array_like of float
        Finite values, in the order of the slots (read in C order).

    Returns
    -------
    str
    """
    x = np.asarray(x, dtype=np.float64).ravel() + 0.0  # -0.0 becomes 0.0
    mag = np.abs(x)
    special = (np.abs(x - np.rint(x)) <= 1e-11 * mag) | (mag >= 1e11) | (mag < 1e-300)
    if not special.any():
        return template % tuple(x.tolist())
    # the special values are written NaN ("nan", in no other slot or text), then replaced
    texts = ["0.0" if v == 0 else repr(_round(v)) for v in x[special].tolist()]
    x[special] = np.nan
    parts = (template % tuple(x.tolist())).split("nan")
    if len(parts) != len(texts) + 1:
        raise ExportError(f"a template with text in its slots for {len(texts)} values")
    pieces = [""] * (2 * len(texts) + 1)
    pieces[0::2], pieces[1::2] = parts, texts
    return "".join(pieces)


def _template(shape: tuple[int, ...]) -> str:
    """Compact JSON template (see :func:`_fill`) of a float array of ``shape``."""
    if not shape:
        return _SLOT
    if shape[0] == 0:
        return "[]"
    return "[" + ",".join([_template(shape[1:])] * shape[0]) + "]"


def _float_text(a: np.ndarray) -> str:
    """Compact JSON of a finite float array, each value as :func:`_round` and ``json.dumps``
    would write it, formatted in bulk (see :func:`_fill`)."""
    return _fill(_template(a.shape), a)


def _item_texts(a: np.ndarray) -> list[str]:
    """(n,) the compact JSON of each item ``a[i]`` of a finite float array (n, ...), as
    :func:`_float_text` writes it, all formatted at once."""
    if len(a) == 0:
        return []
    return _fill("\n".join([_template(a.shape[1:])] * len(a)), a).split("\n")


def _int_text(a: np.ndarray) -> str:
    """Compact JSON of an integer array (1-D or 2-D)."""
    if a.ndim == 1:
        return "[" + ",".join(map(str, a.tolist())) + "]"
    row = "[" + ",".join(["%d"] * a.shape[1]) + "]"
    return ("[" + ",".join([row] * len(a)) + "]") % tuple(a.ravel().tolist())


def _plain_list(items) -> list | _Raw | None:
    """:func:`_plain` of a list or tuple whose items (or items' items) are all of one simple
    kind, without visiting them one by one in Python; None when they are not."""
    if not items:
        return []
    kinds = set(map(type, items))
    if kinds <= _AS_IS:
        return list(items)
    if kinds == {float}:
        a = np.array(items, dtype=np.float64)
        return _Raw(_float_text(a)) if np.isfinite(a).all() else None
    if kinds <= {list, tuple}:
        inner = set(map(type, itertools.chain.from_iterable(items)))
        if inner <= _AS_IS:
            return [v if type(v) is list else list(v) for v in items]
        if inner == {float} and len(set(map(len, items))) == 1:
            a = np.array(items, dtype=np.float64)
            return _Raw(_float_text(a)) if np.isfinite(a).all() else None
    return None


def _plain(obj, where: str):
    """JSON-ready copy of ``obj``: numpy to Python, floats rounded, tuples to lists.

    Arrays and lists of floats become :class:`_Raw` text (written as is by :func:`_dump`).
    """
    if isinstance(obj, np.ndarray):
        if obj.ndim in (1, 2) and obj.size:
            if obj.dtype.kind == "f" and np.isfinite(obj).all():
                return _Raw(_float_text(obj))
            if obj.dtype.kind in "iu":
                return _Raw(_int_text(obj))
        obj = obj.tolist()
    elif isinstance(obj, _RaggedInts):
        return _Raw(obj.text())
    elif isinstance(obj, _Raw):
        return obj
    obj = python_scalar(obj)
    if obj is None or isinstance(obj, bool | str | int):
        return obj
    if isinstance(obj, float):
        try:
            return _round(obj)
        except ExportError:
            raise ExportError(f"FOLD value at {where} is not finite ({obj})") from None
    if isinstance(obj, Mapping):
        out = {}
        for k, v in obj.items():
            if not isinstance(k, str):
                raise ExportError(f"FOLD keys must be strings, got {k!r} at {where}")
            out[k] = _plain(v, f"{where}.{k}" if where else k)
        return out
    if isinstance(obj, list | tuple):
        fast = _plain_list(obj)
        if fast is not None:
            return fast
        return [_plain(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    raise ExportError(
        f"FOLD value at {where or 'top level'} has unsupported type {type(obj).__name__}"
    )


def _compact(obj) -> str:
    """``json.dumps(obj, separators=(",", ":"))``, with :class:`_Raw` text inside written as is."""
    if isinstance(obj, _Raw):
        return obj.text
    try:
        return json.dumps(obj, separators=(",", ":"), allow_nan=False)
    except TypeError:  # a _Raw inside
        pass
    if isinstance(obj, dict):
        return "{" + ",".join(json.dumps(k) + ":" + _compact(v) for k, v in obj.items()) + "}"
    return "[" + ",".join(map(_compact, obj)) + "]"


def _dump(obj, depth: int, out: list[str]) -> list[str]:
    """Dicts and lists of dicts one entry per line, everything else compact on one line: the
    text's pieces appended to ``out`` (joined once by :func:`fold_json`), which is returned."""
    pad = "  " * depth
    if isinstance(obj, dict) and obj:
        out.append("{\n")
        for k, v in obj.items():
            out += (pad, "  ", json.dumps(k), ": ")
            _dump(v, depth + 1, out).append(",\n")
        out[-1] = "\n" + pad + "}"
    elif isinstance(obj, list) and dict in set(map(type, obj)):  # _plain made mappings dicts
        out.append("[\n")
        for v in obj:
            out += (pad, "  ")
            _dump(v, depth + 1, out).append(",\n")
        out[-1] = "\n" + pad + "]"
    else:
        out.append(_compact(obj))
    return out


def fold_json(doc: Mapping, *, root: str = "") -> str:
    """Serialise a FOLD document deterministically.

    Keys keep the document's order (:func:`fold_document` builds them in a fixed order); floats
    are rounded to 12 significant digits (``-0`` written as ``0.0``; :func:`fold_document` has
    rounded its facets' fold angles further); numpy arrays and scalars
    become JSON arrays and numbers. Each top-level key (and each key of a frame) is on its own
    line, arrays are compact. Output is ASCII and ends with a newline: the text of
    :func:`fold_json_chunks`, joined.

    Parameters
    ----------
    doc : mapping
        A FOLD document, such as the result of :func:`fold_document`.
    root : str
        The name the path of a bad value starts with in the error (``"annotations"`` for
        :func:`annotations_json`: ``annotations.tabs[1][0]``); none by default.

    Returns
    -------
    str

    Raises
    ------
    ExportError
        When a value is not finite, not JSON data, or a key is not a string.
    """
    return "".join(fold_json_chunks(doc, root=root))


def fold_json_chunks(doc: Mapping, *, root: str = "") -> Iterator[str]:
    """:func:`fold_json`'s text one top-level key at a time, each key's value converted only
    when its turn comes: written as it comes
    (:func:`~filletfold.export.atomic.write_outputs`), a large design's file is never whole
    in memory, only its largest array's text (the design of a 100k-face scan writes a
    ``design.fold`` of about 300 MB).

    Parameters and errors as :func:`fold_json`; an error is raised when the bad value's turn
    comes, after the keys before it.

    Yields
    ------
    str
    """
    if not isinstance(doc, Mapping):
        raise ExportError(f"a FOLD document must be a mapping, got {type(doc).__name__}")
    if not doc:
        yield _compact(_plain(doc, root)) + "\n"
        return
    yield "{\n"
    last = len(doc) - 1
    for i, (k, v) in enumerate(doc.items()):
        if not isinstance(k, str):
            raise ExportError(f"FOLD keys must be strings, got {k!r} at {root}")
        parts = _dump(_plain(v, f"{root}.{k}" if root else k), 1, ["  ", json.dumps(k), ": "])
        parts.append(",\n" if i < last else "\n}\n")
        yield "".join(parts)
