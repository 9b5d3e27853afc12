"""Geometric invariants of every generated design (the core issue's checks)."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.spatial import ConvexHull

import filletfold
from filletfold.errors import MeshReadError, ParameterError
from filletfold.export.outputs import edge_mismatch, relative_mismatch
from filletfold.rounding.edges import round_edges
from filletfold.surface.sampling import cone_sample_counts
from filletfold.vertex.apex import crease_length
from filletfold.vertex.frame import vertex_frame

from .conftest import CHECKS, design_of, random_convex


@pytest.mark.parametrize("check", CHECKS, ids=lambda c: c.__name__[6:])
def test_invariants_on_every_example(example_design, check):
    check(example_design)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 10_000),
    share=st.floats(0.15, 0.7),
    depth=st.floats(0.1, 1.0),
    samples=st.integers(3, 30),
    arc_step=st.sampled_from([0.0, 1.5, 10.0, 60.0]),
)
def test_invariants_on_generated_meshes(seed, share, depth, samples, arc_step):
    """Random convex polyhedra, radii, depths and samplings (down to 2 points on an arc):
    every invariant holds."""
    v, f = random_convex(seed)
    m = filletfold.load_mesh((v, f))[0]
    d = filletfold.round_mesh(
        m,
        radius=share * round_edges(m, 1e-6 * m.mean_edge_length).uniform_limit,
        depth=depth * m.mean_edge_length,
        samples=samples,
        arc_step=arc_step,
    )
    for check in CHECKS:
        check(d)


@pytest.mark.parametrize("name", ["icosahedron", "cube", "random-convex", "dimpled-cube", "house"])
def test_tangent_continuity_at_cylinder_face_joins(name):
    d = design_of(name)
    m, rd = d.mesh, d.rounding
    worst = 0.0
    for u in range(m.n_vertices):
        fr = vertex_frame(m, rd, u)
        V, v = d.vertices.apex[u], d.vertices.apex_developed[u]
        n = len(fr.sides)
        for i, side in enumerate(fr.sides):
            h = 1e-6 * side.arc
            for s, nb in ((side.arc, (i + 1) % n), (0.0, i - 1)):
                l0, _ = crease_length(fr, i, V, v, np.array([s]))
                l1, _ = crease_length(fr, i, V, v, np.array([s - h if s else h]))
                slope = (l0[0] - l1[0]) / (h if s else -h)
                tangent = fr.cyl_map[i][:2, :2] @ np.array([1.0, slope])
                # the straight crease on the neighbouring face, in the same chart
                other = fr.sides[nb]
                so = 0.0 if s else other.arc
                lo, _ = crease_length(fr, nb, V, v, np.array([so]))
                mo = fr.cyl_map[nb] if nb > i or s == 0.0 else fr.face_map[i] @ fr.gluing_start(nb)
                if s == 0.0 and i == 0:
                    mo = fr.cyl_map[n - 1]
                    mo = np.linalg.inv(fr.rho) @ mo
                p_other = mo[:2, :2] @ np.array([so, lo[0]]) + mo[:2, 2]
                l_here, _ = crease_length(fr, i, V, v, np.array([s]))
                p_here = fr.cyl_map[i][:2, :2] @ np.array([s, l_here[0]]) + fr.cyl_map[i][:2, 2]
                seg = p_other - p_here
                cos = abs(seg @ tangent) / np.linalg.norm(seg) / np.linalg.norm(tangent)
                worst = max(worst, np.degrees(np.arccos(min(1.0, cos))))
    assert worst < 1e-3  # degrees; finite-difference slope limits the check itself


@pytest.mark.parametrize("name", ["icosahedron", "cube", "random-convex"])
def test_mismatch_converges_under_refinement(name):
    """Doubling the sampling divides the relative chord mismatch by 4 (absolute: by 8)."""
    rel, ab = [], []
    for n in (9, 17, 33):
        p = design_of(name, samples=n, arc_step=0).pattern
        rel.append(relative_mismatch(p).max())
        ab.append(edge_mismatch(p).max())
    assert 3.8 < rel[0] / rel[1] < 4.2 and 3.8 < rel[1] / rel[2] < 4.2
    assert 7.6 < ab[0] / ab[1] < 8.4 and 7.6 < ab[1] / ab[2] < 8.4


@pytest.mark.parametrize("name", [pytest.param("blob", marks=pytest.mark.slow), "geodesic-sphere"])
def test_mismatch_converges_as_the_arc_step_shrinks(name):
    """Halving the arc step (arcs under (samples - 1) steps) divides the relative chord
    mismatch by about 4: the adaptive sampling refines like the uniform one."""
    rel = []
    for step in (4.0, 2.0, 1.0):
        p = design_of(name, samples=200, arc_step=step).pattern
        rel.append(relative_mismatch(p).max())
    assert 3.5 < rel[0] / rel[1] < 4.5 and 3.5 < rel[1] / rel[2] < 4.5


@pytest.mark.parametrize(
    "step",
    [
        pytest.param(0.0, marks=pytest.mark.slow),
        pytest.param(0.7, marks=pytest.mark.slow),
        1.5,
        5.0,
        45.0,
    ],
)
def test_arc_points_bound_the_turn_between_samples(step):
    """Every arc gets at most ``samples`` points, at least 2, and fewer only when the turn
    between two samples stays within the arc step; the built modules use those counts, or
    more where a cone at the arc's end turns faster than the arc
    (:func:`~filletfold.surface.sampling.cone_sample_counts`)."""
    d = design_of("blob", arc_step=step)
    rd = d.rounding
    n = rd.arc_points(24, step)
    cones = cone_sample_counts(d.stages.solved, d.stages.centres, len(n), step)
    arcs = rd.arc_length > 0
    assert (n[~arcs] == 1).all() and (n[arcs] >= 2).all() and (n <= 24).all()
    turn = np.degrees(2 * rd.half_angle[arcs]) / (n[arcs] - 1)
    fewer = n[arcs] < 24
    if step == 0:
        assert not fewer.any()
    else:
        assert (turn[fewer] <= step * (1 + 1e-9)).all()
        # one point less would exceed the step (unless already at the minimum of 2)
        more = fewer & (n[arcs] > 2)
        assert (np.degrees(2 * rd.half_angle[arcs][more]) / (n[arcs][more] - 2) > step).all()
    assert_allclose(np.asarray(d.stages.samples), np.maximum(n, cones))
    n = np.maximum(n, cones)
    # a cylinder patch of edge e has n[e] - 1 quads on each of its two modules' halves
    quads = {}
    for patch, face in zip(d.pattern.face_patch, d.pattern.faces, strict=True):
        if patch.kind == "cylinder" and len(face) == 4:
            e = patch.index
            quads[e] = quads.get(e, 0) + 1
    for e, count in quads.items():
        assert count <= 2 * (n[e] - 1)
    assert sum(quads.values()) > 0.9 * (2 * (n[arcs] - 1)).sum()


def test_icosahedron_fold_angles_match_reference():
    d = filletfold.round_mesh(
        "icosahedron", radius=0.15, depth=0.3, samples=64, arc_step=0, chord_tol=0
    )
    a = d.pattern.edge_fold_angle[d.pattern.edge_assignment == "M"]
    assert a.min() == pytest.approx(-73.18, abs=0.01)
    assert a.max() == pytest.approx(-64.14, abs=0.01)


def test_real_object_non_saddles_are_solved_or_reported():
    d = design_of("blob")
    counts = d.status_counts()
    assert counts["saddle"] > 0 and counts["ok"] > d.mesh.n_vertices // 2
    for u, status in enumerate(d.vertices.status):
        assert status in ("ok", "saddle", "infeasible")
        if status != "ok":
            assert d.vertices.reason[u]


def test_export_writes_the_four_files(tmp_path):
    d = design_of("cube")
    files = d.export(tmp_path / "out")
    assert sorted(f.name for f in files) == [
        "annotations.json",
        "assembly.txt",
        "design.fold",
        "folded.obj",
        "pattern.svg",
        "report.json",
        "timings.json",
    ]
    fold = json.loads((tmp_path / "out" / "design.fold").read_text())
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert fold["frame_classes"] == ["creasePattern"]
    assert len(fold["vertices_coords"][0]) == 2
    frame = fold["file_frames"][0]
    assert frame["frame_classes"] == ["foldedForm"] and frame["frame_parent"] == 0
    assert frame["frame_inherit"] is True and len(frame["vertices_coords"][0]) == 3
    n_edges = len(fold["filletfold:mesh_edges_vertices"])
    n_faces = len(fold["filletfold:mesh_faces_vertices"])
    assert report["mesh_counts"] == {"vertices": 8, "edges": n_edges, "faces": n_faces}
    for name in fold["filletfold:faces_patch"]:
        kind, idx = re.fullmatch(r"(cone|cylinder|face) (\d+)", name).groups()
        bound = {"cone": 8, "cylinder": n_edges, "face": n_faces}
        assert int(idx) < bound[kind]
    assert fold["filletfold:mesh_vertices_coords"] == d.mesh.vertices.tolist()
    assert report["treatment_counts"] == {"cone": 8, "sharp": 0, "hole": 0}
    assert "edges" not in report and "vertices" not in report  # a summary
    report = d.report()  # the tables
    for e in report["edges"]:
        assert set(e) >= {"vertices", "faces", "radius", "half_angle"}
    assert set(report["vertices"][0]) >= {
        "kind",
        "status",
        "normal",
        "apex",
        "apex_2d",
        "depth",
        "margin",
    }
    # same design, same bytes
    d.export(tmp_path / "again")
    for f in files:
        assert (
            tmp_path / "again" / f.name
        ).read_bytes() == f.read_bytes() or f.name == "timings.json"


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"samples": 2}, ParameterError, "samples must be an integer >= 3"),
        ({"radius": "abc"}, ParameterError, "radius must be a number or a percentage"),
        ({"radius": "-5%"}, ParameterError, "radius must be positive"),
        ({"radius": 3.0, "strict": True}, ParameterError, r"exceeds its limit 0\.5"),
        ({"radius": 3.0, "clamp": False}, ParameterError, r"exceeds its limit 0\.5"),
        ({"depth": -1}, ParameterError, "depth must be positive"),
        ({"depth": float("nan")}, ParameterError, "depth must be finite"),
        ({"depth": np.ones(3)}, ParameterError, r"per-element depth must have shape \(8,\)"),
        ({"depth": {"default": 0.3, 99: 0.2}}, ParameterError, "vertex 99, which does not exist"),
        ({"coplanar_deg": -1}, ParameterError, "coplanar tolerance"),
        ({"arc_step": -1}, ParameterError, r"arc step must be in \[0, 180\] degrees"),
        ({"arc_step": float("nan")}, ParameterError, "arc step must be in"),
        ({"arc_step": "2"}, ParameterError, "arc step must be a number of degrees"),
    ],
)
def test_bad_parameters(kwargs, error, match):
    with pytest.raises(error, match=match):
        filletfold.round_mesh("cube", **kwargs)


def test_unknown_mesh_name():
    with pytest.raises(MeshReadError, match="no built-in example named 'cubee'"):
        filletfold.round_mesh("cubee")


def test_per_vertex_depth():
    d = filletfold.round_mesh("cube", depth={"default": "30%", 3: 0.5})
    assert_allclose(d.vertices.depth_requested[3], 0.5)
    assert_allclose(d.vertices.depth[3], 0.5, atol=1e-9)
    assert_allclose(np.delete(d.vertices.depth, 3), 0.3, atol=1e-9)


def s_prism():
    """A prism over an S-shaped polygon: no point of the S sees all of it."""
    s = np.array(
        [
            [0, 0],
            [3, 0],
            [3, 3],
            [1, 3],
            [1, 4],
            [3, 4],
            [3, 5],
            [0, 5],
            [0, 2],
            [2, 2],
            [2, 1],
            [0, 1],
        ],
        dtype=float,
    )
    n = len(s)
    v = np.vstack([np.c_[s, np.zeros(n)], np.c_[s, np.ones(n)]])
    faces = [list(range(n))[::-1], list(range(n, 2 * n))]
    faces += [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    return v, faces


def test_radii_over_their_limits_are_fitted_by_default():
    d = filletfold.round_mesh("cube", radius=3.0)
    assert np.all(d.rounding.radius <= 0.9 * 0.5 + 1e-12)
    assert len(d.fitting["reduced"]) == d.mesh.n_edges
    assert_allclose(d.fitting["radius_requested"], 3.0)
    assert "fitted" in d.summary()


def test_face_that_is_not_star_shaped_is_split_into_convex_parts():
    d = filletfold.round_mesh(s_prism(), radius=0.05)
    assert any(r.what == "split-face" for r in d.repairs)
    assert d.mesh.corner_angles().max() <= np.pi + 1e-9
    assert "repair" in d.summary()


def test_face_that_is_not_star_shaped_is_named():
    from filletfold.errors import MeshError

    with pytest.raises(MeshError, match=r"face \d+ is not star-shaped"):
        filletfold.round_mesh(s_prism(), radius=0.05, strict=True)


def test_a_mesh_far_from_the_origin_is_computed_about_its_centre():
    """Moved by 1e6 (survey coordinates), a mesh gives the design of the original, moved:
    without centring, every difference of two points would lose six digits."""
    from filletfold.mesh import example_mesh

    v, f = example_mesh("random-convex")
    near = filletfold.round_mesh((v, f))
    far = filletfold.round_mesh((v + 1e6, f))
    assert far.certificate.ok
    assert_allclose(far.mesh.vertices - 1e6, near.mesh.vertices, atol=1e-9)
    assert_allclose(far.pattern.vertices_3d - 1e6, near.pattern.vertices_3d, atol=1e-8)
    assert_allclose(far.pattern.vertices_2d, near.pattern.vertices_2d, atol=1e-8)
    assert_allclose(far.vertices.apex - 1e6, near.vertices.apex, atol=1e-8)
    assert_allclose(far.rounding.axis_point - 1e6, near.rounding.axis_point, atol=1e-8)


def test_infeasible_vertices_are_rescued_with_smaller_radii():
    """On a cube with radius 0.45 every vertex is infeasible; halving its edges' radii once
    makes each cone feasible: applied by default, only named in the reason without."""
    d = filletfold.round_mesh("cube", radius=0.45)
    assert d.status_counts()["ok"] == 8
    assert d.fitting["rescued"] == dict.fromkeys(range(8), 0.5)
    assert_allclose(d.rounding.radius[d.rounding.radius > 0], 0.225)
    assert d.certificate.ok
    assert "vertices rescued: 8 with the radii of their edges scaled by 0.5" in d.summary()
    hint = filletfold.round_mesh("cube", radius=0.45, fit_vertices=False)
    assert hint.status_counts()["infeasible"] == 8
    assert_allclose(hint.rounding.radius[hint.rounding.radius > 0], 0.45)
    assert all(
        "feasible with the radii of its edges multiplied by 0.5" in r for r in hint.vertices.reason
    )
    assert "would be feasible" in hint.summary()


@pytest.mark.slow
@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_a_convex_solid_has_no_infeasible_vertex(seed):
    """Every vertex of a random convex hull gets a cone, with smaller radii where needed, or is
    left sharp (its edges' fillets would be slivers, or no radius helped): no hole."""
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(60, 3))
    p *= rng.uniform(0.8, 1.2, size=(60, 1)) / np.linalg.norm(p, axis=1)[:, None]
    d = filletfold.round_mesh((p, ConvexHull(p).simplices), radius="5%")
    counts = d.status_counts()
    assert counts["infeasible"] == counts["saddle"] == 0
    assert counts["ok"] + counts["sharp"] == d.mesh.n_vertices


def test_a_nearly_developable_vertex_is_exact():
    """float32 coordinates put the angle sums of a developable tessellation only near 2 pi
    (5e-8 off): such a vertex is a cone about the fixed point of its development, or left
    sharp, never treated as closed (its rulings would part by the development's gap)."""
    from filletfold.mesh import example_mesh

    v, f = example_mesh("yoshimura")
    d = filletfold.round_mesh((v.astype(np.float32).astype(float), f))
    assert d.certificate.ok, [c.line() for c in d.certificate.failed]
    assert d.status_counts()["infeasible"] == 0


def test_conical_fillets_are_sampled_by_their_normal_too():
    """A fuzzed hull whose conical fillet turns by 171 degrees: its facets folded 11.4 degrees
    apart at the arc step's 19 points (10 deg step); sampled by the fillet's own normal they
    fold by at most the step."""
    from filletfold.testing.fuzz import case_by_name

    case = case_by_name("hull-10/collapse-edge+quantise#0240")
    d = filletfold.round_mesh((np.asarray(case.vertices), [np.asarray(f) for f in case.faces]))
    assert any(p.kind == "fillet" for p in d.pattern.face_patch)
    assert d.certificate["facet folds"].ok, d.certificate["facet folds"].line()
    assert d.certificate["facet folds"].value <= 10.0


def test_the_reports_fitting_counts_its_lists_and_lists_them_with_the_tables(tmp_path):
    """``report.json`` is a summary: ``fitting`` has the counts of the rescued and sharp
    elements, and their lists only with the per-element tables (``tables=True``)."""
    import json

    d = filletfold.round_mesh("cube", radius=0.45)
    d.export(tmp_path / "summary")
    d.export(tmp_path / "tables", tables=True)
    short = json.loads((tmp_path / "summary" / "report.json").read_text())["fitting"]
    full = json.loads((tmp_path / "tables" / "report.json").read_text())["fitting"]
    lists = ("reduced", "sharp", "creased", "rescued", "sharpened")
    assert not set(lists) & set(short)
    assert {k: v for k, v in full.items() if k not in lists} == short
    assert short["vertices_rescued"] == len(full["rescued"]) == 8
    assert short["edges_sharp"] == len(full["sharp"])
    assert short["vertices_sharpened"] == len(full["sharpened"])
    assert short["radii_reduced"] == len(full["reduced"])
    assert short["edges_creased"] == len(full["creased"]) == 0  # no sheet material
