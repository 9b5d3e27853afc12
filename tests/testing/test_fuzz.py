"""Reproducible robustness cases (:mod:`filletfold.testing.fuzz`) on the first 20 cases: the
same bytes from the same seed, other cases from another seed, a case rebuilt from its index or
its name, and files the mesh reader reads or refuses with one line that names the file."""

from __future__ import annotations

import re

import numpy as np
import pytest

from filletfold.errors import FilletfoldError
from filletfold.mesh import EXAMPLES, example_mesh, example_names, load_mesh, read_mesh
from filletfold.testing import (
    FILE_KINDS,
    GARBAGE_KINDS,
    KINDS,
    OUTCOMES,
    case_by_name,
    fuzz_case,
    fuzz_cases,
    run_case,
)

N = 20


@pytest.fixture(scope="module")
def cases():
    return fuzz_cases(N)


def content(case) -> bytes:
    """Everything a case holds but its name."""
    if case.file is not None:
        return case.file[0].encode() + case.file[1]
    return case.vertices.tobytes() + b"".join(np.asarray(f).tobytes() + b"|" for f in case.faces)


def test_the_same_seed_gives_the_same_bytes(cases):
    again = fuzz_cases(N)
    assert [c.name for c in again] == [c.name for c in cases]
    assert [c.digest() for c in again] == [c.digest() for c in cases]
    assert [content(c) for c in again] == [content(c) for c in cases]
    assert all(re.fullmatch(r"[0-9a-f]{64}", c.digest()) for c in cases)


def test_another_seed_gives_other_cases(cases):
    other = fuzz_cases(N, seed=1)
    assert all(c.name.endswith("@1") and c.seed == 1 for c in other)
    assert not any(c.name.endswith("@0") or "@" in c.name for c in cases)
    assert len({c.digest() for c in cases} | {c.digest() for c in other}) == 2 * N
    differ = sum(content(a) != content(b) for a, b in zip(cases, other, strict=True))
    assert differ >= N - 2


def test_case_i_is_the_ith_case(cases):
    for i in (0, 7, N - 1):
        assert fuzz_case(i).digest() == cases[i].digest()
    assert [c.digest() for c in fuzz_cases(5)] == [c.digest() for c in cases[:5]]
    assert fuzz_case(3, seed=1).digest() == fuzz_cases(4, seed=1)[3].digest()


def test_a_case_is_rebuilt_from_its_name(cases):
    for case in cases:
        again = case_by_name(case.name)
        assert again.digest() == case.digest() and content(again) == content(case)
    other = fuzz_case(4, seed=2)
    assert case_by_name(f"  {other.name}\n").digest() == other.digest()


@pytest.mark.parametrize("name", ["", "cube", "cube/flip", "cube/flip#x", "/flip#0001"])
def test_a_malformed_name_is_refused(name):
    with pytest.raises(ValueError, match="not a case name"):
        case_by_name(name)


def test_a_name_that_is_not_the_case_of_its_index_is_refused(cases):
    base, rest = cases[0].name.split("/", 1)
    wrong = f"{base}x/{rest}"
    with pytest.raises(ValueError, match=re.escape(cases[0].name)):
        case_by_name(wrong)


def test_negative_indices_and_seeds_are_refused():
    with pytest.raises(ValueError):
        fuzz_case(-1)
    with pytest.raises(ValueError):
        fuzz_case(0, seed=-1)


def test_each_case_is_what_its_name_says(cases):
    for i, case in enumerate(cases):
        assert case.index == i and case.seed == 0
        assert case.name == f"{case.base}/{case.kind}#{i:04d}"
        assert set(case.kinds) <= set(KINDS) and "+".join(case.kinds) == case.kind
        assert (case.file is None) == (case.vertices is not None) == (case.faces is not None)
        assert case.garbage <= (case.kinds[-1] in GARBAGE_KINDS)
        if case.file is None:
            assert case.file_name is None
            assert case.vertices.dtype == np.float64 and case.vertices.shape[1] == 3
            assert all(f.dtype == np.int64 for f in case.faces)
        else:
            suffix, data = case.file
            assert isinstance(data, bytes) and re.fullmatch(r"\.[A-Za-z]+", suffix)
            assert case.file_name.endswith(suffix)
            assert re.fullmatch(r"[A-Za-z0-9._-]+", case.file_name)
            assert case.kinds[-1] in FILE_KINDS + GARBAGE_KINDS


def test_the_files_are_read_or_refused_in_one_line_naming_them(cases, tmp_path):
    files = [c for c in cases if c.file is not None]
    assert files and any(c.garbage for c in files) and not all(c.garbage for c in files)
    for case in files:
        path = tmp_path / case.file_name
        path.write_bytes(case.file[1])
        try:
            mesh, _ = load_mesh(str(path))
        except FilletfoldError as exc:  # any other exception fails the test
            message = str(exc)
            assert "\n" not in message and "\r" not in message, case.name
            assert path.name in message, case.name
        else:
            assert not case.garbage, f"{case.name}: a garbage file was read"
            assert mesh.n_faces > 0


def test_the_array_cases_load_or_are_refused_in_one_line(cases):
    arrays = [c for c in cases if c.file is None]
    assert arrays
    for case in arrays:
        try:
            load_mesh((case.vertices, case.faces))
        except FilletfoldError as exc:
            assert "\n" not in str(exc), case.name


def test_an_unmutated_file_holds_its_base_mesh(cases, tmp_path):
    """A file case of a built-in example and no mutation reads back as the example (its
    corners to float32 rounding; triangles in PLY and STL)."""
    plain = [c for c in cases if c.base in example_names() and c.kinds[0] in FILE_KINDS]
    assert plain
    for case in plain:
        path = tmp_path / case.file_name
        path.write_bytes(case.file[1])
        v, faces = read_mesh(path)
        v0, f0 = example_mesh(case.base)
        size = np.ptp(v0, axis=0).max()
        np.testing.assert_allclose(v.min(axis=0), v0.min(axis=0), atol=1e-6 * size)
        np.testing.assert_allclose(v.max(axis=0), v0.max(axis=0), atol=1e-6 * size)
        if case.kinds[0] in ("obj", "off"):
            assert len(faces) == len(f0)
        else:
            assert len(faces) == sum(len(f) - 2 for f in f0)


def test_run_case_says_how_a_case_ended(cases, tmp_path):
    garbage = next(c for c in cases if c.garbage)
    out = run_case(garbage, tmp_path)
    assert out.name == garbage.name and out.kind == garbage.kind and out.garbage
    assert out.outcome == "error" and out.names_file and not out.defect
    assert out.error_type and out.message and out.file.endswith(garbage.file_name)
    # a convex closed built-in written to a file (which one depends on the list of built-ins)
    convex = {n for n, e in EXAMPLES.items() if e.closed and "convex" in e.kinds}
    plain = next(c for c in cases if c.base in convex and c.kinds[0] in FILE_KINDS)
    out = run_case(plain, tmp_path)
    assert out.outcome in OUTCOMES and out.outcome == "design", out.message
    assert out.certified is not False and not out.defect
    assert out.n_faces == len(example_mesh(plain.base)[1])
    assert out.message == "" and out.error_type == ""
