"""Stages split over threads (issue 6) give the designs of one thread, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

import filletfold
from filletfold import parallel
from filletfold.surface import module as module_batch
from filletfold.vertex import solve


def test_thread_map_keeps_order_and_raises(monkeypatch):
    monkeypatch.setenv("FILLETFOLD_THREADS", "2")
    assert list(parallel.thread_map(lambda x: x * x, range(50))) == [x * x for x in range(50)]

    def fail(x):
        if x == 3:
            raise ValueError("part 3")
        return x

    with pytest.raises(ValueError, match="part 3"):
        list(parallel.thread_map(fail, range(6)))


@pytest.mark.parametrize("value, want", [("1", 1), ("3", 3), ("0", 1)])
def test_threads_follow_the_environment(monkeypatch, value, want):
    monkeypatch.setenv("FILLETFOLD_THREADS", value)
    assert parallel.threads() == want


@pytest.mark.parametrize(
    "name, kwargs",
    [
        ("blob", {}),
        ("torus", {}),
        ("geodesic-sphere:level=2", {"depth": 0.5}),
        ("chicken-wire", {"material_loss": True}),
    ],
)
def test_designs_in_threads_are_those_of_one_thread(name, kwargs, monkeypatch):
    """Small slices and chunks, so that the apex rounds and the module chunks run in several
    parts: every per-vertex result and the whole pattern are the same with 1 and 2 threads."""
    monkeypatch.setattr(solve, "ROUND_SLICE", 16)
    monkeypatch.setattr(module_batch, "CHUNK", 16)
    designs = []
    for n in ("1", "2"):
        monkeypatch.setenv("FILLETFOLD_THREADS", n)
        designs.append(filletfold.round_mesh(name, tabs=False, layout="modules", **kwargs))
    one, two = designs
    assert one.vertices.status == two.vertices.status
    assert one.vertices.reason == two.vertices.reason
    for field in ("apex", "apex_developed", "depth", "margin"):
        np.testing.assert_array_equal(getattr(one.vertices, field), getattr(two.vertices, field))
    for field in ("vertices_2d", "vertices_3d", "edges", "edge_assignment", "edge_fold_angle"):
        np.testing.assert_array_equal(getattr(one.pattern, field), getattr(two.pattern, field))
    assert [f.tolist() for f in one.pattern.faces] == [f.tolist() for f in two.pattern.faces]


def test_threads_reject_a_value_that_is_not_a_number(monkeypatch):
    from filletfold.errors import ParameterError

    monkeypatch.setenv("FILLETFOLD_THREADS", "two")
    with pytest.raises(ParameterError, match="FILLETFOLD_THREADS must be a whole number"):
        parallel.threads()
