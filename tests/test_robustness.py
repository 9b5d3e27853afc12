"""Robustness of ``round_mesh`` on the fuzz cases of seed 0 (filletfold.testing): the first
25 in ``make test``, 200 in the slow tier.

Meshes as users bring them (scaled, far away, flipped, soups, holes, duplicates, zero-area and
non-manifold pieces, non-planar quads, float32, integer grids) must give a design or one
line of :class:`~filletfold.errors.FilletfoldError`, never a traceback; a design must pass its
certificate (when ``filletfold.check`` exists); a file that is not a mesh must be refused by an
error that names it. ``benchmarks/robustness.py`` runs the same cases, more of them, and
prints the counts.
"""

from __future__ import annotations

import pytest

from filletfold.testing import KINDS, case_by_name, fuzz_cases, run_case
from filletfold.testing.fuzz import certifier

N_CASES = 200
#: Seconds one case may take before it counts as a time-out (they take well under one).
TIMEOUT = 60.0


#: The first cases, which `make test` runs (garbage files among them); the slow tier runs all
#: N_CASES.
N_FAST = 25
#: Cases of the long suite (``make test-long``), in parts of LONG_PART run by separate workers.
N_LONG = 5000
LONG_PART = 500


@pytest.fixture(
    scope="module",
    params=[
        pytest.param(N_FAST, id="first"),
        pytest.param(N_CASES, id="all", marks=pytest.mark.slow),
        *(
            pytest.param(
                (start, start + LONG_PART),
                id=f"long-{start}",
                # the four tests of a part on one worker: its cases run once (--dist loadgroup)
                marks=[pytest.mark.long, pytest.mark.xdist_group(f"long-{start}")],
            )
            for start in range(0, N_LONG, LONG_PART)
        ),
    ],
)
def outcomes(request, tmp_path_factory):
    """The outcomes of the first cases of seed 0 (or of the cases ``[start, stop)`` of the
    long suite), run once for this file (with the solver users get: the numba kernel when it
    is installed)."""
    folder = tmp_path_factory.mktemp("fuzz")
    if isinstance(request.param, tuple):
        start, stop = request.param
        cases = fuzz_cases(stop)[start:]
    else:
        cases = fuzz_cases(request.param)
    return [run_case(case, folder, timeout=TIMEOUT) for case in cases]


def listing(items, line) -> str:
    shown = [line(o) for o in items[:40]]
    more = f"\n... and {len(items) - 40} more" if len(items) > 40 else ""
    return "\n".join(shown) + more + "\n(rerun one: benchmarks/robustness.py --case NAME)"


def test_no_tracebacks(outcomes):
    bad = [o for o in outcomes if o.outcome in ("traceback", "timeout")]
    assert not bad, f"{len(bad)} of {len(outcomes)} cases ended in a traceback:\n" + listing(
        bad, lambda o: f"{o.name}: {o.message} (at {o.where})"
    )


def test_errors_are_one_line(outcomes):
    bad = [o for o in outcomes if o.outcome == "error-multiline"]
    assert not bad, f"{len(bad)} errors have a message of several lines:\n" + listing(
        bad, lambda o: f"{o.name}: {o.error_type}: {o.message!r}"
    )


def test_designs_pass_the_certificate(outcomes):
    if certifier() is None:
        pytest.skip("filletfold.check.certify_design does not exist yet")
    designs = [o for o in outcomes if o.outcome == "design"]
    bad = [o for o in designs if not o.certified]
    assert not bad, f"{len(bad)} of {len(designs)} designs fail their certificate:\n" + listing(
        bad, lambda o: f"{o.name}: failing {', '.join(o.failed_checks) or '(no check named)'}"
    )


def test_garbage_files_are_refused_naming_the_file(outcomes):
    garbage = [o for o in outcomes if o.garbage]
    assert garbage
    bad = [o for o in garbage if o.outcome not in ("error", "error-multiline") or not o.names_file]
    assert not bad, (
        f"{len(bad)} of {len(garbage)} garbage files were not refused by an error naming "
        f"the file:\n" + listing(bad, lambda o: f"{o.name}: {o.outcome}: {o.message}")
    )


def test_every_kind_is_run():
    seen = {k for case in fuzz_cases(N_CASES) for k in case.kinds}
    assert seen == set(KINDS), f"kinds never drawn: {sorted(set(KINDS) - seen)}"


def test_fuzz_cases_are_deterministic():
    a, b = fuzz_cases(N_CASES), fuzz_cases(N_CASES)
    assert [c.name for c in a] == [c.name for c in b]
    assert [c.digest() for c in a] == [c.digest() for c in b]
    assert len({c.name for c in a}) == N_CASES
    files = [c for c in a if c.file is not None]
    assert files and all(x.file == y.file for x, y in zip(a, b, strict=True) if x.file)


def test_case_i_does_not_depend_on_the_number_of_cases():
    long, short = fuzz_cases(3 * N_CASES), fuzz_cases(N_CASES)
    assert [c.digest() for c in long[:N_CASES]] == [c.digest() for c in short]
    assert len({c.name for c in long}) == 3 * N_CASES
    for case in long[::149]:
        assert case_by_name(case.name).digest() == case.digest()
    other = fuzz_cases(5, seed=3)
    assert all(c.name.endswith("@3") for c in other)
    assert case_by_name(other[4].name).digest() == other[4].digest()


@pytest.mark.parametrize(
    "name",
    [
        # two parts of the surface back to back in space, no face between them: the net joined
        # their modules there and the crease folded flat (180 degrees)
        "hull-274/dup-faces+zero-area#1011",
        # a thin face beside a sharp vertex: the face piece's centre lay beyond the tapering
        # fillet, and the share of the face at the fillet's wide end crossed itself
        "hull-33/dup-vertex+bumps#4598",
    ],
)
def test_designs_the_long_suite_found_invalid_are_certified(name, tmp_path):
    outcome = run_case(case_by_name(name), tmp_path, timeout=TIMEOUT)
    assert outcome.outcome == "design", outcome.message
    assert outcome.certified, outcome.failed_checks
