"""The rescue of infeasible vertices (:mod:`filletfold.vertex.rescue`): smaller radii on their
own edges, applied (``fit_vertices``) or only found and reported as a hint."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import ConvexHull

import filletfold

CONE = Path(__file__).resolve().parents[1] / "data" / "corpus" / "compas-cone.stl"


@pytest.fixture(scope="module")
def fitted():
    return filletfold.round_mesh(CONE, tabs=False, sharp="none")


@pytest.fixture(scope="module")
def hinted():
    return filletfold.round_mesh(CONE, tabs=False, fit_vertices=False, sharp="none")


def test_rescued_vertices_are_ok_with_their_edges_scaled_by_the_factor(fitted):
    rescued = fitted.fitting["rescued"]
    assert rescued and fitted.fitting["rescue_applied"]
    edges, radius = fitted.mesh.edges, fitted.rounding.radius
    requested = fitted.fitting["radius_requested"]
    for u, factor in rescued.items():
        assert fitted.vertices.status[u] == "ok"
        assert factor in (0.5, 0.25, 0.125, 0.0625)  # halved, up to four times
        own = np.flatnonzero((edges == u).any(axis=1))
        np.testing.assert_allclose(radius[own], factor * requested[own], rtol=1e-12)
    assert fitted.certificate.ok


def test_without_fitting_the_design_keeps_its_radii_and_says_what_works(fitted, hinted):
    assert not hinted.fitting["rescue_applied"]
    np.testing.assert_array_equal(hinted.rounding.radius, hinted.fitting["radius_requested"])
    for u, factor in hinted.fitting["rescued"].items():
        assert hinted.vertices.status[u] == "infeasible"
        reason = hinted.vertices.reason[u]
        assert f"multiplied by {factor:g}" in reason and "--fit-vertices" in reason
    assert hinted.fitting["rescued"] == fitted.fitting["rescued"]


@pytest.mark.parametrize("seed", [616, 3, 11])
def test_a_convex_solid_ends_with_no_infeasible_vertex(seed):
    """Seed 616: a vertex rescued in one round, made infeasible again by its neighbour's
    rescue, must be tried again (it was left infeasible)."""
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(60, 3))
    p *= rng.uniform(0.8, 1.2, size=(60, 1)) / np.linalg.norm(p, axis=1)[:, None]
    d = filletfold.round_mesh((p, ConvexHull(p).simplices), radius="5%", tabs=False)
    counts = d.status_counts()
    assert counts["infeasible"] == 0 and counts["saddle"] == 0
    for u in d.fitting["sharpened"]:  # no radius helped: its edges are left sharp
        own = np.flatnonzero((d.mesh.edges == u).any(axis=1))
        assert (d.rounding.radius[own] == 0).all() and d.vertices.status[u] == "sharp"
