"""Shared fixtures: designs of every built-in example, computed once per session."""

from __future__ import annotations

import functools

import pytest

import filletfold
from filletfold.mesh import EXAMPLES, example_names

ALL = example_names()
CLOSED_CONVEX = [n for n, e in EXAMPLES.items() if "convex" in e.kinds and e.closed]


@functools.cache
def design_of(name: str, radius="10%", depth="30%", samples: int = 24) -> filletfold.Design:
    """Round a built-in example (cached: designs are read-only in the tests)."""
    return filletfold.round_mesh(name, radius=radius, depth=depth, samples=samples)


@pytest.fixture(params=ALL)
def example_design(request) -> filletfold.Design:
    return design_of(request.param)
