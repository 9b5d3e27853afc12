"""Cones no sampling can follow (filletfold.surface.sampling.unsampled_cones): found, and made
sharp by the design rather than drawn with sliver edges or facets folded past the arc step."""

from __future__ import annotations

import numpy as np
import pytest

import filletfold
import filletfold.pipeline as pipeline
from filletfold.surface.sampling import (
    MAX_CONE_SAMPLES,
    SAFETY,
    cone_sample_counts,
    cone_sample_needs,
    unsampled_cones,
)

from ..conftest import design_of


def test_counts_are_the_needs_capped():
    d = design_of("icosahedron", arc_step=10.0)
    solved, centres = d.stages.solved, d.stages.centres
    edge, vertex, count, arc = cone_sample_needs(solved, centres, 10.0)
    assert len(edge) == len(vertex) == len(count) == len(arc) > 0
    assert (arc > 0).all() and (count >= 2).all()
    need = cone_sample_counts(solved, centres, d.mesh.n_edges, 10.0)
    for e in range(d.mesh.n_edges):
        mine = count[edge == e]
        assert need[e] == (min(mine.max(), MAX_CONE_SAMPLES) if len(mine) else 1)


def test_which_cones_cannot_be_sampled():
    d = design_of("icosahedron", arc_step=10.0)
    solved, centres = d.stages.solved, d.stages.centres
    assert unsampled_cones(solved, centres, 10.0, 0.0) == {}  # a regular solid: none
    assert unsampled_cones(solved, centres, 0.0, 1.0) == {}  # no step: no bound
    _, vertex, count, arc = cone_sample_needs(solved, centres, 10.0)
    # chords as long as the shortest arc: that arc has room for its two ends only
    tight = unsampled_cones(solved, centres, 10.0, float(arc.min()))
    most = np.maximum(np.floor(arc / arc.min()).astype(int) + 1, 2)
    assert set(tight) == set(vertex[np.ceil((count - 1) * SAFETY) + 1 > most].tolist())
    assert tight and "edge" in next(iter(tight.values()))
    # a step so small that the needs exceed MAX_CONE_SAMPLES
    fine = unsampled_cones(solved, centres, 0.01, 0.0)
    assert set(fine) == set(vertex.tolist())


@pytest.mark.slow  # fast tier near its budget: in make test-slow (CI runs both)
def test_a_cone_that_cannot_be_sampled_is_made_sharp(monkeypatch):
    """The design makes such a vertex sharp (its corner kept, its fillets tapering into it),
    solves its neighbours again, and stays valid: a blob vertex stands in for the sliver cone
    of a 166k-face scan (face000.ply), whose arcs needed chords of 5e-8 of its size."""
    plain = filletfold.round_mesh("blob")
    target = int(np.flatnonzero(np.array(plain.vertices.status) == "ok")[0])
    real = pipeline.unsampled_cones

    def one(cones, centres, step, min_chord, cache=None):
        found = real(cones, centres, step, min_chord, cache)
        if any(f.vertex == target for f, *_ in cones):
            found[target] = "its cone folds too sharply (test)"
        return found

    monkeypatch.setattr(pipeline, "unsampled_cones", one)
    d = filletfold.round_mesh("blob")
    assert d.vertices.status[target] == "infeasible"
    assert d.vertices.treatment[target] == "sharp" and "too sharply" in d.vertices.reason[target]
    assert np.isnan(d.vertices.apex[target]).all()
    assert d.certificate.ok, [c.name for c in d.certificate.failed]
    assert d.status_counts()["ok"] >= plain.status_counts()["ok"] - 8


def test_a_cone_measured_once_is_not_measured_again(monkeypatch):
    """The apex stage's check and the surface's sampling share their measurements: the same
    rows with the cache, and no chunk built for a cone whose frame and apex did not change."""
    import filletfold.surface.module as module

    d = design_of("blob", arc_step=10.0)
    solved, centres = d.stages.solved, d.stages.centres
    plain = cone_sample_needs(solved, centres, 10.0)
    cache: dict = {}
    first = cone_sample_needs(solved, centres, 10.0, cache)
    built = []
    real = module._Chunk.of
    monkeypatch.setattr(module._Chunk, "of", lambda *a, **k: built.append(1) or real(*a, **k))
    again = cone_sample_needs(solved, centres, 10.0, cache)
    assert not built
    for a, b, c in zip(plain, first, again, strict=True):
        key = np.lexsort((plain[0], plain[1]))
        assert np.array_equal(a[key], b[key]) and np.array_equal(
            a[key], c[np.lexsort((again[0], again[1]))]
        )
    # a cone whose apex moved is measured again
    u = next(i for i, x in enumerate(solved) if x[1] is not None and not x[0].sharp)
    moved = list(solved)
    moved[u] = (solved[u][0], np.asarray(solved[u][1]) + 1e-3, solved[u][2])
    cone_sample_needs(moved, centres, 10.0, cache)
    assert len(built) == 1
