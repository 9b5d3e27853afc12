"""Vertex classification, normals, developed and spatial apices (sec. 2.4, 2.5, 3.1, 3.2).

Reference figures are those of docs/method.md, 'Reference figures' (edge length 1).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import filletfold
from filletfold.mesh import load_mesh
from filletfold.rounding.edges import round_edges
from filletfold.tolerances import tol
from filletfold.vertex.apex import build_constraints, validate_apex
from filletfold.vertex.batch import solve_apex
from filletfold.vertex.frame import developed_apices, vertex_frame, vertex_frames
from filletfold.vertex.normal import max_min_direction, vertex_normal

from ..conftest import ALL, CLOSED_CONVEX, design_of, folded_degree4_vertex, random_convex


def frame_of(name, r, u=0):
    m = load_mesh(name)[0]
    return m, vertex_frame(m, round_edges(m, r), u)


def test_icosahedron_reference_figures():
    m, fr = frame_of("icosahedron", 0.15)
    D, b, sigma = vertex_normal(np.array([s.R for s in fr.sides]), m.face_normal[fr.ring.faces])
    assert sigma == -1
    assert_allclose(b, 0.52573, atol=5e-6)
    assert_allclose(D, -fr.U / np.linalg.norm(fr.U), atol=1e-7)
    assert_allclose(np.degrees(fr.rotation_angle()), -60.0, atol=1e-9)
    w = 2 * 0.15 * (np.tan(fr.sides[0].gamma) - fr.sides[0].gamma)
    assert_allclose(np.linalg.norm(fr.developed_apex()), w, rtol=1e-9)
    assert_allclose(w, 0.005131, atol=5e-7)


def test_cube_reference_figures():
    _, fr = frame_of("cube", 0.1)
    assert_allclose(np.degrees(fr.rotation_angle()), -90.0, atol=1e-9)
    w = 2 * 0.1 * (np.tan(np.pi / 4) - np.pi / 4)
    assert_allclose(np.linalg.norm(fr.developed_apex()), w / 2 * np.sqrt(2), rtol=1e-9)
    assert_allclose(np.linalg.norm(fr.developed_apex()), 0.030349, atol=5e-7)


@pytest.mark.parametrize("name", ALL)
def test_rho_turns_by_minus_the_defect(name):
    m = load_mesh(name)[0]
    rd = round_edges(m, "10%" and 0.1 * m.mean_edge_length)
    for u in range(m.n_vertices):
        fr = vertex_frame(m, rd, u)
        if not fr.ring.closed:
            continue
        defect = 2 * np.pi - m.vertex_angle_sum[u]
        turn = fr.rotation_angle()
        assert abs(np.angle(np.exp(1j * (turn + defect)))) < 1e-9
        v = fr.developed_apex()
        if v is not None:  # v is the fixed point of rho
            assert_allclose(fr.rho[:2, :2] @ v + fr.rho[:2, 2], v, atol=1e-12)


def test_one_developed_apex_for_pipeline_and_frame():
    """The pipeline's developed apices (:func:`developed_apices` of all frames at once) are
    :meth:`VertexFrame.developed_apex` of each frame, and the fixed points of rho."""
    d = filletfold.round_mesh("random-convex")
    frames = vertex_frames(d.mesh, d.rounding, range(d.mesh.n_vertices))
    got = developed_apices(np.array([f.rho for f in frames]))
    for u, fr in enumerate(frames):
        one = fr.developed_apex()
        assert one is not None
        np.testing.assert_array_equal(one, got[u])
        assert_allclose(fr.rho[:2, :2] @ one + fr.rho[:2, 2], one, atol=1e-13)
        if d.vertices.status[u] == "ok":
            np.testing.assert_array_equal(d.vertices.apex_developed[u], one)
    # a translation has no fixed point
    shift = np.eye(3)
    shift[:2, 2] = (0.1, 0.2)
    assert np.isnan(developed_apices(shift[None])).all()


def test_icosahedron_depth_window_projects():
    """Depths outside the window [0.13, 0.53] (r = 0.15) are projected to its ends."""
    _, fr = frame_of("icosahedron", 0.15)
    D = -fr.U / np.linalg.norm(fr.U)
    v = fr.developed_apex()
    used = {}
    for d in (0.05, 0.3, 0.8):
        cons = build_constraints(fr, v, -1, 9, 0.0)
        sol = solve_apex(cons, fr.U + d * D, [fr.U + t * D for t in (0.25, 0.5, 1.0)])
        assert sol.ok
        assert validate_apex(fr, sol.apex, v, -1).ok
        used[d] = (sol.apex - fr.U) @ D
    assert_allclose(used[0.3], 0.3, atol=1e-12)
    assert 0.125 < used[0.05] < 0.135
    assert 0.53 < used[0.8] < 0.54


def test_depth_used_is_reported():
    d = filletfold.round_mesh("icosahedron", radius=0.15, depth=0.05)
    assert d.status_counts()["ok"] == 12
    assert np.all(d.vertices.depth > 0.125) and np.all(d.vertices.depth < 0.145)
    assert_allclose(d.vertices.depth_requested, 0.05)


@pytest.mark.parametrize("depth", ["15%", "30%", "45%", "60%"])
@pytest.mark.parametrize("name", ["icosahedron", "cube"])
def test_done_when_all_ok_over_depths(name, depth):
    d = design_of(name, radius="10%", depth=depth)
    assert d.status_counts()["ok"] == d.mesh.n_vertices


def test_saddles_are_classified():
    for name, expect in (("l-prism", 2), ("torus", 24), ("saddle-patch", 9)):
        d = design_of(name)
        assert d.status_counts()["saddle"] == expect
        for u, st_ in enumerate(d.vertices.status):
            if st_ == "saddle":
                assert d.vertices.normal_bound[u] <= tol.normal_bound
                assert "saddle" in d.vertices.reason[u]
                assert np.all(np.isnan(d.vertices.apex[u]))


@pytest.mark.parametrize("name", CLOSED_CONVEX)
def test_convex_solids_have_back_side_normals(name):
    d = design_of(name)
    assert np.all(d.vertices.sigma == -1)
    assert np.all(d.vertices.solid_angle > 2 * np.pi)


@pytest.mark.parametrize("name", CLOSED_CONVEX)
def test_apices_of_convex_solids_lie_inside(name):
    d = design_of(name)
    m = d.mesh
    for u in range(m.n_vertices):
        V = d.vertices.apex[u]
        assert d.vertices.status[u] == "ok"
        for f, face in enumerate(m.faces):
            assert (V - m.vertices[face[0]]) @ m.face_normal[f] < 0


def test_boundary_vertices_are_reported():
    d = design_of("open-box")
    m = d.mesh
    for u in range(m.n_vertices):
        assert (d.vertices.status[u] == "boundary") == bool(m.is_boundary_vertex[u])


def test_max_min_direction_matches_brute_force():
    rng = np.random.default_rng(3)
    for _ in range(20):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        u = rng.normal(size=(6, 3)) * 0.6 + axis
        u /= np.linalg.norm(u, axis=1)[:, None]
        d, b = max_min_direction(u)
        cand = rng.normal(size=(20000, 3))
        cand /= np.linalg.norm(cand, axis=1)[:, None]
        assert b >= (cand @ u.T).min(axis=1).max() - 1e-6
        assert_allclose(np.linalg.norm(d), 1.0)


@pytest.mark.slow  # fast tier near its budget: in make test-slow (CI runs both)
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), share=st.floats(0.2, 0.6), depth=st.floats(0.1, 0.8))
def test_random_convex_polyhedra_every_solved_apex_is_valid(seed, share, depth):
    """Whatever the instance, an ok vertex passes the dense check, and no vertex is a saddle."""
    v, f = random_convex(seed)
    m = load_mesh((v, f))[0]
    limit = round_edges(m, 1e-6 * m.mean_edge_length).uniform_limit
    d = filletfold.round_mesh(m, radius=share * limit, depth=depth * m.mean_edge_length)
    assert d.status_counts()["saddle"] == 0
    rd = d.rounding
    for u in range(m.n_vertices):
        if d.vertices.status[u] == "sharp":  # every edge left sharp (a fillet of a sliver)
            assert rd.sharp[m.vertex_ring(u).edges].all()
            continue
        if d.vertices.status[u] != "ok":
            assert d.vertices.status[u] == "infeasible" and d.vertices.reason[u]
            continue
        fr = vertex_frame(d.mesh, rd, u)
        check = validate_apex(fr, d.vertices.apex[u], fr.developed_apex(), -1, n_samples=513)
        assert check.ok, check.failing


def test_developable_vertex_is_detected_and_reported():
    v, f = folded_degree4_vertex()
    m = load_mesh((v, f))[0]
    u = int(np.argmin(np.linalg.norm(m.vertices, axis=1)))
    assert abs(m.vertex_angle_sum[u] - 2 * np.pi) < 1e-12
    d = filletfold.round_mesh(m, radius="2%", layout="modules")
    assert d.vertices.status[u] == "developable"
    assert "material loss" in d.vertices.reason[u]
    assert np.all(np.isnan(d.vertices.apex[u]))
    # its module still exists, without a cone, and the pattern stays valid
    assert u in d.pattern.piece_vertex
    assert not any(str(p) == f"cone {u}" for p in d.pattern.face_patch)


def test_crease_through_T_gives_a_clean_module():
    """At l = l_max the straight crease on a face has zero length (docs/method.md,
    'Corrections to the paper', 11): the apex on the icosahedron vertex's axis at the depth
    where the creases run through every T (to round-off: the two ends of each straight crease
    are then merged)."""
    from scipy.optimize import brentq

    from filletfold.surface.centres import face_piece_centres
    from filletfold.surface.faces import face_polygons
    from filletfold.surface.module import build_module
    from filletfold.vertex.apex import crease_length

    m = load_mesh("icosahedron")[0]
    rd = round_edges(m, 0.15)
    fr = vertex_frame(m, rd, 0)
    v = fr.developed_apex()
    D = -fr.U / np.linalg.norm(fr.U)

    def beyond_t(depth):
        l_end, _ = crease_length(fr, 0, fr.U + depth * D, v, np.array([fr.sides[0].arc]))
        return l_end[0] - fr.lmax_end[0]

    apex = fr.U + brentq(beyond_t, 0.0, 0.3, xtol=1e-17) * D
    for i in range(fr.n_sides):
        ends, _ = crease_length(fr, i, apex, v, np.array([0.0, fr.sides[i].arc]))
        assert_allclose(ends, [fr.lmax_start[i], fr.lmax_end[i]], rtol=1e-13)
    pieces = build_module(m, fr, face_piece_centres(m, rd), 24, apex, v)
    assert len(pieces) == 1
    p2, _ = pieces[0].arrays()
    polys = face_polygons(p2, pieces[0].faces)
    assert np.all([q.is_valid for q in polys]) and min(q.area for q in polys) > 1e-6
    used = {i for f in pieces[0].faces for i in f}
    assert used == set(range(len(p2)))


def test_cut_samples_come_back_on_the_same_sides_when_the_radii_change():
    """The samples a vertex's solves added, kept per mesh edge as fractions of the arc, land
    on the same sides of a frame with other radii, at the same fraction of each arc; a
    side that is flat there (radius 0) or missing gets none."""
    from filletfold.vertex.solve import cut_fractions, cut_samples

    m = load_mesh("icosahedron")[0]
    u = 0
    big = vertex_frame(m, round_edges(m, 0.2), u)
    small_r = np.full(m.n_edges, 0.2)
    ring = big.ring.edges
    small_r[ring[1]] *= 0.5
    small_r[ring[2]] = 0.0
    small = vertex_frame(m, round_edges(m, small_r), u)
    arc = big.arrays.arc
    extra = np.array([[0, 0.25 * arc[0]], [1, 0.5 * arc[1]], [2, 0.75 * arc[2]]])
    frac = cut_fractions(big, extra)
    assert_allclose(frac, [[ring[0], 0.25], [ring[1], 0.5], [ring[2], 0.75]])
    assert_allclose(cut_samples(big, frac), extra)
    again = cut_samples(small, frac)  # side 2 is flat now: its sample is left out
    assert_allclose(again, [[0, 0.25 * small.arrays.arc[0]], [1, 0.5 * small.arrays.arc[1]]])
    assert_allclose(small.arrays.arc[1], 0.5 * arc[1])
    assert cut_samples(small, np.array([[10**6, 0.5]])).shape == (0, 2)  # not its edge


def test_a_vertex_solved_again_starts_with_the_samples_its_solve_added(monkeypatch):
    """``solve_apices(cuts=)`` notes the samples each vertex ended with; solving the same
    vertices again from the dict needs no cut round (fewer problems) and gives apices that
    pass the same validation."""
    import filletfold.vertex.solve as solve

    d = filletfold.round_mesh("blob", tabs=False, certify=False)
    frames, res0 = d.stages.frames, d.stages.classified
    todo = [u for u in range(len(frames)) if res0.status[u] == "" and not frames[u].sharp]
    counted = []
    real = solve.solve_apex_batch

    def counting(problems, *a, **k):
        counted[-1] += len(problems)
        return real(problems, *a, **k)

    monkeypatch.setattr(solve, "solve_apex_batch", counting)
    runs = []
    cuts: dict = {}  # filled by the first solve, read (and filled again) by the second
    for _ in range(2):
        res = solve.VertexResult.empty(len(frames))
        res.take(res0, range(len(frames)))
        counted.append(0)
        solve.solve_apices(frames, d.stages.depths, res, d.stages.centres, vertices=todo, cuts=cuts)
        runs.append(res)
    res1, res2 = runs
    assert set(cuts) == set(todo)
    added = sum(len(c) for c in cuts.values())
    assert added > 0  # blob's solves add samples: the test sees the hints at work
    assert counted[1] < counted[0]
    assert [res1.status[u] for u in todo] == [res2.status[u] for u in todo]
    assert all(res2.status[u] != "ok" or res2.margin[u] > -1e-9 for u in todo)
