"""``round_mesh(..., reuse=design)``: only what changed is recomputed, and the result is the
same as a fresh computation (issue 5: a per-vertex depth re-solves one vertex)."""

from __future__ import annotations

import numpy as np
import pytest

import filletfold
import filletfold.pipeline as pipeline
from filletfold.mesh import example_mesh


def test_without_stages_the_pieces_go_before_the_glue_tabs(monkeypatch):
    """keep_stages=False: once the pattern is assembled, the modules' pieces go (the pattern
    holds their points again), before the glue tabs and the certificate; with the stages they
    stay in ``design.pieces``."""
    import gc
    import weakref

    from filletfold.layout import arrange as arrange_module

    refs, alive_at_tabs = [], []
    assemble, add_tabs = arrange_module.assemble_pattern, arrange_module.add_tabs_and_labels

    def spy_assemble(pieces, offsets):
        refs.append(weakref.ref(pieces[0]))
        return assemble(pieces, offsets)

    def spy_tabs(pattern, tab_h, **kwargs):
        gc.collect()
        alive_at_tabs.append(refs[-1]() is not None)
        return add_tabs(pattern, tab_h, **kwargs)

    monkeypatch.setattr(arrange_module, "assemble_pattern", spy_assemble)
    monkeypatch.setattr(arrange_module, "add_tabs_and_labels", spy_tabs)
    kept = filletfold.round_mesh("cube")
    lean = filletfold.round_mesh("cube", keep_stages=False)
    assert alive_at_tabs == [True, False]
    assert len(kept.pieces) > 0 and lean.pieces == []
    np.testing.assert_array_equal(kept.pattern.vertices_2d, lean.pattern.vertices_2d)
    assert kept.pattern.annotations.labels.text == lean.pattern.annotations.labels.text


@pytest.fixture
def solved_vertices(monkeypatch):
    """Record which vertices every ``solve_apices`` call was asked to solve."""
    calls = []
    original = pipeline.solve_apices

    def spy(*args, vertices=None, **kwargs):
        calls.append(list(vertices) if vertices is not None else None)
        return original(*args, vertices=vertices, **kwargs)

    monkeypatch.setattr(pipeline, "solve_apices", spy)
    return calls


def same_design(a: filletfold.Design, b: filletfold.Design) -> None:
    va, vb = a.vertices, b.vertices
    assert va.status == vb.status
    np.testing.assert_array_equal(va.apex, vb.apex)
    np.testing.assert_array_equal(va.depth, vb.depth)
    np.testing.assert_array_equal(va.normal, vb.normal)
    np.testing.assert_array_equal(a.pattern.vertices_2d, b.pattern.vertices_2d)
    np.testing.assert_array_equal(a.pattern.vertices_3d, b.pattern.vertices_3d)
    assert [list(f) for f in a.pattern.faces] == [list(f) for f in b.pattern.faces]


def test_one_vertex_depth_resolves_only_that_vertex(solved_vertices):
    first = filletfold.round_mesh("icosahedron", depth="30%")
    depth = {"default": "30%", 3: 0.4 * first.mesh.mean_edge_length}
    again = filletfold.round_mesh("icosahedron", depth=depth, reuse=first)
    assert solved_vertices[-1] == [3]
    same_design(again, filletfold.round_mesh("icosahedron", depth=depth))
    assert again.vertices.depth[3] != first.vertices.depth[3]


def test_global_depth_reuses_rounding_and_normals(solved_vertices):
    first = filletfold.round_mesh("dodecahedron", depth="30%")
    frames, status = list(first.stages.frames), list(first.stages.classified.status)
    again = filletfold.round_mesh("dodecahedron", depth="40%", reuse=first)
    # the earlier design's stages are left as they were (the new one has lists of its own)
    assert again.stages.frames is not first.stages.frames
    assert all(a is b for a, b in zip(first.stages.frames, frames, strict=True))
    assert list(first.stages.classified.status) == status
    # the same frames (not classified again), in a list of the new design's own
    assert all(a is b for a, b in zip(again.stages.frames, first.stages.frames, strict=True))
    assert len(solved_vertices[-1]) == first.mesh.n_vertices
    same_design(again, filletfold.round_mesh("dodecahedron", depth="40%"))


def test_a_new_radius_recomputes_everything():
    first = filletfold.round_mesh("cube", radius="10%")
    again = filletfold.round_mesh("cube", radius="12%", reuse=first)
    assert not any(a is b for a, b in zip(again.stages.frames, first.stages.frames, strict=True))
    same_design(again, filletfold.round_mesh("cube", radius="12%"))


def test_new_samples_rebuild_modules_but_keep_apices(solved_vertices):
    first = filletfold.round_mesh("octahedron", samples=16)
    again = filletfold.round_mesh("octahedron", samples=32, reuse=first)
    assert solved_vertices[-1] == []
    same_design(again, filletfold.round_mesh("octahedron", samples=32))


def test_reuse_with_a_different_mesh_is_a_fresh_design():
    first = filletfold.round_mesh("cube")
    other = filletfold.round_mesh("tetrahedron", reuse=first)
    same_design(other, filletfold.round_mesh("tetrahedron"))


def test_without_stages_the_frames_go_before_the_layout(monkeypatch):
    """keep_stages=False (the command line): the same pattern, no stages, and the vertex frames
    are freed before the layout and export (a large design's peak memory)."""
    import gc
    import weakref

    refs = []
    classify = pipeline.classify_vertices

    def spy(*args, **kwargs):
        frames = classify(*args, **kwargs)
        refs.append(weakref.ref(frames[0]))
        return frames

    alive_at_layout = []
    arrange = pipeline.arrange

    def layout_spy(*args, **kwargs):
        gc.collect()
        alive_at_layout.append(refs[-1]() is not None)
        return arrange(*args, **kwargs)

    monkeypatch.setattr(pipeline, "classify_vertices", spy)
    monkeypatch.setattr(pipeline, "arrange", layout_spy)
    # (modules: nets re-cut the modules from the frames, so they keep them to the layout)
    kept = filletfold.round_mesh("icosahedron", tabs=False, layout="modules")
    lean = filletfold.round_mesh("icosahedron", tabs=False, keep_stages=False, layout="modules")
    assert kept.stages is not None and lean.stages is None
    np.testing.assert_array_equal(kept.pattern.vertices_2d, lean.pattern.vertices_2d)
    gc.collect()
    assert refs[0]() is not None  # held by kept.stages
    assert refs[1]() is None
    # and already when the layout starts (the cones' sampling cache held them until then)
    assert alive_at_layout == [True, False]


@pytest.fixture
def cleanings(monkeypatch):
    """Count the calls of ``load_mesh`` (which cleans the mesh) made by ``round_mesh``."""
    calls = []
    original = pipeline.load_mesh

    def spy(*args, **kwargs):
        calls.append(args[0])
        return original(*args, **kwargs)

    monkeypatch.setattr(pipeline, "load_mesh", spy)
    return calls


@pytest.mark.parametrize("shift", [0.0, 1e6])  # 1e6: computed about the centre (far_offset)
def test_the_same_polymesh_is_cleaned_once(cleanings, shift):
    """A new radius on the same PolyMesh (what the app does) takes the cleaned mesh over and
    gives the design a fresh call gives, array for array; a different mesh or coplanar
    tolerance is cleaned again."""
    vertices, faces = example_mesh("house")
    mesh = filletfold.PolyMesh(np.asarray(vertices) + shift, faces)
    first = filletfold.round_mesh(mesh, radius="10%", tabs=False)
    again = filletfold.round_mesh(mesh, radius="12%", tabs=False, reuse=first)
    assert len(cleanings) == 1
    assert again.stages.cleaned[1] is first.stages.cleaned[1]
    fresh = filletfold.round_mesh(mesh, radius="12%", tabs=False)
    assert len(cleanings) == 2
    same_design(again, fresh)
    np.testing.assert_array_equal(again.mesh.vertices, fresh.mesh.vertices)
    assert again.repairs == fresh.repairs
    copy = filletfold.PolyMesh(mesh.vertices.copy(), mesh.faces)  # equal arrays: taken over
    filletfold.round_mesh(copy, radius="10%", tabs=False, reuse=again)
    assert len(cleanings) == 2
    moved = filletfold.PolyMesh(mesh.vertices * 1.01, mesh.faces)
    same_design(
        filletfold.round_mesh(moved, tabs=False, reuse=first),
        filletfold.round_mesh(moved, tabs=False),
    )
    filletfold.round_mesh(mesh, tabs=False, coplanar_deg=2.0, reuse=first)
    assert len(cleanings) == 5
