"""The modules of many vertices at once (build_modules): the same pieces, bit for bit, as one
build_module per vertex; the batched path is taken on convex meshes and by hole modules (saddle,
developable, boundary) and modules split into runs; the batched overlap proof answers as the
per-piece one."""

from __future__ import annotations

import functools
import itertools

import numpy as np
import pytest

import filletfold
from filletfold.mesh import example_names
from filletfold.rounding.edges import round_edges
from filletfold.surface import batch as module_batch
from filletfold.surface import overlap
from filletfold.surface.batch import build_modules
from filletfold.surface.module import build_module
from filletfold.surface.overlap import faces_interior_disjoint, faces_interior_disjoint_many

from .conftest import CLOSED_CONVEX, design_of, jittered_grid, random_convex
from .test_speed_module import annulus_strip

#: Examples whose every module takes the batched path: cones split into runs (blob), saddle
#: holes (torus, saddle-patch), developable holes (miura, resch), open boundary rings.
BATCHED = ("blob", "torus", "saddle-patch", "miura", "chicken-wire", "resch", "open-box", "tent")


@functools.cache
def convex_design(seed: int, samples: int = 24, arc_step: float = 1.5) -> filletfold.Design:
    m = filletfold.load_mesh(random_convex(seed))[0]
    radius = 0.5 * round_edges(m, 1e-3).uniform_limit
    return filletfold.round_mesh(
        m, radius=radius, samples=samples, arc_step=arc_step, tabs=False, layout="modules"
    )


def assert_same_modules(got, want) -> None:
    assert len(got) == len(want)
    for u, (mg, mw) in enumerate(zip(got, want, strict=True)):
        assert len(mg) == len(mw), u
        for pg, pw in zip(mg, mw, strict=True):
            assert pg.vertex == pw.vertex
            for attr in ("points_2d", "points_3d"):
                a, b = getattr(pg, attr), getattr(pw, attr)
                assert isinstance(a, np.ndarray) and a.dtype == b.dtype == np.float64
                assert a.shape == b.shape, (u, attr)
                assert np.array_equal(a, b), (u, attr, float(np.abs(a - b).max()))
            assert pg.faces == pw.faces, u
            assert all(type(i) is int for f in pg.faces for i in f)
            assert pg.patches == pw.patches, u
            assert pg.apex_index == pw.apex_index, u
            assert pg._keys == pw._keys == {}


def compare(design: filletfold.Design, n_samples, monkeypatch) -> float:
    """build_modules against build_module per vertex on the design's frames and apices;
    returns the share of vertices built by the batched path."""
    st = design.stages
    frames, apices, developed = (list(c) for c in zip(*st.solved, strict=True))
    want = [build_module(design.mesh, f, st.centres, n_samples, a, v) for f, a, v in st.solved]
    slow = []

    def counted(mesh, frame, *args):
        slow.append(frame.vertex)
        return build_module(mesh, frame, *args)

    monkeypatch.setattr(module_batch, "build_module", counted)
    got = build_modules(design.mesh, frames, st.centres, n_samples, apices, developed)
    assert_same_modules(got, want)
    return 1 - len(slow) / len(frames)


@pytest.mark.parametrize("name", example_names())
def test_every_example_gives_the_modules_of_build_module(name, monkeypatch):
    d = design_of(name)
    fast = compare(d, d.stages.samples, monkeypatch)
    if name in CLOSED_CONVEX:
        assert fast > 0.9
    if name == "yoshimura":  # creases through a corner T: merge_coincident merges points
        assert fast < 1
    if name in BATCHED:  # saddles, holes, boundaries and modules split into runs
        assert fast == 1.0


@pytest.mark.parametrize(("samples", "arc_step"), [(24, 1.5), (24, 0.0), (3, 1.5), (3, 0.0)])
def test_geodesic_sphere_and_random_convex(samples, arc_step, monkeypatch):
    designs = [design_of("geodesic-sphere:level=2", samples=samples, arc_step=arc_step)]
    designs += [convex_design(seed, samples, arc_step) for seed in range(4)]
    for d in designs:
        assert compare(d, d.stages.samples, monkeypatch) > 0.9


@pytest.mark.parametrize("name", ["geodesic-sphere:level=2", "torus", "resch", "saddle-patch"])
def test_uniform_sample_counts(name, monkeypatch):
    """An int for all arcs, down to 2 points per arc (and 1: a single point on every arc)."""
    d = design_of(name)
    for n in (2, 7):
        fast = compare(d, n, monkeypatch)
        if name != "resch":  # a few of resch's modules merge points with 2 or 7 per arc
            assert fast == 1.0
    compare(d, 1, monkeypatch)


@pytest.mark.parametrize("name", ["torus", "miura", "l-prism", "blob"])
@pytest.mark.parametrize(("radius", "depth"), [("6%", "20%"), ("15%", "45%")])
def test_holes_open_rings_and_runs_at_other_radii(name, radius, depth, monkeypatch):
    """Saddle and developable holes, open boundary rings, modules split into runs (and the
    reflex corners of l-prism, left to build_module) at other radii and depths."""
    d = design_of(name, radius=radius, depth=depth)
    fast = compare(d, d.stages.samples, monkeypatch)
    if name != "l-prism":
        assert fast > 0.9


def test_any_vertices_in_any_order(monkeypatch):
    d = design_of("house")
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


@pytest.mark.parametrize("name", ["geodesic-sphere:level=2", "torus", "chicken-wire"])
def test_chunks(name, monkeypatch):
    """Vertices built in several chunks give the same modules."""
    monkeypatch.setattr(module_batch, "CHUNK", 7)
    d = design_of(name)
    assert compare(d, d.stages.samples, monkeypatch) == 1.0


def test_overlapping_rings_are_split_without_the_union(monkeypatch):
    """The full rings of torus' saddles and resch's developable vertices overlap themselves at
    their cut: a pair of faces there answers without the union, and every vertex is batched."""

    def refused(*args, **kwargs):
        raise AssertionError("not expected here")

    for name in ("torus", "resch"):
        d = design_of(name)
        st = d.stages
        assert max(len(m) for m in st.modules) == 2
        want = [build_module(d.mesh, f, st.centres, st.samples, a, v) for f, a, v in st.solved]
        frames, apices, developed = (list(c) for c in zip(*st.solved, strict=True))
        with monkeypatch.context() as m:
            m.setattr(overlap.shapely, "union_all", refused)
            m.setattr(module_batch, "build_module", refused)
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
        d = design_of(name)
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
