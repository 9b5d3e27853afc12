"""The vectorised exporters (issue 6) write the bytes of the plain per-element loops."""

from __future__ import annotations

import dataclasses
import json
import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from filletfold.errors import ExportError
from filletfold.export import (
    cut_files,
    fold_document,
    fold_json,
    folded_obj,
    pattern_svg,
    report_json,
    validate_pattern,
)
from filletfold.export.fold import (
    _float_text,
    _round,
    annotations_document,
    design_counts,
    file_creator,
)
from filletfold.export.obj import obj_decimals, obj_group_name, weld_vertices
from filletfold.export.report import to_json_data
from filletfold.surface.pattern import CreasePattern
from filletfold.surface.validate import validated_faces

from ..conftest import design_of

NAMES = ["cube", "torus", "house", "open-box", "miura"]


# ---------------------------------------------------------------- reference loops


def ref_plain(obj):
    """FOLD values one by one: numpy to Python, floats to 12 digits, -0 to 0."""
    obj = obj.tolist() if isinstance(obj, np.ndarray | np.generic) else obj
    if isinstance(obj, float):
        return _round(obj)
    if isinstance(obj, Mapping):
        return {k: ref_plain(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [ref_plain(v) for v in obj]
    return obj


def ref_dump(obj, depth=0) -> str:
    pad = "  " * depth
    if isinstance(obj, dict) and obj:
        items = [f"{pad}  {json.dumps(k)}: {ref_dump(v, depth + 1)}" for k, v in obj.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, list) and any(isinstance(v, dict) for v in obj):
        items = [f"{pad}  {ref_dump(v, depth + 1)}" for v in obj]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    return json.dumps(obj, separators=(",", ":"), allow_nan=False)


def ref_fold_json(doc) -> str:
    return ref_dump(ref_plain(doc)) + "\n"


def ref_obj(pattern: CreasePattern) -> str:
    v, inverse = weld_vertices(pattern.vertices_3d)
    decimals = obj_decimals(v)

    def num(x):
        s = f"{x:.{decimals}f}"
        if "." in s:
            s = s.rstrip("0").rstrip(".")
        return "0" if s in ("-0", "") else s

    lines = [
        "# header",
        f"# {len(v)} vertices, {len(pattern.faces)} faces, {len(set(pattern.face_patch))} patches",
    ]
    lines.extend(f"v {num(a)} {num(b)} {num(c)}" for a, b, c in v)
    groups: dict[str, list[int]] = {}
    for i, patch in enumerate(pattern.face_patch):
        groups.setdefault(obj_group_name(patch), []).append(i)
    for name, ids in groups.items():
        lines.append(f"g {name}")
        lines.extend(
            "f " + " ".join(str(int(inverse[k]) + 1) for k in pattern.faces[i]) for i in ids
        )
    return "\n".join(lines) + "\n"


def ref_svg_number(x: float, decimals: int) -> str:
    s = f"{x:.{decimals}f}"
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


# ---------------------------------------------------------------- FOLD


SPECIAL = [0.0, -0.0, 1.0, -7.0, 0.5, 1e-5, 1e-4, 1 / 3, 0.1 + 0.2, 1e11, 1e12, 999999999999.5]
SPECIAL += [1.5e15, 1e16, 1e17, 5e-324, 1e-310, 2.2250738585072014e-308, 123456789012.4]
SPECIAL += [2.0**52, 1e-11, 1.00000000000001, 0.99999999999999, 12345678901.99999]


@settings(max_examples=200, deadline=None)
@given(
    st.lists(
        st.one_of(
            st.floats(allow_nan=False, allow_infinity=False),
            st.sampled_from(SPECIAL),
            st.integers(-(10**6), 10**6).map(float),
        ),
        min_size=1,
        max_size=60,
    ),
    st.sampled_from([1, 2, 3]),
)
def test_float_text_is_round_then_repr(values, k):
    x = np.array(values[: len(values) // k * k] or values[:1] * k, dtype=float)
    assert _float_text(x) == json.dumps([_round(v) for v in x.tolist()], separators=(",", ":"))
    m = x.reshape(-1, k)
    rows = [[_round(v) for v in r] for r in m.tolist()]
    assert _float_text(m) == json.dumps(rows, separators=(",", ":"))


def test_float_text_many_zeros_and_few_zeros():
    rng = np.random.default_rng(3)
    for share in (0.001, 0.3, 1.0):
        x = np.where(rng.random(3000) < share, 0.0, rng.normal(size=3000)).reshape(-1, 3)
        x[::5, 1] = -0.0
        ref = json.dumps([[_round(v) for v in r] for r in x.tolist()], separators=(",", ":"))
        assert _float_text(x) == ref


@pytest.mark.parametrize("name", NAMES)
def test_fold_text_is_the_loops_text(name):
    p = design_of(name).pattern
    doc = fold_document(p, title="t", extra={"filletfold:x": [np.arange(3.0), {"y": (1.5, 2)}]})
    assert fold_json(doc) == ref_fold_json(doc)
    files = cut_files(p, "fold", title="t")
    assert files["design.fold"] == fold_json(fold_document(p, title="t", annotations=False))


def test_fold_json_mixed_and_nested_values():
    doc = {
        "a": [1, 2.0, True, None, "s"],
        "b": [[1.0, 2.0], [3.0]],
        "c": [[{"d": np.array([0.25, -0.0])}], np.array([[1, 2], [3, 4]])],
        "e": (np.float32(0.1), np.int64(3)),
        "f": [],
        "g": [[], []],
        "h": np.zeros((0, 2)),
        "i": {"j": [np.array([1e20, 1e-320])]},
    }
    assert fold_json(doc) == ref_fold_json(doc)


def test_fold_json_still_rejects_non_finite_inside_arrays():
    with pytest.raises(ExportError, match=r"a\[1\] is not finite"):
        fold_json({"a": np.array([1.0, np.inf])})
    with pytest.raises(ExportError, match=r"a\[0\]\[1\] is not finite"):
        fold_json({"a": [[1.0, float("nan")]]})


FOLD_FLOATS = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False),
    st.floats(allow_nan=False, allow_infinity=False, width=32),
    st.sampled_from(SPECIAL),
    st.integers(-(10**15), 10**15).map(float),
    st.floats(-1e-300, 1e-300),
)


@settings(max_examples=200, deadline=None)
@given(st.lists(FOLD_FLOATS, min_size=0, max_size=40), st.sampled_from([(), (2,), (2, 2)]))
def test_item_texts_and_fill_are_round_then_repr(values, row):
    from filletfold.export.fold import _fill, _item_texts, _template

    k = math.prod(row)
    x = np.array(values[: len(values) // k * k], dtype=float).reshape(-1, *row)
    items = [json.dumps(ref_plain(r), separators=(",", ":")) for r in x.tolist()]
    assert _item_texts(x) == items
    template = "{" + ";".join([_template(row)] * len(x)) + "}"
    assert _fill(template, x) == "{" + ";".join(items) + "}"


def _annotated(tabs, hinges, labels, sheets) -> CreasePattern:
    from filletfold.surface.pattern import Annotations

    p = dataclasses.replace(design_of("cube").pattern)
    p.annotations = Annotations(tabs=tabs, tab_hinges=hinges, labels=labels, sheets=sheets)
    return p


@pytest.mark.slow  # every example: the fast tier under 3 minutes
def test_fold_annotations_in_bulk_are_the_plain_documents_text():
    from filletfold.surface.pattern import Label

    rng = np.random.default_rng(5)
    tabs = [rng.normal(size=(k, 2)) for k in (4, 0, 3, 4, 1, 6)]
    tabs[0][1] = [-0.0, 2.0]  # zero, integral
    tabs += [[[0.5, 1e-320], [3e15, 7.0]], np.array([1.0, 2.0, 3.0, 4.0])]  # lists, flat
    hinges = [np.reshape(t, (-1, 2))[:2] for t in tabs if np.size(t) >= 4]
    hinges.append([0.1, 0.2, 0.3, 0.4])
    labels = [
        Label(np.array([0.0, 1.0]), "1", 0.0, 0.25, "tab"),
        Label([2.5, -0.0], 'a "%s" é\u2028', np.float64(-52.771095670080626), 1, "p%d"),
        Label(np.array([[1e-7, 123456789012.4]]), "", 90, np.float32(0.1), "part"),
    ]
    for sheets in (np.zeros((0, 4)), np.array([[0.0, 0.0, 210.0, 297.5]]), [0, 0, 1, 2]):
        for subset in (slice(None), slice(0, 0)):
            p = _annotated(tabs[subset], hinges[subset], labels[subset], sheets)
            files = cut_files(p, "fold", title="t")
            doc = fold_document(p, title="t")
            assert fold_json(doc) == ref_fold_json(doc)
            # annotations.json: the bulk writer's text is the plain document's
            side = {"file_creator": file_creator(), "design": design_counts(p)}
            plain = {**side, **annotations_document(p.annotations)}
            assert files["annotations.json"] == ref_fold_json(plain)
            bare = fold_document(p, title="t", annotations=False)
            assert files["design.fold"] == fold_json(bare) == ref_fold_json(bare)


@pytest.mark.parametrize(
    ("where", "match"),
    [
        ("tab", r"annotations\.tabs\[1\]\[0\]\[1\] is not finite"),
        ("hinge", r"annotations\.tab_hinges\[0\]\[1\]\[0\] is not finite"),
        ("angle", r"annotations\.labels\[1\]\.angle is not finite"),
        ("height", r"annotations\.labels\[0\]\.height is not finite"),
        ("sheet", r"annotations\.sheets\[0\]\[2\] is not finite"),
    ],
)
def test_fold_annotations_still_name_a_value_not_finite(where, match):
    from filletfold.surface.pattern import Label

    nan = float("nan")
    tabs = [np.ones((3, 2)), np.array([[1.0, nan if where == "tab" else 2.0]])]
    hinges = [np.array([[0.0, 0.0], [np.inf if where == "hinge" else 1.0, 0.0]])]
    labels = [
        Label(np.zeros(2), "a", 0.0, nan if where == "height" else 1.0),
        Label(np.zeros(2), "b", -np.inf if where == "angle" else 0.0, 1.0),
    ]
    sheets = np.array([[0.0, 0.0, nan if where == "sheet" else 1.0, 1.0]])
    p = _annotated(tabs, hinges, labels, sheets)
    with pytest.raises(ExportError, match=match):
        cut_files(p, "fold")
    with pytest.raises(ExportError, match=match):
        fold_json(fold_document(p))


@pytest.mark.parametrize(
    ("tabs", "hinges"),
    [([np.ones(3)], []), ([np.ones((2, 2))], [np.ones(6)]), ([np.ones((3, 3))], [])],
)
def test_fold_annotations_malformed_fail_as_the_plain_document(tabs, hinges):
    p = _annotated(tabs, hinges, [], np.zeros((0, 4)))
    with pytest.raises(ValueError, match="reshape"):
        fold_document(p)
    with pytest.raises(ValueError, match="reshape"):
        cut_files(p, "fold")


# ---------------------------------------------------------------- OBJ


@pytest.mark.parametrize("name", NAMES)
def test_obj_is_the_loops_text(name):
    p = design_of(name).pattern
    text = folded_obj(p)
    assert text.split("\n", 1)[1] == ref_obj(p).split("\n", 1)[1]
    assert cut_files(p, "obj")["folded.obj"] == text


def test_obj_group_names_with_percent_and_minus_zero():
    v2 = np.array([[0, 0], [1, 0], [0, 1], [1, 1]], dtype=float)
    v3 = np.array([[-0.0, 0, 0], [1, -0.0, 0], [0, 1, 0], [1, 1, 1e-20]])
    p = CreasePattern(v2, v3, [[0, 1, 2], [1, 3, 2]], ["face 5%d", "cone  7"], [0, 0], [0])
    text = folded_obj(p)
    assert text.split("\n", 1)[1] == ref_obj(p).split("\n", 1)[1]
    assert "g face_5%d\n" in text and "-0 " not in text


# ---------------------------------------------------------------- SVG


_NS = "{http://www.w3.org/2000/svg}"
#: The SVG group of each pattern edge assignment (the default preset).
_GROUP = {"F": "flat", "B": "border", "V": "valley", "M": "mountain"}


def _svg_groups(text: str) -> dict:
    root = ET.fromstring(text)
    return {g.get("id"): list(g) for g in root.iter(_NS + "g")}


def _line_lengths(elements) -> np.ndarray:
    xy = np.array([[float(e.get(k)) for k in ("x1", "y1", "x2", "y2")] for e in elements])
    return np.hypot(xy[:, 2] - xy[:, 0], xy[:, 3] - xy[:, 1]) if len(xy) else np.zeros(0)


def _rounding(lengths: np.ndarray, text: str | None = None) -> float:
    """What rounding the SVG's coordinates (9 significant digits of the drawing, 4 decimals at
    least; with ``text``, a cut-file preset's drawing, also its resolution of
    :data:`~filletfold.export.presets.RESOLUTION_MM` printed) can do to a line's length."""
    from filletfold.export.presets import RESOLUTION_MM

    digits = 4 * max(1e-4, 1e-9 * float(np.max(lengths, initial=0.0)) * 1e3)
    if text is None:
        return digits
    root = ET.fromstring(text)
    user = float(root.get("viewBox").split()[2]) / float(root.get("width")[:-2])
    return max(digits, 2 * RESOLUTION_MM * user)


@pytest.mark.parametrize("name", NAMES)
def test_svg_lines_are_the_pattern_edges(name):
    """Each assignment's group has one line per pattern edge, in edge order, as long as the
    edge times one drawing scale (the SVG's numbers round to 1e-9 of its extent)."""
    p = design_of(name).pattern
    text = pattern_svg(p, preset="origami-simulator")
    groups = _svg_groups(text)
    length = np.linalg.norm(np.diff(p.vertices_2d[p.edges], axis=1)[:, 0], axis=1)
    got, want = [], []
    for code, gid in _GROUP.items():
        lines = [e for e in groups[gid] if e.tag == _NS + "line"]
        assert len(lines) == np.sum(p.edge_assignment == code), code
        got.append(_line_lengths(lines))
        want.append(length[p.edge_assignment == code])
    got, want = np.concatenate(got), np.concatenate(want)
    k = np.median(got[want > 0] / want[want > 0])
    assert_allclose(got, k * want, atol=_rounding(got))
    assert cut_files(p, "svg", preset="origami-simulator")["pattern.svg"] == text


def test_svg_numbers_match_the_formatter():
    from filletfold.export.svg import _format_all

    rng = np.random.default_rng(0)
    x = np.concatenate(
        [rng.normal(size=500) * 50, [0.0, -0.0, -1e-12, 1e-12, -4e-9, 5e-9, 100.0, -0.5e-7]]
    )
    for d in (0, 1, 3, 7, 9):
        assert _format_all(x, d) == [ref_svg_number(v, d) for v in x.tolist()]


@pytest.mark.parametrize("name", [*NAMES, "odd"])
def test_svg_annotations_are_the_patterns(name):
    """Tabs, hinges and labels: one element each, the labels' texts in order, the hinges as
    long as the pattern's (one drawing scale with the edges)."""
    from filletfold.export.paths import tab_cut_paths
    from filletfold.surface.pattern import Label

    if name == "odd":
        labels = [
            Label(np.array([0.0, 1.0]), "1", 0.0, 0.25, "tab"),
            Label([2.5, -0.0], 'a <"&"> %s é', np.float64(-52.771095670080626), 1, "p%d"),
            Label(np.array([[1e-7, -3.0]]), "", 90, np.float32(0.1), "part"),
            Label(np.array([0.5, 0.5]), "z", -0.0, 1e-12, "angle"),
        ]
        tab = np.array([[0.0, 0.0], [0.2, -0.2], [0.8, -0.2], [1.0, 0.0], [0.0, 0.0]])
        p = _annotated(
            [tab, tab[:3] + 2.0, np.zeros((0, 2))],
            [tab[[3, 0]], tab[:2]],
            labels,
            np.array([[-1.0, -1.0, 3.0, 2.0], [0.0, 0.0, 0.5, 0.25]]),
        )
    else:
        p = design_of(name).pattern
    ann = p.annotations
    text = pattern_svg(p)
    groups = _svg_groups(text)
    if not len(ann.tab_hinges) and not len(ann.labels):
        assert "tab-hinge" not in groups and "labels" not in groups
        return
    cuts = [e for e in groups.get("tab-cut", []) if e.tag in (_NS + "polyline", _NS + "polygon")]
    assert len(cuts) == sum(len(q) > 1 for q, _ in tab_cut_paths(ann))  # empty ones: none
    hinges = groups.get("tab-hinge", [])
    assert len(hinges) == len(ann.tab_hinges)
    # the labels sit in one group per run of one kind and size, which carries both
    texts = [(t, run.get("class")) for run in groups.get("labels", []) for t in run]
    assert [(t.text or "", c) for t, c in texts] == [(str(lb.text), lb.kind) for lb in ann.labels]
    assert all(t.get("font-size") is None and t.get("class") is None for t, _ in texts)
    if len(hinges):
        want = np.array(
            [np.linalg.norm(np.subtract(*np.reshape(h, (2, 2)))) for h in ann.tab_hinges]
        )
        edges = [e for e in groups["border"] if e.tag == _NS + "line"]
        border = np.linalg.norm(
            np.diff(p.vertices_2d[p.edges[p.edge_assignment == "B"]], axis=1)[:, 0], axis=1
        )
        got = _line_lengths(hinges)
        if len(edges):
            k = np.median(_line_lengths(edges)[border > 0] / border[border > 0])
        else:  # unitless: the larger side of the pattern is printed 200 mm
            root = ET.fromstring(text)
            user = float(root.get("viewBox").split()[2]) / float(root.get("width")[:-2])
            from filletfold.export.paths import pattern_extent

            lo, hi = pattern_extent(p)
            k = 200.0 * user / float((hi - lo).max())
        assert_allclose(got, k * want, atol=_rounding(got, text))


# ---------------------------------------------------------------- report.json


@pytest.mark.parametrize("name", NAMES)
def test_report_json_is_json_dumps_indent_2(name):
    report = design_of(name).report()
    assert report_json(report) == json.dumps(to_json_data(report), indent=2) + "\n"


def test_report_json_odd_values():
    doc = {
        "a": [1, 2.5, float("nan"), None, True, 'é"q'],
        "b": [[1.0, float("inf")], [2, 3], []],
        "c": {},
        "d": [],
        "e": [[], {}, {"k": [1, {"z": np.arange(3)}]}],
        "f": np.array([[1.0, np.nan]]),
        "g": ("x", "\u2028"),
        "h": {1: 2, 2.5: "z", None: False},
    }
    assert report_json(doc) == json.dumps(to_json_data(doc), indent=2, allow_nan=False) + "\n"


# ---------------------------------------------------------------- validation


def _square(faces) -> CreasePattern:
    p = CreasePattern(
        [[0, 0], [1, 0], [1, 1], [0, 1]],
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
        [[0, 1, 2], [0, 2, 3]],
        ["face 0", "face 0"],
        [0, 0],
        [0],
    )
    p.faces = faces
    return p


def test_validated_faces_of_mixed_integer_types():
    faces = [np.array([0, 1, 2], dtype=np.uint64), np.array([0, 2, 3], dtype=np.int32)]
    flat, start = validated_faces(_square(faces))
    assert flat.dtype == np.int64 and flat.tolist() == [0, 1, 2, 0, 2, 3]
    assert start.tolist() == [0, 3, 6]
    plain = _square([[0, 1, 2], [0, 2, 3]])
    assert fold_json(fold_document(_square(faces))) == fold_json(fold_document(plain))
    assert cut_files(_square(faces), "fold,obj") == cut_files(plain, "fold,obj")


@pytest.mark.parametrize(
    ("faces", "match"),
    [
        ([[0, 1, 2], np.array([[0, 2, 3]])], "face 1 must list at least 3 integer"),
        ([[0, 1, 2], [0.0, 2.0, 3.0]], "face 1 must list at least 3 integer"),
        ([[0, 1, 2], [True, False, True]], "face 1 must list at least 3 integer"),
        ([[0, 1, 2], [0, 2]], "face 1 must list at least 3 integer"),
        ([[0, 1, 2], [0, 2, -1]], "face 1 refers to a vertex outside"),
        ([[0, 1, 2], (0, 2, 4)], "face 1 refers to a vertex outside"),
    ],
)
def test_validate_pattern_still_names_the_face(faces, match):
    with pytest.raises(ExportError, match=match):
        validate_pattern(_square(faces))
    with pytest.raises(ExportError, match=match):
        cut_files(_square(faces), "fold,obj,svg")


# ---------------------------------------------------------------- report.json by columns


def ref_report_json(report) -> str:
    return json.dumps(to_json_data(report), indent=2, allow_nan=False) + "\n"


@pytest.mark.parametrize("name", NAMES)
def test_report_records_write_the_report_of_dicts(name):
    from filletfold.export.outputs import design_report, report_records

    d = design_of(name)
    report = design_report(d)
    assert report_json(report_records(d)) == ref_report_json(report)
    assert all(type(v) is dict for key in ("edges", "vertices") for v in report[key])


FLOATS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1.0, 0.1, -2.5, 1e300, 5e-324, float("nan"), float("inf")]),
)
SCALARS = st.one_of(FLOATS, st.none(), st.booleans(), st.integers(-5, 5), st.text(max_size=4))
VALUES = st.one_of(
    SCALARS,
    st.lists(st.one_of(FLOATS, st.none(), st.integers(-3, 3)), max_size=4),
    st.lists(st.text(max_size=3), max_size=3),
    st.lists(st.lists(FLOATS, max_size=3), max_size=3),
    st.dictionaries(st.sampled_from("xy"), FLOATS, max_size=2),
)


@settings(max_examples=150, deadline=None)
@given(
    st.lists(
        st.dictionaries(st.sampled_from(["kind", "status", "reason", "a", "b"]), VALUES),
        max_size=12,
    ),
    st.booleans(),
)
def test_report_json_of_records_is_json_dumps(records, ordered):
    if ordered:  # one common key order, some keys missing: written a column at a time
        order = ["kind", "status", "reason", "a", "b"]
        records = [{k: r[k] for k in order if k in r} for r in records]
    doc = {"records": records, "nested": {"list": records[:3]}, "rows": [[1.0, None], None]}
    assert report_json(doc) == ref_report_json(doc)


@settings(max_examples=100, deadline=None)
@given(
    st.integers(0, 40),
    st.integers(1, 3),
    st.lists(st.sampled_from([0.0, -0.0, 1.5, 0.1, np.nan, np.inf, -np.inf]), min_size=1),
    st.randoms(use_true_random=False),
)
def test_records_of_arrays_write_their_dicts(n, k, pool, rnd):
    from filletfold.export.report import Records

    pick = np.array(pool)[[rnd.randrange(len(pool)) for _ in range(n * (k + 1))]]
    rows = pick[: n * k].reshape(n, k) * rnd.choice([1.0, 1e-7, 3.3])
    mask = np.array([rnd.random() < 0.3 for _ in range(n)], dtype=bool)
    table = Records(
        {
            "kind": [rnd.choice(["cone", "saddle"]) for _ in range(n)],
            "reason": [rnd.choice([None, 'no "cone"', "é"]) for _ in range(n)],
            "value": pick[n * k :],
            "row": rows,
            "ids": np.arange(n * 2).reshape(n, 2),
            "flag": mask,
            "sigma": np.arange(n) % 3 - 1,
        },
        present={"reason": ~mask},
        nulls={"row": mask, "sigma": np.arange(n) % 3 == 1},
    )
    if n == 0:
        assert report_json({"t": table}) == '{\n  "t": []\n}\n'
        return
    dicts = table.dicts()
    assert [("reason" in r) for r in dicts] == (~mask).tolist()
    assert all(r["row"] is None for r, m in zip(dicts, mask, strict=True) if m)
    assert report_json({"t": table}) == ref_report_json({"t": dicts})
    assert to_json_data({"t": table}) == to_json_data({"t": dicts})


def test_report_json_arrays_and_repeated_floats():
    zeros = [0.0, -0.0] * 50 + [0.1] * 20
    doc = {
        "a": np.array([[1.0, np.nan], [np.inf, -0.0]]),
        "faces": [np.array([1, 2, 3]), np.array([4, 5, 6, 7]), np.array([], dtype=int)],
        "mixed": [np.array([1, 2]), np.array([0.5])],
        "zeros": zeros,
        "zeros_or_none": [*zeros, None],
        "flags": np.array([True, False]),
        "empty": np.zeros((0, 3)),
    }
    assert report_json(doc) == ref_report_json(doc)
    assert '"-0.0"' not in report_json(doc) and "-0.0" in report_json(doc)


def test_report_records_reject_ragged_columns():
    from filletfold.export.report import Records

    with pytest.raises(ExportError, match="one length"):
        Records({"a": [1, 2], "b": [1]})
    with pytest.raises(ExportError, match="one length"):
        Records({"a": [1, 2]}, nulls={"b": [True, False]})


def test_indented_still_rejects_non_finite_json_data():
    from filletfold.export.report import _indented

    for bad in ([1.0, float("nan")], [None, float("inf")], [[1.0, float("-inf")]]):
        with pytest.raises(ValueError, match="not JSON compliant"):
            _indented(bad, "\n")


def test_group_names_all_at_once_are_obj_group_name():
    from filletfold.export.obj import _group_names

    names = ["cone 3", "  a  b ", "x\t\ny", "", "   ", "é\u2028z", "\u3000q\u3000", "a%d", "z"]
    assert _group_names(names) == [obj_group_name(n) for n in names]
    assert _group_names([*names, "p\x00q"]) == [obj_group_name(n) for n in [*names, "p\x00q"]]
    assert _group_names([]) == []


# ---------------------------------------------------------------- report JSON (hand-made)


@dataclasses.dataclass
class _Stats:
    count: int
    ratio: float


def test_report_json_numpy_and_nan():
    report = {
        "z": np.float64(1.5),
        "a": np.array([[1.0, np.nan], [np.inf, -2.0]]),
        "n": np.int64(7),
        "flag": np.bool_(True),
        "nan": float("nan"),
        "ids": (np.int32(1), 2),
        "nested": {np.int64(3): "three", "stats": _Stats(2, float("-inf"))},
    }
    text = report_json(report)
    assert text.endswith("\n")
    assert text.startswith('{\n  "z": 1.5,')
    back = json.loads(text)
    assert list(back) == ["z", "a", "n", "flag", "nan", "ids", "nested"]
    assert back["a"] == [[1.0, None], [None, -2.0]]
    assert back["n"] == 7 and back["flag"] is True and back["nan"] is None
    assert back["ids"] == [1, 2]
    assert back["nested"] == {"3": "three", "stats": {"count": 2, "ratio": None}}
    assert "NaN" not in text and "Infinity" not in text
    assert report_json(report) == text


@pytest.mark.parametrize(
    ("report", "match"),
    [
        ({"x": object()}, r"at x has no JSON form \(object\)"),
        ({"x": [1, complex(1, 2)]}, r"x\[1\] has no JSON form"),
        ({"x": np.array([1j])}, "complex128 array"),
        ({(1, 2): 3}, "is not a string or number"),
    ],
)
def test_report_json_rejects(report, match):
    with pytest.raises(ExportError, match=match):
        report_json(report)
