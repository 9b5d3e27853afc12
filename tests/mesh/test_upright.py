"""Which way is up: the axis a mesh stands on, else its format's convention."""

from __future__ import annotations

import json

import numpy as np
import pytest

import filletfold
from filletfold.mesh.examples import example_mesh
from filletfold.mesh.upright import FOOT, stand_margins, up_axis


def _centres_areas(vertices, faces):
    tri = vertices[np.asarray(faces)]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    return tri.mean(axis=1), area


def _table(up: int):
    """A table top on four thin legs, standing along axis ``up``: a box of 2 x 2 x 0.2 over
    four 0.1-wide legs 1 high (as points and a hull of triangles, which is all it needs)."""
    import trimesh

    parts = [
        trimesh.creation.box(
            (2.0, 2.0, 0.2), trimesh.transformations.translation_matrix((0, 0, 1.1))
        )
    ]
    for x in (-0.9, 0.9):
        for y in (-0.9, 0.9):
            parts.append(
                trimesh.creation.box(
                    (0.1, 0.1, 1.0), trimesh.transformations.translation_matrix((x, y, 0.5))
                )
            )
    mesh = trimesh.util.concatenate(parts)
    v = np.roll(np.asarray(mesh.vertices), up - 2, axis=1)  # z of the table becomes axis `up`
    return v, np.asarray(mesh.faces)


@pytest.mark.parametrize("up", [0, 1, 2])
def test_a_table_stands_on_its_legs_along_any_axis(up):
    v, f = _table(up)
    margin = stand_margins(v, *_centres_areas(v, f))
    assert np.argmax(margin) == up and margin[up] == pytest.approx(
        0.95 / 2.0
    )  # the legs' outer corners, size 2
    # on its side it stands only on the edge of its top and one leg: far less well
    assert up_axis(v, *_centres_areas(v, f)) == ("xyz"[up], f"it stands on its -{'xyz'[up]} side")


def test_a_mesh_that_stands_on_no_side_takes_its_formats_convention():
    rng = np.random.default_rng(3)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]) @ q.T  # a tipped tetrahedron
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    c, a = _centres_areas(v, f)
    assert np.all(stand_margins(v, c, a) <= 0)  # each lowest point is a corner alone
    assert up_axis(v, c, a, "scan.OBJ") == ("y", "it stands on no side: the OBJ convention")
    assert up_axis(v, c, a, "part.stl") == ("z", "it stands on no side: the STL convention")
    assert up_axis(v, c, a, "cube") == ("z", "it stands on no side: the default")
    assert np.all(stand_margins(np.zeros((3, 3)), c[:1], a[:1]) == -np.inf)  # no extent
    assert FOOT < 0.1


@pytest.mark.slow  # pictures drawn: the fast tier under 3 minutes
def test_a_design_knows_its_up_says_so_and_draws_it(tmp_path):
    from filletfold.app.view import scene_arrays
    from filletfold.cli import main

    vertices, faces = example_mesh("house")  # its gable roof up z
    turned = (np.asarray(vertices)[:, [1, 2, 0]], faces)  # z -> y, as a scan
    design = filletfold.round_mesh(turned, layout="modules")
    assert (design.up, design.up_why) == ("y", "it stands on its -y side")
    assert "up: +y (it stands on its -y side; in the pictures; --up to choose)" in design.summary()
    assert design.report()["up"] == {"axis": "y", "why": "it stands on its -y side"}
    scene = scene_arrays(design)  # the app draws up as its z
    v3 = scene.to_scene(design.pattern.vertices_3d)
    extent = np.ptp(design.pattern.vertices_3d, axis=0)
    assert np.ptp(v3, axis=0)[2] == pytest.approx(extent[1] * scene.scale)
    given = filletfold.round_mesh(turned, layout="modules", up="x", reuse=design)
    assert (given.up, given.up_why) == ("x", "given") and "up: " not in given.summary()
    with pytest.raises(filletfold.errors.ParameterError, match="up must be"):
        filletfold.round_mesh("cube", up="w")
    # the command line, and export taking the design's up (and size) from its report
    out = tmp_path / "house"
    assert main(["round", "house", "--up", "Y", "-q", "-f", "fold,json,png", "-o", str(out)]) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["up"] == {"axis": "y", "why": "given"} and report["parameters"]["up"] == "y"
    before = (out / "preview.png").read_bytes()
    assert main(["export", str(out), "-f", "png"]) == 0
    assert (out / "preview.png").read_bytes() == before  # seen the same way again
    assert main(["export", str(out), "-f", "png", "--up", "z"]) == 0
    assert (out / "preview.png").read_bytes() != before
