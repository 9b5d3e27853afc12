"""Resources bounded before they are spent (issue 30): a face of too many corners, a vertex
of too many edges and too many samples per arc are refused at once, naming the element and
the option that raises the limit."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

import filletfold
from filletfold.defaults import DEFAULT_MAX_CORNERS, MAX_SAMPLES
from filletfold.errors import MeshError, ParameterError
from filletfold.mesh import load_mesh
from filletfold.mesh.polymesh import estimate_pattern_points


def _ngon_cone(n: int):
    """An n-gon closed by a cone of n triangles (the n-gon's corners and the tip)."""
    v = [(math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n), 0.0) for i in range(n)]
    faces = [list(range(n - 1, -1, -1))] + [[i, (i + 1) % n, n] for i in range(n)]
    return np.array([*v, (0.0, 0.0, 1.0)]), faces


def _bipyramid(n: int):
    """Two cones of n triangles on an n-gon: two vertices of n edges, no face larger than 3."""
    v = [(math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n), 0.0) for i in range(n)]
    faces = [[i, (i + 1) % n, n] for i in range(n)] + [[(i + 1) % n, i, n + 1] for i in range(n)]
    return np.array([*v, (0.0, 0.0, 1.0), (0.0, 0.0, -1.0)]), faces


def test_a_face_of_too_many_corners_is_refused_before_it_is_cleaned():
    mesh = _ngon_cone(10_000)  # cleaned, it took 35 s; its vertex normals asked for 2.2 GB
    t = time.perf_counter()
    with pytest.raises(MeshError, match=r"face 0 has 10000 corners, more than 256 \(--max-corners"):
        filletfold.round_mesh(mesh)
    assert time.perf_counter() - t < 5.0
    with pytest.raises(MeshError, match="more than 300"):
        load_mesh(_ngon_cone(301), max_corners=300)
    load_mesh(_ngon_cone(300), max_corners=300)  # at the limit: read


def test_a_face_that_repeats_its_corners_is_repaired_not_refused():
    v = np.array([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], dtype=float)
    faces = [[0, 1, 2] * 2000, [0, 1, 3], [1, 2, 3], [2, 0, 3]]
    mesh, log = load_mesh((v, faces), max_corners=DEFAULT_MAX_CORNERS)
    assert mesh.n_faces == 4 and any(r.what == "split-face" for r in log.repairs)


def test_a_vertex_of_too_many_edges_is_refused():
    with pytest.raises(MeshError, match=r"vertex 300 meets 300 edges, more than 256"):
        filletfold.round_mesh(_bipyramid(300))


def test_samples_are_bounded():
    with pytest.raises(ParameterError, match=f"at most {MAX_SAMPLES} points per arc"):
        filletfold.round_mesh("cube", samples=MAX_SAMPLES + 1)
    with pytest.raises(ParameterError, match="max corners must be an integer >= 3"):
        filletfold.round_mesh("cube", max_corners=2)


def test_a_gltf_of_many_instances_is_refused_before_they_are_expanded(tmp_path, monkeypatch):
    """Issue 30: a 1.1 MB GLB of instances expanded to 400,000 triangles and 3.3 GB. The
    triangles every instance places are counted before any is expanded."""
    trimesh = pytest.importorskip("trimesh")
    from filletfold.mesh import io

    sphere = trimesh.creation.icosphere(subdivisions=1)  # 80 triangles
    scene = trimesh.Scene()
    for i in range(30):
        place = np.eye(4)
        place[0, 3] = 3.0 * i
        scene.add_geometry(sphere, geom_name="ball", node_name=f"ball{i}", transform=place)
    path = tmp_path / "instances.glb"
    scene.export(path)
    monkeypatch.setattr(io, "MAX_READ_TRIANGLES", 2000)
    with pytest.raises(MeshError, match=r"2,400 triangles, more than the 2,000 filletfold reads"):
        io.read_mesh(path)
    monkeypatch.setattr(io, "MAX_READ_TRIANGLES", 2400)
    _, faces = io.read_mesh(path)  # at the limit: read, every instance placed
    assert len(faces) == 2400


def test_an_apex_deeper_than_ten_thousand_edges_is_refused():
    """Issue 30: a depth of 1e308 raised ZeroDivisionError, then overflowed the solver into a
    design of sharp vertices only."""
    with pytest.raises(ParameterError, match=r"depth 1e\+308 is more than 10000 times"):
        filletfold.round_mesh("cube", depth=1e308)
    with pytest.raises(ParameterError, match="at vertex 3"):
        filletfold.round_mesh("cube", depth={"default": "30%", 3: 2e4})
    assert filletfold.round_mesh("cube", depth=50.0, certify=False).pattern.n_pieces > 0


# -- the pattern's size, estimated before anything is solved ---------------------------------
@pytest.mark.parametrize(
    ("name", "samples", "arc_step"),
    [
        ("tetrahedron", 3, 10.0),  # the most points per edge over the examples (0.77)
        ("cube", 3, 0.0),
        ("house", 24, 10.0),
        ("torus", 24, 0.0),
        ("geodesic-sphere", 8, 10.0),
        ("blob", 24, 10.0),
    ],
)
def test_the_estimate_bounds_the_pattern_it_is_made_for(name, samples, arc_step):
    design = filletfold.round_mesh(name, samples=samples, arc_step=arc_step)
    points = len(design.pattern.vertices_2d)
    estimate = estimate_pattern_points(design.mesh, samples)
    assert points <= estimate < 20 * points  # an upper estimate, not a vague one


@pytest.mark.slow
def test_the_estimate_bounds_every_examples_pattern():
    for name in filletfold.example_names():
        for samples in (3, 24, 96):
            design = filletfold.round_mesh(name, samples=samples, arc_step=0.0)
            assert len(design.pattern.vertices_2d) <= estimate_pattern_points(
                design.mesh, samples
            ), (name, samples)


def test_a_pattern_estimated_over_the_limit_is_refused_before_anything_is_solved(monkeypatch):
    import filletfold.design as design_mod

    def no_solving(*args, **kw):
        raise AssertionError("the refused design was solved")

    monkeypatch.setattr(design_mod, "edge_stage", no_solving)
    mesh, _ = load_mesh("geodesic-sphere")
    estimate = estimate_pattern_points(mesh, 64)
    with pytest.raises(MeshError, match=r"estimated at up to [\d,]+ pattern points.*--max-points"):
        filletfold.round_mesh(mesh, samples=64, max_points=estimate - 1)
    with pytest.raises(ParameterError, match="max points"):
        filletfold.round_mesh(mesh, max_points=0)


def test_the_command_names_the_limit_and_writes_nothing(tmp_path, capsys):
    from filletfold.cli import main

    out = tmp_path / "out"
    assert main(["round", "cube", "-n", "256", "--max-points", "10000", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--max-points" in err and "--faces" in err
    assert not out.exists()


@pytest.mark.slow
def test_a_mesh_of_200k_triangles_is_refused_at_the_default_limit():
    n = 330  # a wavy grid of 217,800 triangles: no coplanar faces to merge
    x, y = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0))
    vertices = np.c_[x.ravel(), y.ravel(), (0.3 * np.sin(x / 7) * np.cos(y / 5)).ravel()]
    i = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    faces = np.r_[np.c_[i, i + 1, i + n + 2], np.c_[i, i + n + 2, i + n + 1]]
    t = time.perf_counter()
    with pytest.raises(MeshError, match=r"327,291 edges at 24 samples.* more than 50,000,000"):
        filletfold.round_mesh((vertices, faces))
    assert time.perf_counter() - t < 60  # reading and cleaning only (9 s here)
