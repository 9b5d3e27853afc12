"""Reading a design back from its FOLD file (:mod:`filletfold.export.fold_read`): the pattern
the writer wrote, to the file's 12 digits, and one-line errors on what is not such a file."""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from filletfold.errors import MeshReadError
from filletfold.export import fold_document, fold_json, pattern_dxf, read_fold
from filletfold.export.fold_read import pattern_from_fold
from filletfold.surface.pattern import CreasePattern

from ..conftest import design_of, tiny_square
from .conftest import arc_pattern, layer_lengths, read_dxf


@pytest.mark.parametrize("name", ["cube", "torus", "miura"])
def test_read_fold_gives_back_the_written_pattern(name, tmp_path):
    p = design_of(name).pattern
    path = tmp_path / "design.fold"
    path.write_text(fold_json(fold_document(p)))
    q = read_fold(path)
    size = np.abs(p.vertices_3d).max() + np.abs(p.vertices_2d).max()
    np.testing.assert_allclose(q.vertices_2d, p.vertices_2d, rtol=0, atol=1e-11 * size)
    np.testing.assert_allclose(q.vertices_3d, p.vertices_3d, rtol=0, atol=1e-11 * size)
    assert [f.tolist() for f in q.faces] == [np.asarray(f).tolist() for f in p.faces]
    assert q.face_patch == list(p.face_patch)
    np.testing.assert_array_equal(q.face_piece, p.face_piece)
    np.testing.assert_array_equal(q.piece_vertex, p.piece_vertex)
    np.testing.assert_array_equal(q.edges, p.edges)
    np.testing.assert_array_equal(q.edge_assignment, p.edge_assignment)
    np.testing.assert_allclose(q.edge_fold_angle, p.edge_fold_angle, rtol=1e-11, atol=1e-9)
    np.testing.assert_array_equal(q.edge_faces, p.edge_faces)


def test_what_is_not_a_design_is_refused_in_one_line(tmp_path):
    doc = json.loads(fold_json(fold_document(design_of("cube").pattern)))
    broken = dict(doc)
    del broken["faces_vertices"]
    with pytest.raises(MeshReadError) as e:
        pattern_from_fold(broken)
    assert "\n" not in str(e.value)
    bad = dict(doc, faces_vertices=[[0, 1, 10**9], *doc["faces_vertices"][1:]])
    with pytest.raises(MeshReadError, match="not a valid filletfold design"):
        pattern_from_fold(bad)
    path = tmp_path / "x.fold"
    path.write_text("{ not json")
    with pytest.raises(MeshReadError) as e:
        read_fold(path)
    assert "\n" not in str(e.value)


# ---------------------------------------------------------------- FOLD read back


def write_fold(tmp_path, doc, name="design.fold"):
    path = tmp_path / name
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    return path


def assert_same_pattern(a: CreasePattern, b: CreasePattern) -> None:
    assert_allclose(a.vertices_2d, b.vertices_2d, atol=1e-9)
    assert_allclose(a.vertices_3d, b.vertices_3d, atol=1e-9)
    assert [list(f) for f in a.faces] == [list(f) for f in b.faces]
    assert list(map(str, a.face_patch)) == list(map(str, b.face_patch))
    assert a.face_piece.tolist() == b.face_piece.tolist()
    assert a.piece_vertex.tolist() == b.piece_vertex.tolist()
    assert a.edges.tolist() == b.edges.tolist()
    assert a.edge_assignment.tolist() == b.edge_assignment.tolist()
    assert_allclose(a.edge_fold_angle, b.edge_fold_angle, atol=1e-9)
    assert a.edge_faces.tolist() == b.edge_faces.tolist()
    aa, ba = a.annotations, b.annotations
    assert len(aa.tabs) == len(ba.tabs) and len(aa.labels) == len(ba.labels)
    # annotation numbers are written to FOLD's 12 significant digits
    tol = annotation_tolerance(aa)
    for s, t in zip(aa.tabs, ba.tabs, strict=True):
        assert_allclose(s, t, rtol=0, atol=tol)
    for s, t in zip(aa.tab_hinges, ba.tab_hinges, strict=True):
        assert_allclose(s, t, rtol=0, atol=tol)
    for s, t in zip(aa.labels, ba.labels, strict=True):
        assert (s.text, s.kind) == (t.text, t.kind)
        assert_allclose([*s.position, s.height], [*t.position, t.height], rtol=0, atol=tol)
        assert abs(s.angle - t.angle) <= 1e-11 * max(1.0, abs(s.angle))
    assert_allclose(np.reshape(aa.sheets, (-1, 4)), np.reshape(ba.sheets, (-1, 4)), atol=tol)


def annotation_tolerance(ann) -> float:
    """How far a written annotation length may be from its own: FOLD's 12 significant digits
    of the largest |length|."""
    lengths = [
        *map(np.ravel, ann.tabs),
        *map(np.ravel, ann.tab_hinges),
        *(np.ravel([*lb.position, lb.height]) for lb in ann.labels),
        np.ravel(ann.sheets),
    ]
    largest = max((float(np.abs(x).max()) for x in lengths if np.size(x)), default=0.0)
    if largest == 0:
        return 0.0
    return 1e-11 * largest


def test_read_fold_round_trip_cube(cube, tmp_path):
    doc = fold_document(cube.pattern)
    assert doc["filletfold:pieces_vertex"] == cube.pattern.piece_vertex.tolist()
    back = read_fold(write_fold(tmp_path, fold_json(doc)))
    assert_same_pattern(cube.pattern, back)


@pytest.mark.parametrize("annotated", [False, True])
def test_read_fold_round_trip_annotations(annotated, tmp_path):
    pattern = arc_pattern(annotated=annotated)
    doc = fold_document(pattern)
    assert ("filletfold:annotations" in doc) is annotated
    back = read_fold(write_fold(tmp_path, fold_json(doc)))
    assert_same_pattern(pattern, back)
    # the pattern read back exports like the original (up to FOLD's 12 digits)
    a, b = layer_lengths(read_dxf(pattern_dxf(back))), layer_lengths(read_dxf(pattern_dxf(pattern)))
    assert a.keys() == b.keys()
    for layer in a:
        assert a[layer][0] == pytest.approx(b[layer][0], rel=1e-9)
        assert len(a[layer][1]) == len(b[layer][1])


def test_read_fold_reads_labels_written_as_records(tmp_path):
    """Files written before the labels were parallel lists hold a list of records, one key per
    line: they read back to the same labels (missing angle, height, kind: the defaults)."""
    pattern = arc_pattern(annotated=True)
    doc = json.loads(fold_json(fold_document(pattern)))
    columns = doc["filletfold:annotations"]["labels"]
    records = [dict(zip(columns, row, strict=True)) for row in zip(*columns.values(), strict=True)]
    assert len(records) == len(pattern.annotations.labels) == 2
    new = read_fold(write_fold(tmp_path, doc, "new.fold"))
    doc["filletfold:annotations"]["labels"] = records
    old = read_fold(write_fold(tmp_path, json.dumps(doc, indent=2), "old.fold"))
    for a, b in zip(old.annotations.labels, new.annotations.labels, strict=True):
        assert (a.text, a.angle, a.height, a.kind) == (b.text, b.angle, b.height, b.kind)
        assert a.position.tolist() == b.position.tolist()
    assert_same_pattern(pattern, old)
    # the optional fields, in either layout
    del records[0]["angle"], records[0]["height"], records[0]["kind"]
    lean = {"position": columns["position"], "text": columns["text"]}
    for labels in (records, lean):
        doc["filletfold:annotations"]["labels"] = labels
        first = read_fold(write_fold(tmp_path, doc, "lean.fold")).annotations.labels[0]
        assert (first.angle, first.height, first.kind) == (0.0, 0.05, "part")


def test_read_fold_tabs_cut_as_written(cube, tmp_path):
    """Read back from the file, a tab still meets its hinge: the same cut paths as the
    design's own, within the file's rounding."""
    from filletfold.export.paths import tab_cut_paths

    ann = cube.pattern.annotations
    assert len(ann.tabs) > 0
    back = read_fold(write_fold(tmp_path, fold_json(fold_document(cube.pattern)))).annotations
    tol = annotation_tolerance(ann)
    mine, read = tab_cut_paths(ann), tab_cut_paths(back)
    assert [closed for _, closed in read] == [closed for _, closed in mine]
    assert not any(closed for _, closed in read)  # every tab found its hinge
    for (a, _), (b, _) in zip(mine, read, strict=True):
        assert_allclose(a, b, rtol=0, atol=tol)


def test_read_fold_without_pieces_vertex(tmp_path):
    doc = fold_document(tiny_square())
    del doc["filletfold:pieces_vertex"]
    back = read_fold(write_fold(tmp_path, doc))
    assert back.piece_vertex.tolist() == [-1]


def _mutated(change):
    doc = json.loads(fold_json(fold_document(tiny_square())))
    change(doc)
    return doc


@pytest.mark.parametrize(
    ("content", "match"),
    [
        ("{not json", "invalid JSON"),
        ("[1, 2]", "top level is a list"),
        ({"file_spec": 1.2, "vertices_coords": [[0, 0]]}, "missing key"),
        (_mutated(lambda d: d.pop("file_frames")), "no folded frame"),
        (_mutated(lambda d: d.update(file_frames=[{"frame_classes": []}])), "no frame of"),
        (_mutated(lambda d: d["file_frames"][0].update(vertices_coords=[[0, 0]] * 4)), "3D"),
        (_mutated(lambda d: d.update(vertices_coords=[[0, 0, 0]] * 4)), "2D points"),
        (_mutated(lambda d: d["edges_assignment"].__setitem__(0, "X")), "not a valid filletfold"),
        (_mutated(lambda d: d.update(edges_foldAngle="x")), "malformed arrays"),
        (_mutated(lambda d: d.update({"filletfold:annotations": [1]})), "must be an object"),
        (
            _mutated(lambda d: d.update({"filletfold:annotations": {"labels": [{"x": 1}]}})),
            "annotations is malformed",
        ),
        (
            _mutated(
                lambda d: d.update(
                    {"filletfold:annotations": {"labels": {"position": [[0, 0]], "text": []}}}
                )
            ),
            "annotations is malformed",
        ),
        (
            _mutated(
                lambda d: d.update(
                    {"filletfold:annotations": {"labels": {"position": [0, 0], "text": ["a"]}}}
                )
            ),
            "annotations is malformed",
        ),
    ],
)
def test_read_fold_rejects(content, match, tmp_path):
    path = write_fold(tmp_path, content)
    with pytest.raises(MeshReadError, match=match):
        read_fold(path)


def test_read_fold_missing_file_and_folder(tmp_path):
    with pytest.raises(MeshReadError, match="no such file"):
        read_fold(tmp_path / "nothing.fold")
    with pytest.raises(MeshReadError, match="is a folder"):
        read_fold(tmp_path)


def test_read_fold_takes_the_annotations_from_the_file_beside_it(cube, tmp_path):
    """``filletfold round`` writes the tabs and labels into annotations.json: read_fold finds
    them there (the same as in the design), none without the file, and refuses one written
    for another design, naming it."""
    from filletfold.export import cut_files

    for name, text in cut_files(cube.pattern, "fold").items():
        (tmp_path / name).write_text(text)
    back = read_fold(tmp_path / "design.fold")
    assert len(back.annotations.tabs) == len(cube.pattern.annotations.tabs) > 0
    assert_same_pattern(cube.pattern, back)
    other = tmp_path / "annotations.json"
    doc = json.loads(other.read_text())
    doc["design"]["faces"] += 1
    other.write_text(json.dumps(doc))
    with pytest.raises(MeshReadError, match=r"annotations\.json: written for another design"):
        read_fold(tmp_path / "design.fold")
    other.write_text("{ nope")
    with pytest.raises(MeshReadError, match=r"annotations\.json: not an annotations file \(inv"):
        read_fold(tmp_path / "design.fold")
    other.write_text("[1, 2]")
    with pytest.raises(MeshReadError, match=r"annotations\.json: not an annotations file"):
        read_fold(tmp_path / "design.fold")
    other.unlink()
    assert len(read_fold(tmp_path / "design.fold").annotations.tabs) == 0


def test_cut_files_exported_from_the_files_are_those_of_round(tmp_path):
    """``filletfold export`` rebuilds pattern.svg byte for byte from design.fold and
    annotations.json, and pattern.dxf to the file's 12 digits (the DXF keeps every digit of
    a float): a net with glue tabs on sheets, whose tab bases lie on the pieces' borders
    (rounded apart, they would change the SVG's scale)."""
    from filletfold.cli import main

    out = tmp_path / "ico"
    args = ["round", "icosahedron", "--layout", "net", "--sheet", "A4", "--units", "mm"]
    assert main([*args, "--scale", "40", "--format", "fold,svg,dxf", "-o", str(out), "-q"]) == 0
    first = {n: (out / n).read_bytes() for n in ("pattern.svg", "pattern.dxf")}
    assert main(["export", str(out), "--format", "svg,dxf", "--units", "mm", "--scale", "40"]) == 0
    assert (out / "pattern.svg").read_bytes() == first["pattern.svg"]
    a = layer_lengths(read_dxf((out / "pattern.dxf").read_text()))
    b = layer_lengths(read_dxf(first["pattern.dxf"].decode()))
    assert a.keys() == b.keys() and "TAB" in a
    for layer in a:
        assert a[layer][0] == pytest.approx(b[layer][0], rel=1e-9)
        assert len(a[layer][1]) == len(b[layer][1])
