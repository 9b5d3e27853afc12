"""The assembly guide: the order the pieces are glued in, and assembly.pdf."""

from __future__ import annotations

import re

import numpy as np
import pytest

import filletfold
from filletfold.export.assembly import STEPS_PER_PAGE, Step, _caption, assembly_pdf, assembly_steps


def test_the_largest_piece_starts_and_each_step_joins_the_largest_neighbour():
    # pieces 0-1-2 in a chain, 3 touching 1; piece 1 glues border 5 to itself; 4 alone
    seams = np.array([[0, 1], [1, 2], [1, 3], [2, 1], [1, 1]])
    area = np.array([1.0, 5.0, 2.0, 3.0, 4.0])
    steps = assembly_steps(seams, area)
    assert steps == [
        Step(1, (), (), (5,)),  # the largest first, closing its own border
        Step(3, (1,), (3,), ()),  # then the largest of its neighbours
        Step(2, (1,), (2, 4), ()),  # two borders onto piece 1
        Step(0, (1,), (1,), ()),
        Step(4, (), (), ()),  # the part done: the largest left starts a part of its own
    ]
    # every piece once, and every border between two pieces glued at exactly one step
    assert sorted(s.piece for s in steps) == list(range(5))
    glued = sorted(b for s in steps for b in (*s.borders, *s.own))
    assert glued == [1, 2, 3, 4, 5]


def test_steps_follow_the_assembled_part_before_another_part_starts():
    seams = np.array([[0, 1], [2, 3]])
    steps = assembly_steps(seams, np.array([1.0, 2.0, 4.0, 3.0]))
    assert [s.piece for s in steps] == [2, 3, 1, 0]  # 2's part whole, then 1's (the larger)
    assert steps[1].onto == (2,) and steps[2].onto == ()


def test_a_caption_names_the_pieces_and_counts_the_borders():
    names = ["P1", "P2", "P3"]
    assert _caption(Step(0, (), (), ()), names) == "P1 first"
    text = _caption(Step(2, (0, 1), tuple(range(1, 14)), (20,)), names)
    assert text == (
        "P3 onto P1, P2: 13 borders (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, ...); "
        "first close its own 1 border (20)"
    )


def _pages(pdf: bytes) -> int:
    return len(re.findall(rb"/Type /Page\b", pdf))


def test_the_guide_has_an_overview_and_a_page_per_six_steps_and_the_same_bytes():
    design = filletfold.round_mesh("cube", layout="modules")  # 8 pieces, one per vertex
    seams = design.fabrication["seams"]
    pdf = assembly_pdf(design.pattern, seams, up=design.up, width_px=160)
    assert pdf.startswith(b"%PDF")
    assert _pages(pdf) == 1 + -(-design.pattern.n_pieces // STEPS_PER_PAGE) == 3
    assert assembly_pdf(design.pattern, seams, up=design.up, width_px=160) == pdf


def test_the_guide_is_written_with_the_pdf_and_not_without_tabs(tmp_path):
    from filletfold.export.outputs import export_design

    design = filletfold.round_mesh("tetrahedron")
    written = [p.name for p in export_design(design, tmp_path / "t", formats="pdf")]
    assert written == ["pattern.pdf", "assembly.txt", "assembly.pdf"]
    assert (tmp_path / "t" / "assembly.pdf").read_bytes().startswith(b"%PDF")
    written = [p.name for p in export_design(design, tmp_path / "f", formats="fold")]
    assert "assembly.pdf" not in written  # not without the pdf (nor by default)
    bare = filletfold.round_mesh("tetrahedron", tabs=False, reuse=design)
    written = [p.name for p in export_design(bare, tmp_path / "b", formats="pdf")]
    assert written == ["pattern.pdf"]  # no numbered borders: nothing to guide


def test_export_writes_the_guide_from_the_files(tmp_path):
    """``filletfold export DIR --format pdf`` makes assembly.pdf from the design's files: the
    seams are in annotations.json (they were only in memory), read back equal."""
    from filletfold.cli import main
    from filletfold.export.fold_read import read_fold

    design = filletfold.round_mesh("cube", layout="modules")
    folder = tmp_path / "cube"
    design.export(folder)
    read = read_fold(folder / "design.fold").annotations.seams
    assert read == list(design.fabrication["seams"])
    assert main(["export", str(folder), "--format", "pdf"]) == 0
    guide = (folder / "assembly.pdf").read_bytes()
    assert _pages(guide) == 1 + -(-design.pattern.n_pieces // STEPS_PER_PAGE)


@pytest.mark.parametrize("up", ["y", "z"])
def test_labels_of_the_overview_sit_on_their_pieces(up):
    from filletfold.export.assembly import _View

    design = filletfold.round_mesh("cube", layout="modules")
    from filletfold.surface.triangulate import triangulate_faces

    tri = triangulate_faces(design.pattern.vertices_2d, design.pattern.faces)
    view = _View(design.pattern, tri, (-60.0, 25.0, up), 200)
    from filletfold.surface.validate import face_signed_area_2d

    area = np.abs(face_signed_area_2d(design.pattern.vertices_2d, design.pattern.faces))
    xy, seen = view.label_points(area)
    assert seen.sum() >= 3  # a cube seen from a corner shows at least three of its corners
    assert np.all((xy[seen] >= 0) & (xy[seen] <= [view.w, view.h]))


def test_seams_that_name_no_piece_are_a_named_error(tmp_path):
    import json

    from filletfold.errors import MeshReadError
    from filletfold.export.fold_read import read_fold

    folder = tmp_path / "cube"
    filletfold.round_mesh("cube").export(folder)
    doc = json.loads((folder / "annotations.json").read_text())
    doc["seams"]["joins"][0] = [0, len(doc["seams"]["pieces"])]
    (folder / "annotations.json").write_text(json.dumps(doc))
    with pytest.raises(MeshReadError, match=r"annotations\.json is malformed.*not named"):
        read_fold(folder / "design.fold")
