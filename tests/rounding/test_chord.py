"""Arc sampling that follows the chord tolerance (``round_mesh(chord_tol=...)``)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_array_equal

import filletfold
from filletfold.defaults import MAX_SAMPLES
from filletfold.errors import ParameterError
from filletfold.export.outputs import edge_mismatch, relative_mismatch
from filletfold.parameters import resolve_chord_tol
from filletfold.rounding.edges import chord_counts
from filletfold.surface.sampling import cone_sample_counts


def chord_error(turn, radius, n):
    """Largest distance between an arc and the chords of ``n`` evenly spaced samples."""
    return radius * (1.0 - np.cos(0.5 * turn / (n - 1)))


@given(
    turn=st.floats(1e-4, np.pi * 0.999),
    radius=st.floats(1e-3, 1e3),
    share=st.floats(1e-9, 3.0),
)
def test_chord_counts_are_the_fewest_within_the_tolerance(turn, radius, share):
    tol = share * radius
    n = int(chord_counts(turn, radius, tol))
    assert n >= 2
    assert chord_error(turn, radius, n) <= tol * (1 + 1e-9)
    if n > 2:  # one point fewer would leave a chord too far from the arc
        assert chord_error(turn, radius, n - 1) > tol * (1 - 1e-9)


def test_halving_the_tolerance_multiplies_the_steps_by_about_sqrt_2():
    rng = np.random.default_rng(3)
    turn = rng.uniform(0.5, 3.0, 200)
    radius = rng.uniform(0.1, 10.0, 200)
    tol = 2e-6
    n1 = chord_counts(turn, radius, tol)
    n2 = chord_counts(turn, radius, tol / 2)
    assert (chord_error(turn, radius, n2) <= tol / 2 * (1 + 1e-9)).all()
    assert (n2 >= n1).all()
    ratio = (n2 - 1) / (n1 - 1)  # steps of at least 40: the ceiling moves them by 2.5 % at most
    assert n1.min() > 40
    assert np.abs(ratio - np.sqrt(2)).max() < 0.04


def test_no_arc_no_radius_and_a_huge_tolerance():
    assert chord_counts([0.0, 1.0, 1.0], [1.0, 0.0, 1.0], 5.0).tolist() == [2, 2, 2]
    # a tolerance far below round-off of 1 - tol / r still counts (no cancellation)
    assert int(chord_counts(1.0, 1.0, 1e-20)) > 1e9


def cylinder_chord_errors(design):
    """(k,) for every pattern edge of every ``cylinder e`` face: how much nearer the axis of
    edge ``e`` its folded midpoint lies than the radius (the chord's distance from the arc:
    0 on a ruling, ``r (1 - cos(phi / 2))`` on a chord over the turn ``phi``)."""
    p, rd, mesh = design.pattern, design.rounding, design.mesh
    v3 = p.vertices_3d
    out = []
    for face, patch in zip(p.faces, p.face_patch, strict=True):
        kind, index = patch
        if kind != "cylinder":
            continue
        e = int(index)
        a, b = mesh.vertices[mesh.edges[e]]
        t = (b - a) / np.linalg.norm(b - a)
        ring = np.asarray(face)
        mid = 0.5 * (v3[ring] + v3[np.roll(ring, -1)]) - rd.axis_point[e]
        radial = mid - np.outer(mid @ t, t)
        out.append(rd.radius[e] - np.linalg.norm(radial, axis=1))
    return np.concatenate(out)


@pytest.mark.parametrize("name", ["icosahedron", "cube", "torus"])
@pytest.mark.parametrize("chord_tol", ["0.1%", "0.01%"])
def test_every_folded_chord_of_a_cylinder_is_within_the_tolerance(name, chord_tol):
    d = filletfold.round_mesh(
        name, chord_tol=chord_tol, arc_step=0, samples=MAX_SAMPLES, tabs=False
    )
    tol = resolve_chord_tol(chord_tol, d.mesh.mean_edge_length)
    err = cylinder_chord_errors(d)
    size = d.certificate.size
    assert err.max() <= tol + 1e-12 * size
    assert err.max() > 0.3 * tol  # the samples are no denser than the tolerance needs
    assert d.certificate.ok


def test_a_smaller_fillet_gets_fewer_points():
    """Two cubes' edges alike but for their radii: the one with half the radius gets about
    1 / sqrt(2) of the steps for the same tolerance (the arc step would give both alike)."""
    big = filletfold.round_mesh(
        "cube", radius="20%", chord_tol="0.001%", arc_step=0, samples=MAX_SAMPLES
    )
    small = filletfold.round_mesh(
        "cube", radius="10%", chord_tol="0.001%", arc_step=0, samples=MAX_SAMPLES
    )
    nb, ns = big.stages.samples, small.stages.samples
    assert len(set(nb.tolist())) == 1 and len(set(ns.tolist())) == 1
    assert (nb[0] - 1) / (ns[0] - 1) == pytest.approx(np.sqrt(2), rel=0.04)


@pytest.mark.slow  # fast tier near its budget: in make test-slow (CI runs both)
def test_the_isometry_figures_stay_at_round_off():
    """The certificate's ruling isometry and contraction are the construction's, not the
    sampling's: with the chord tolerance as with the old arc step, at round-off (1e-11: the
    torus's contraction is 1.1e-12 with numpy 2.4, the sampling's own mismatch about 1e-5)."""
    old = filletfold.round_mesh("torus", chord_tol=0, arc_step=1.5, tabs=False)
    new = filletfold.round_mesh("torus", arc_step=5, tabs=False)  # the tolerance decides
    assert len(new.pattern.vertices_2d) < len(old.pattern.vertices_2d)
    for d in (old, new):
        assert d.certificate.ok
        for name in ("ruling isometry", "contraction"):
            assert d.certificate[name].value < 1e-11


def test_mismatch_converges_as_the_chord_tolerance_shrinks():
    """The chords' 2D - 3D mismatch: a chord of length ``h`` on a crease of normal curvature
    ``k`` is ``k^2 h^3 / 24`` shorter folded than flat, and the tolerance sets
    ``h^2 = 8 r tol``: dividing the tolerance by 4 divides the relative mismatch by 4 and the
    absolute one by 8."""
    rel, ab = [], []
    for tol in ("0.004%", "0.001%", "0.00025%"):
        p = filletfold.round_mesh(
            "icosahedron", chord_tol=tol, arc_step=0, samples=MAX_SAMPLES, tabs=False
        ).pattern
        rel.append(relative_mismatch(p).max())
        ab.append(edge_mismatch(p).max())
    assert 3.5 < rel[0] / rel[1] < 4.5 and 3.5 < rel[1] / rel[2] < 4.5
    assert 7.0 < ab[0] / ab[1] < 9.0 and 7.0 < ab[1] / ab[2] < 9.0


def test_samples_cap_the_points_and_zero_turns_the_tolerance_off():
    """``samples`` caps what the chord tolerance and the arc step ask for; an arc at whose
    ends a cone turns faster than the step gets the points its cones need instead."""
    d = filletfold.round_mesh("cube", chord_tol="1e-9", samples=7, tabs=False)
    cones = cone_sample_counts(d.stages.solved, d.stages.centres, d.mesh.n_edges, 10.0)
    assert (cones > 7).all()  # the cube's cones turn faster than its arcs
    assert_array_equal(d.stages.samples, np.maximum(7, cones))
    d = filletfold.round_mesh("cube", chord_tol="1e-9", samples=7, arc_step=0, tabs=False)
    assert set(d.stages.samples.tolist()) == {7}
    d = filletfold.round_mesh("cube", chord_tol=0, arc_step=0, samples=5, tabs=False)
    assert set(d.stages.samples.tolist()) == {5}
    assert d.params.as_dict()["chord_tol"] == 0


@pytest.mark.parametrize(
    ("value", "match"),
    [
        ("-1%", "chord tolerance must be finite and >= 0"),
        (float("nan"), "chord tolerance must be finite"),
        ("fine", "chord tolerance must be a length or a percentage"),
        (True, "chord tolerance must be a length"),
    ],
)
def test_bad_chord_tolerance(value, match):
    with pytest.raises(ParameterError, match=match):
        filletfold.round_mesh("cube", chord_tol=value)


def test_resolve_chord_tol():
    assert resolve_chord_tol("0.5%", 2.0) == pytest.approx(0.01)
    assert resolve_chord_tol(0.25, 2.0) == 0.25
    assert resolve_chord_tol("0", 2.0) == 0.0
