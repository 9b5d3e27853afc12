"""The modules of all vertices at once (build_modules, the one path): the same pieces, to
round-off, as the per-vertex oracle of tests/reference/module.py, for cones, hole modules
(saddle, developable, boundary), modules split into runs, reflex corners, hole borders through
a corner T and merged points; the batched overlap proof answers as the per-piece one."""

from __future__ import annotations

import functools
import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import filletfold
from filletfold.mesh import example_names
from filletfold.rounding.edges import round_edges
from filletfold.surface import module, overlap
from filletfold.surface.module import apply_rows, build_modules
from filletfold.surface.overlap import (
    faces_interior_disjoint,
    faces_interior_disjoint_many,
)
from filletfold.vertex.frame import apply

from ..conftest import annulus_strip, design_of, jittered_grid, random_convex, rotation
from ..reference.module import build_module


@functools.cache
def convex_design(seed: int, samples: int = 24, arc_step: float = 1.5) -> filletfold.Design:
    m = filletfold.load_mesh(random_convex(seed))[0]
    radius = 0.5 * round_edges(m, 1e-3).uniform_limit
    return filletfold.round_mesh(
        m,
        radius=radius,
        samples=samples,
        arc_step=arc_step,
        tabs=False,
        layout="modules",
        sharp="none",
    )


def assert_same_modules(got, want) -> None:
    """The same pieces: the same faces, patches and apex, the points equal to round-off."""
    assert len(got) == len(want)
    for u, (mg, mw) in enumerate(zip(got, want, strict=True)):
        assert len(mg) == len(mw), u
        for pg, pw in zip(mg, mw, strict=True):
            assert pg.vertex == pw.vertex
            for attr in ("points_2d", "points_3d"):
                a, b = getattr(pg, attr), getattr(pw, attr)
                assert isinstance(a, np.ndarray) and a.dtype == np.float64
                assert a.shape == np.shape(b), (u, attr)
                scale = max(1.0, float(np.abs(b).max(initial=0.0)))
                np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * scale, err_msg=f"{u} {attr}")
            assert pg.faces == pw.faces, u
            assert all(type(i) is int for f in pg.faces for i in f)
            assert pg.patches == pw.patches, u
            assert pg.apex_index == pw.apex_index, u
            assert pg._keys == pw._keys == {}


def compare(design: filletfold.Design, n_samples) -> None:
    """build_modules against the per-vertex oracle (tests/reference/module.py) on the design's
    frames and apices."""
    st = design.stages
    frames, apices, developed = (list(c) for c in zip(*st.solved, strict=True))
    want = [build_module(design.mesh, f, st.centres, n_samples, a, v) for f, a, v in st.solved]
    got = build_modules(design.mesh, frames, st.centres, n_samples, apices, developed)
    assert_same_modules(got, want)


@pytest.mark.parametrize("name", example_names())
def test_every_example_gives_the_modules_of_the_oracle(name):
    """Cones split into runs (blob), saddle holes (torus, saddle-patch), developable holes
    (miura, resch), open boundary rings, reflex corners (l-prism), creases through a corner T
    whose points merge (yoshimura)."""
    d = design_of(name, sharp="none")
    compare(d, d.stages.samples)


#: The default sampling runs in the fast tier, the others (7 s) in the slow one.
SAMPLINGS = [(24, 1.5)] + [
    pytest.param(*c, marks=pytest.mark.slow) for c in [(24, 0.0), (3, 1.5), (3, 0.0)]
]


@pytest.mark.slow  # fast tier near its budget: in make test-slow (CI runs both)
@pytest.mark.parametrize(("samples", "arc_step"), SAMPLINGS)
def test_geodesic_sphere_and_random_convex(samples, arc_step):
    designs = [
        design_of("geodesic-sphere:level=2", samples=samples, arc_step=arc_step, sharp="none")
    ]
    designs += [convex_design(seed, samples, arc_step) for seed in range(4)]
    for d in designs:
        compare(d, d.stages.samples)


@pytest.mark.parametrize("name", ["geodesic-sphere:level=2", "torus", "resch", "saddle-patch"])
def test_uniform_sample_counts(name):
    """An int for all arcs, down to 2 points per arc (and 1: a single point on every arc)."""
    d = design_of(name, sharp="none")
    for n in (1, 2, 7):
        compare(d, n)


@pytest.mark.parametrize("name", ["torus", "miura", "l-prism", "blob"])
@pytest.mark.parametrize(("radius", "depth"), [("6%", "20%"), ("15%", "45%")])
def test_holes_open_rings_and_runs_at_other_radii(name, radius, depth):
    """Saddle and developable holes, open boundary rings, modules split into runs and the
    reflex corners of l-prism at other radii and depths."""
    d = design_of(name, radius=radius, depth=depth, sharp="none")
    compare(d, d.stages.samples)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["pyvista-ant.ply", "compas-tubemesh.obj"])
def test_real_meshes_give_the_modules_of_the_oracle(name):
    """Hole borders through a corner T (28 of the ant's hole modules), sharp edges whose
    points merge, fitted radii: what the examples do not have."""
    from pathlib import Path

    corpus = Path(__file__).parent.parent / "data" / "corpus"
    d = filletfold.round_mesh(corpus / name, tabs=False, sharp="none")
    compare(d, d.stages.samples)


def test_any_vertices_in_any_order():
    d = design_of("house", sharp="none")
    st = d.stages
    order = [7, 2, 9, 0, 2]
    frames = [st.solved[u][0] for u in order]
    want = [
        build_module(d.mesh, f, st.centres, st.samples, a, v)
        for f, a, v in (st.solved[u] for u in order)
    ]
    got = build_modules(
        d.mesh,
        frames,
        st.centres,
        st.samples,
        [st.solved[u][1] for u in order],
        [st.solved[u][2] for u in order],
    )
    assert_same_modules(got, want)
    assert build_modules(d.mesh, [], st.centres, st.samples, [], []) == []
    with pytest.raises(ValueError, match="frames"):
        build_modules(d.mesh, frames, st.centres, st.samples, [], [])
    with pytest.raises(ValueError, match="at least one sample"):
        build_modules(d.mesh, frames, st.centres, 0, [None] * 5, [None] * 5)


def test_one_vertex_built_alone_is_the_same_as_in_the_batch():
    """build_module (a batch of one) gives a vertex the pieces it gets among all the others: a
    module does not depend on the vertices built beside it."""
    d = design_of("blob", sharp="none")
    st = d.stages
    frames, apices, developed = (list(c) for c in zip(*st.solved, strict=True))
    together = build_modules(d.mesh, frames, st.centres, st.samples, apices, developed)
    for u in range(0, len(frames), 9):
        alone = module.build_module(
            d.mesh, frames[u], st.centres, st.samples, apices[u], developed[u]
        )
        assert_same_modules([alone], [together[u]])


@pytest.mark.parametrize("name", ["geodesic-sphere:level=2", "torus", "chicken-wire"])
def test_chunks(name, monkeypatch):
    """Vertices built in several chunks give the same modules."""
    monkeypatch.setattr(module, "CHUNK", 7)
    d = design_of(name, sharp="none")
    compare(d, d.stages.samples)


def test_overlapping_rings_are_split_without_the_union(monkeypatch):
    """The full rings of torus' saddles and resch's developable vertices overlap themselves at
    their cut: a pair of faces there answers without the union."""

    def refused(*args, **kwargs):
        raise AssertionError("not expected here")

    for name in ("torus", "resch"):
        d = design_of(name, sharp="none")
        st = d.stages
        assert max(len(m) for m in st.modules) == 2
        want = [build_module(d.mesh, f, st.centres, st.samples, a, v) for f, a, v in st.solved]
        frames, apices, developed = (list(c) for c in zip(*st.solved, strict=True))
        with monkeypatch.context() as m:
            m.setattr(overlap.shapely, "union_all", refused)
            got = build_modules(d.mesh, frames, st.centres, st.samples, apices, developed)
        assert_same_modules(got, want)


# ---------------------------------------------------------------- the batched overlap proof


def _square_pieces():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    yield np.vstack([square, square + 0.5]), [[0, 1, 2, 3], [4, 5, 6, 7]]  # two loops
    yield square, [[0, 2, 1, 3]]  # bow tie
    yield square, [[3, 2, 1, 0]]  # clockwise
    yield square, [[0, 1, 2, 3]]
    yield square, [[0, 1, 2], [0, 2, 3]]
    yield square, [[0, 1]]  # too few corners
    yield square, []
    pts = np.array([[0, 0], [1, 0], [0, 1], [0.3, 0.3]], dtype=float)
    yield pts, [[0, 1, 2], [1, 3, 2][::-1]]  # folded back
    pts = np.array([[0, 0], [2, 0], [1, 1], [1, 2]], dtype=float)
    yield pts, [[0, 1, 2], [0, 1, 3]]  # one directed edge twice
    pts = np.vstack([square, square + 1.0])
    yield pts, [[0, 1, 2, 3], [4, 5, 6, 7]]  # touching at a corner
    pts = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2], [3, 0], [3, 1]], dtype=float)
    yield pts, [[0, 1, 2, 3, 4, 5], [1, 6, 7, 2]]  # non-convex face
    inside = pts.copy()
    inside[6] = [1.5, 0.5]
    yield inside, [[0, 1, 2, 3, 4, 5], [1, 6, 7, 2]]
    bow = pts.copy()
    bow[[4, 5]] = bow[[5, 4]]
    yield bow, [[0, 1, 2, 3, 4, 5], [1, 6, 7, 2]]  # non-convex and invalid
    for turn, fan in itertools.product([1.0, np.pi, 1.9 * np.pi, 2.0 * np.pi, 3.5 * np.pi], [0, 1]):
        yield annulus_strip(turn, fan=bool(fan))
    rng = np.random.default_rng(3)
    for jitter in (0.0, 0.3, 0.6, 0.9):
        yield jittered_grid(rng, 4, jitter)


def _module_pieces():
    """Pieces of real modules, and whole modules that overlap themselves."""
    for name in ("torus", "l-prism", "blob", "yoshimura"):
        d = design_of(name, sharp="none")
        for piece in d.pieces[:40]:
            yield piece.arrays()[0], piece.faces
        st = d.stages
        for frame, apex, v in st.solved[:40]:
            (whole,) = build_module(
                d.mesh,
                frame,
                st.centres,
                st.samples,
                apex,
                v,
                runs=[(0, len(frame.ring.faces) - 1)],
            )
            yield whole.arrays()[0], whole.faces


def test_batched_proof_answers_as_the_per_piece_one():
    """Many pieces proved at once (in two orders) get the answers each gets alone."""
    cases = [*_square_pieces(), *_module_pieces()]
    want = np.array([faces_interior_disjoint(p, f) for p, f in cases])
    assert want.any() and not want.all()
    for order in (np.arange(len(cases)), np.random.default_rng(0).permutation(len(cases))):
        pts = [cases[i][0] for i in order]
        base = np.cumsum([0] + [len(p) for p in pts])
        faces = [
            [base[k] + np.asarray(f, dtype=np.int64) for f in cases[i][1]]
            for k, i in enumerate(order)
        ]
        size = np.array([len(f) for fs in faces for f in fs], dtype=np.int64)
        flat = np.concatenate([f for fs in faces for f in fs])
        piece = np.repeat(np.arange(len(order)), [len(fs) for fs in faces])
        got = faces_interior_disjoint_many(np.vstack(pts), flat, size, piece, len(order))
        assert np.array_equal(got, want[order])


# ---------------------------------------------------------------- bitwise helpers


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40))
def test_apply_rows_is_apply_row_by_row(seed, n):
    """Batched 2D maps give the bits of one ``apply`` per row (else the patterns would move)."""
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(n, 2)) * 10.0 ** rng.integers(-3, 3)
    m = rotation(rng.uniform(0, 2 * np.pi), rng.normal(size=2) * 5)
    one = np.vstack([apply(m, q) for q in p])
    assert np.array_equal(apply_rows(m, p), one)
    maps = np.stack([rotation(a, rng.normal(size=2)) for a in rng.uniform(0, 7, size=n)])
    each = np.vstack([apply(mk, q) for mk, q in zip(maps, p, strict=True)])
    assert np.array_equal(apply_rows(maps, p), each)
