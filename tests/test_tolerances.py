"""The one tolerance object (:mod:`filletfold.tolerances`): frozen, overridden only by a copy,
and its values in the relations their documentation states."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from filletfold import check
from filletfold.tolerances import Tolerances, tol


def test_tol_holds_the_defaults_and_is_frozen():
    assert tol == Tolerances()
    with pytest.raises(dataclasses.FrozenInstanceError):
        tol.merge = 1.0  # type: ignore[misc]
    assert tol.merge == Tolerances().merge


def test_an_override_is_a_copy_with_one_value_changed():
    loose = dataclasses.replace(tol, weld=1e-4)
    assert loose.weld == 1e-4 and tol.weld == Tolerances().weld
    changed = [
        f.name
        for f in dataclasses.fields(Tolerances)
        if getattr(loose, f.name) != getattr(tol, f.name)
    ]
    assert changed == ["weld"]
    assert Tolerances(planar=1e-3).planar == 1e-3


def test_every_tolerance_is_a_positive_finite_float():
    for f in dataclasses.fields(Tolerances):
        value = getattr(tol, f.name)
        assert isinstance(value, float), f.name
        assert math.isfinite(value) and value > 0, f.name


def test_documented_relations():
    # vertices the same point (merged) are closer than vertices welded as a repair
    assert tol.merge < tol.weld
    # a corner straight within `collinear` is removed; only a less straight one is split
    assert tol.collinear < tol.straight
    # planar to round-off is far stricter than the planarity test of a face
    assert tol.flat < tol.planar
    # `straight` is 1 degree, `fold` 1.03 degrees (creases within the 179 of the check)
    assert math.degrees(tol.straight) == pytest.approx(1.0, rel=3e-3)
    assert math.degrees(tol.fold) == pytest.approx(1.031, rel=3e-3)
    # `parallel` is sin^2 of 1e-6 rad
    assert math.sin(1e-6) ** 2 == pytest.approx(tol.parallel, rel=1e-6)
    # `fixed_point` is 4 sin^2(theta / 2) at a turn of about 1e-7 rad
    assert 4 * math.sin(0.5e-7) ** 2 == pytest.approx(tol.fixed_point, rel=1e-6)
    # `coincide` is round-off: about 45 units in the last place
    assert tol.coincide / np.finfo(float).eps == pytest.approx(45, rel=0.01)


def test_relations_with_the_certificate():
    """The shortest ruling and the narrowest fillet aimed at are above the certificate's
    shortest pattern edge, and the straight creases that `fold` allows (at most 180 degrees
    less it) fold by less than the certificate's largest fold."""
    assert tol.ruling > check.MIN_EDGE
    assert tol.min_fillet > check.MIN_EDGE
    assert 180.0 - math.degrees(tol.fold) < check.MAX_FOLD_DEG
