"""Shared fixtures: designs of every built-in example, computed once per session."""

from __future__ import annotations

import functools
import itertools

import numpy as np
import pytest
from hypothesis import settings
from scipy.spatial import ConvexHull

import filletfold
from filletfold.mesh import EXAMPLES, example_names
from filletfold.vertex import batch

ALL = example_names()
CLOSED_CONVEX = [n for n, e in EXAMPLES.items() if "convex" in e.kinds and e.closed]


@functools.cache
def design_of(
    name: str, radius="10%", depth="30%", samples: int = 24, arc_step: float = 1.5
) -> filletfold.Design:
    """Round a built-in example (cached: designs are read-only in the tests)."""
    return filletfold.round_mesh(
        name, radius=radius, depth=depth, samples=samples, arc_step=arc_step
    )


@pytest.fixture(autouse=True)
def _numpy_interior_point(request, monkeypatch):
    """Every test but the kernel's own solves with the numpy interior-point method, whatever
    is installed and whatever an earlier test loaded: the same bits in every order (the
    kernel agrees to rounding, and test_batch_kernel.py checks that)."""
    if request.node.path.name != "test_batch_kernel.py":
        monkeypatch.setattr(batch, "USE_KERNEL", False)


@pytest.fixture(params=ALL)
def example_design(request) -> filletfold.Design:
    return design_of(request.param)


def random_convex(seed: int):
    """A random convex polyhedron (triangles, outward) from ``seed``."""
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(12, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    p *= rng.uniform(0.8, 1.2, size=(12, 1)) * np.array([1.0, 1.3, 0.8])
    hull = ConvexHull(p)
    faces = []
    for s, eq in zip(hull.simplices, hull.equations, strict=True):
        a, b, c = p[s]
        faces.append(s if np.cross(b - a, c - a) @ eq[:3] > 0 else s[::-1])
    return p, faces


def signed_volume(mesh) -> float:
    """Signed volume of a closed mesh (positive when its faces point outward)."""
    p = mesh.vertices - mesh.vertices.mean(axis=0)
    total = 0.0
    for f in mesh.faces:
        q = p[f]
        total += sum(np.dot(q[0], np.cross(q[i], q[i + 1])) for i in range(1, len(f) - 1))
    return total / 6.0


def jittered_grid(rng, n: int, jitter: float):
    """An n x n grid of points moved by up to ``jitter`` and its (n-1)^2 quads as index lists."""
    xy = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    pts = xy + rng.uniform(-jitter, jitter, size=xy.shape)
    quads = [
        [i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1]
        for i, j in itertools.product(range(n - 1), range(n - 1))
    ]
    return pts, quads


# the same examples on every run (CI must not turn red on a newly drawn case; a case found
# failing is then a failing test until it is fixed): `--hypothesis-profile=explore` draws anew
settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile("repeatable")
