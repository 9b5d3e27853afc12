"""Patch identity: one record (kind, index), one name, read back the same everywhere."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from filletfold.surface.patch import (
    PATCH_KINDS,
    Patch,
    patch_indices,
    patch_kind,
    patch_kinds,
    patch_names,
)

from ..conftest import design_of


@given(st.sampled_from(sorted(PATCH_KINDS)), st.integers(0, 10**9))
def test_a_name_reads_back_as_its_patch(kind, index):
    patch = Patch(kind, index)
    assert Patch.parse(str(patch)) == patch
    assert patch_names(kind, [index]) == [str(patch)]
    assert patch_kinds([str(patch)]).tolist() == [kind]
    assert patch_indices([str(patch)]).tolist() == [index]


@pytest.mark.parametrize("name", ["", "cone", "cone -1", "cone 1.5", "cones 3", "cone 3 4", "x 1"])
def test_a_bad_name_is_refused_naming_it(name):
    with pytest.raises(ValueError, match="is not 'cone <vertex>'"):
        Patch.parse(name)


def test_the_arrays_of_a_real_pattern_are_those_of_each_name():
    """On a design with every kind of patch (a sharp vertex gives conical fillets), the
    vectorised kinds and indices are those of each face's own parse."""
    pattern = design_of("l-prism").pattern
    names = pattern.face_patch
    parsed = [Patch.parse(n) for n in names]
    assert {p.kind for p in parsed} == set(PATCH_KINDS), "not every kind is in the design"
    assert patch_kinds(names).tolist() == [p.kind for p in parsed]
    assert np.array_equal(patch_indices(names), [p.index for p in parsed])
    assert patch_kinds([]).shape == (0,) and patch_indices([]).shape == (0,)
    assert patch_kind("") == "" and patch_kind("", "patch") == "patch"
