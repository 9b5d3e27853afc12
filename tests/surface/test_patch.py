"""Patch identity: one record (kind, index), one name, read back the same everywhere."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from filletfold.surface.patch import (
    PATCH_KINDS,
    Patch,
    as_patch,
    patch_ids,
    patch_indices,
    patch_kind,
    patch_kinds,
    patches_of,
)

from ..conftest import design_of


@given(st.sampled_from(sorted(PATCH_KINDS)), st.integers(0, 10**9))
def test_a_name_reads_back_as_its_patch(kind, index):
    patch = Patch(kind, index)
    assert Patch.parse(str(patch)) == patch
    assert patches_of(kind, [index]) == [patch] and as_patch(str(patch)) == patch
    assert patch_kinds([str(patch)]).tolist() == [kind]
    assert patch_indices([str(patch)]).tolist() == [index]


@pytest.mark.parametrize("name", ["", "cone", "cone -1", "cone 1.5", "cones 3", "cone 3 4", "x 1"])
def test_a_bad_name_is_refused_naming_it(name):
    with pytest.raises(ValueError, match="is not 'cone <vertex>'"):
        Patch.parse(name)


def test_a_foreign_name_stays_a_name():
    """A file's patch name that names no patch is kept as it is (the certificate names it)."""
    assert as_patch("cone 3") == Patch("cone", 3)
    assert as_patch("bump 3") == "bump 3" and as_patch("cone x") == "cone x"


def test_the_arrays_of_a_real_pattern_are_those_of_each_name():
    """A design's faces carry Patch records of every kind (a sharp vertex gives conical
    fillets); the vectorised kinds, indices and ids are those of each face's own record and of
    its name parsed back."""
    pattern = design_of("l-prism").pattern
    parsed = list(pattern.face_patch)
    assert all(isinstance(p, Patch) for p in parsed)
    names = [str(p) for p in parsed]
    assert [Patch.parse(n) for n in names] == parsed
    assert {p.kind for p in parsed} == set(PATCH_KINDS), "not every kind is in the design"
    assert patch_kinds(names).tolist() == [p.kind for p in parsed]
    assert np.array_equal(patch_indices(names), [p.index for p in parsed])
    assert patch_kinds(parsed).tolist() == patch_kinds(names).tolist()
    assert np.array_equal(patch_indices(parsed), patch_indices(names))
    ids = patch_ids(parsed)
    assert np.array_equal(ids, patch_ids(names)) and ids.max() + 1 == len(set(parsed))
    assert patch_kinds([]).shape == (0,) and patch_indices([]).shape == (0,)
    assert patch_kind("") == "" and patch_kind("", "patch") == "patch"
