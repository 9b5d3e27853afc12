"""The numba kernel of the interior-point method against the numpy one (same algorithm).

Every ``interior_point`` call that ``solve_apex_batch`` makes on real apex problems (phase 1
with its slack, groups and give-up rule, phase 2) is repeated with
:func:`~filletfold.vertex.batch_kernel.interior_point_numba`: same converged flags, points
within 1e-8 (relative) and objectives within 1e-9 (relative to the size of their terms)
where both converged. The two differ by rounding only (summation order, Jacobi instead of
LAPACK for the smallest eigenvalue...), but phase 1 of some closed developments amplifies
rounding so much (``chicken-wire``: ~1e5 per iteration) that the numpy version itself lands
elsewhere when its rows are perturbed by 1e-14: on those *sensitive* problems the kernel
must agree as well as the numpy version agrees with itself under that noise (within a
factor 100), and where the noise moves the numpy version by more than 1e-6 or flips its
flag, it may differ as it will (but must stay strictly feasible). Last, the whole
``solve_apex_batch`` with the kernel swapped in: same ``ok`` flags, same apices.
"""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("numba")

import filletfold
from filletfold.vertex import batch, batch_kernel
from filletfold.vertex.batch_kernel import AVAILABLE, interior_point_numba

from ..conftest import first_attempts, objective, random_convex

#: The numpy reference.
numpy_ipm = batch.interior_point_numpy

# (mesh, radius, depth, margin, material loss): open (3 variables) and closed (5) developments
CASES = [
    ("icosahedron", 0.3, 0.6, 0.0, False),
    ("blob", 0.1, 0.3, 1.0, False),
    ("blob", 0.05, 1.0, 2.0, False),
    ("geodesic-sphere", 0.05, 1.0, 2.0, False),
    ("torus", 0.3, 0.6, 0.0, False),
    ("l-prism", 0.3, 0.6, 0.0, False),
    (0, 0.2, 0.5, 0.1, False),  # random convex polyhedra, by seed
    (1, 0.28, 0.4, 0.0, False),
    (2, 0.15, 1.0, 2.0, False),
    ("miura", 0.1, 0.3, 1.0, True),
    ("chicken-wire", 0.1, 0.3, 1.0, True),
    ("resch", 0.1, 0.3, 1.0, True),
]


def case_id(case) -> str:
    mesh, r, d, m, loss = case
    name = mesh if isinstance(mesh, str) else f"random-convex-{mesh}"
    return f"{name}-r{r}-d{d}-m{m}" + ("-loss" if loss else "")


def problems_of(case):
    mesh, r, d, m, loss = case
    return first_attempts(mesh if isinstance(mesh, str) else random_convex(mesh), r, d, m, loss)


def recorded_calls(problems) -> list:
    """The arguments of every ``interior_point`` call of ``solve_apex_batch(problems)``."""
    calls = []
    original = batch.interior_point

    def record(rows, q, c, y, **kw):
        calls.append((rows, q, c, y, kw))
        return numpy_ipm(rows, q, c, y, **kw)

    batch.interior_point = record
    try:
        batch.solve_apex_batch(*zip(*problems, strict=True))
    finally:
        batch.interior_point = original
    return calls


def noise_response(rows, q, c, y, kw, y_ref, conv_ref):
    """How far the numpy version moves when the rows' values are perturbed by 1e-14
    (relative; the largest of two draws): (B,) relative point gaps, (B,) objective gaps and
    (B,) bool verdict flips."""
    gap, f_gap, flip = np.zeros(len(y)), np.zeros(len(y)), np.zeros(len(y), dtype=bool)
    rng = np.random.default_rng(0)
    for _ in range(2):
        a = rows.a * (1 + 1e-14 * rng.standard_normal(rows.a.shape))
        y_n, conv_n = numpy_ipm(dataclasses.replace(rows, a=a), q, c, y, **kw)
        gap = np.maximum(gap, relative_gap(y_n, y_ref))
        f_gap = np.maximum(f_gap, np.abs(value(q, c, y_n) - value(q, c, y_ref)))
        flip |= conv_n != conv_ref
    return gap, f_gap, flip


def relative_gap(y1, y2) -> np.ndarray:
    return np.abs(y1 - y2).max(axis=1) / np.maximum(1.0, np.abs(y1).max(axis=1))


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_kernel_matches_numpy_on_every_call(case):
    """Same flags and points, call by call, on the calls of a real solve.

    Where both converged: points within 1e-8 and objectives within 1e-9 (relative), or, on
    a sensitive problem, within 100 times what 1e-14 noise does to the numpy version. The
    flags may differ, and the points as they will, only where that noise flips the numpy
    version's flag or moves its point by more than 1e-6 (*chaotic*: rounding amplified by
    more than 1e8).
    """
    calls = recorded_calls(problems_of(case))
    assert calls, "the case makes no interior-point call"
    for rows, q, c, y, kw in calls:
        y1, conv1 = numpy_ipm(rows, q, c, y, **kw)
        y2, conv2 = interior_point_numba(rows, q, c, y, **kw)
        # strictly feasible, whatever happened
        assert np.all(np.where(rows.mask, rows.values(y2), 1.0) > 0)
        gap = relative_gap(y1, y2)
        f_gap = np.abs(value(q, c, y2) - value(q, c, y1))
        tol, f_tol, flip = np.full(len(y), 1e-8), 1e-9 * size(q, c, y1), np.zeros(len(y), bool)
        if (conv1 != conv2).any() or (gap > tol).any() or (f_gap > f_tol).any():
            n_gap, n_f_gap, flip = noise_response(rows, q, c, y, kw, y1, conv1)
            tol, f_tol = np.maximum(tol, 100 * n_gap), np.maximum(f_tol, 100 * n_f_gap)
            flip |= n_gap > 1e-6
        odd = conv1 != conv2
        assert not (odd & ~flip).any(), (kw, np.nonzero(odd & ~flip)[0])
        both = conv1 & conv2 & ~flip
        assert np.all(gap[both] <= tol[both]), (kw, gap[both], tol[both])
        assert np.all(f_gap[both] <= f_tol[both]), (kw, f_gap[both], f_tol[both])


def value(q, c, y) -> np.ndarray:
    """(B,) objective ``0.5 y.q.y + c.y``."""
    return 0.5 * (y * q * y).sum(axis=1) + (c * y).sum(axis=1)


def size(q, c, y) -> np.ndarray:
    """(B,) size of the objective's terms (phase 1's objective is a small difference of
    larger terms; phase 2's is a squared distance, its own size)."""
    return 0.5 * np.abs(y * q * y).sum(axis=1) + np.abs(c * y).sum(axis=1)


def test_kernel_covers_both_phases_and_sizes():
    """The cases above exercise phase 1 (with groups, with and without the give-up rule) and
    phase 2, with 3 and 5 variables."""
    seen = set()
    for case in (CASES[1], CASES[11]):
        for rows, _, _, _, kw in recorded_calls(problems_of(case)):
            seen.add((rows.A.shape[2], kw.get("stop_slack") is not None, kw.get("give_up", False)))
    assert {(3, False, False), (4, True, True), (4, True, False)} <= seen
    assert {(5, False, False), (6, True, True)} <= seen


@pytest.mark.parametrize("case", [CASES[i] for i in (1, 2, 6, 9, 10, 11)], ids=case_id)
def test_solve_apex_batch_with_the_kernel(case, monkeypatch):
    """The whole batched solve with the kernel swapped in: same verdicts and apices.

    A problem the interior-point method does not finish in ``max_iter`` iterations is
    finished by SLSQP: whether it finishes is borderline on a few problems (the numpy
    version flips there too under 1e-14 noise), so where the two took different routes the
    objectives must agree instead (to 1e-7).
    """
    problems = problems_of(case)
    monkeypatch.setattr(batch, "interior_point", numpy_ipm)
    ref = batch.solve_apex_batch(*zip(*problems, strict=True))
    monkeypatch.setattr(batch, "interior_point", interior_point_numba)
    got = batch.solve_apex_batch(*zip(*problems, strict=True))
    for (cons, target, _), r, s in zip(problems, ref, got, strict=True):
        assert r.ok == s.ok
        if not r.ok:
            continue
        assert cons.values(s.x).min() >= -1e-12 * cons.scale
        if r.solver == s.solver:
            np.testing.assert_allclose(s.x, r.x, rtol=0, atol=1e-7 * cons.scale)
        else:
            fr, fs = objective(cons, target, r.x), objective(cons, target, s.x)
            assert abs(fs - fr) <= 1e-7 * max(fr, 1e-12), (r.solver, s.solver, fr, fs)


def test_edge_cases():
    """No problem, no iteration, and one problem alone (the batch rules do not matter)."""
    calls = recorded_calls(problems_of(CASES[1]))
    rows, q, c, y, kw = calls[-1]
    empty = rows.take(np.zeros(0, dtype=int))
    y0, conv0 = interior_point_numba(empty, q, c[:0], y[:0], **kw)
    assert y0.shape == (0, y.shape[1]) and conv0.shape == (0,)
    y1, conv1 = interior_point_numba(rows, q, c, y, **{**kw, "max_iter": 0})
    np.testing.assert_array_equal(y1, y)
    assert not conv1.any()
    one = rows.take(np.array([3]))
    ya, ca = numpy_ipm(one, q, c[3:4], y[3:4], **kw)
    yb, cb = interior_point_numba(one, q, c[3:4], y[3:4], **kw)
    assert ca[0] == cb[0]
    np.testing.assert_allclose(yb, ya, rtol=0, atol=1e-8 * max(1.0, np.abs(ya).max()))


def test_import_without_numba():
    """The module imports without numba (AVAILABLE is then False), and its code still runs as
    plain Python."""
    assert AVAILABLE
    code = (
        "import sys; sys.modules['numba'] = None\n"
        "import numpy as np\n"
        "from filletfold.vertex import batch, batch_kernel as k, rows as r\n"
        "assert not k.AVAILABLE\n"
        "rows = r.pack([(np.array([1.0, 2.0]), np.array([[1.0, 0, 0], [0, 1.0, 0]]),"
        " np.zeros(2))], 3)\n"
        "y, conv = k.interior_point_numba(rows, np.full(3, 2.0), np.array([[1.0, 1.0, 1.0]]),"
        " np.zeros((1, 3)))\n"
        "y_ref, conv_ref = batch.interior_point_numpy(rows,"
        " np.full(3, 2.0),"
        " np.array([[1.0, 1.0, 1.0]]), np.zeros((1, 3)))\n"
        "assert conv[0] and conv_ref[0] and np.allclose(y, y_ref, atol=1e-8), (y, y_ref)\n"
    )
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    subprocess.run([sys.executable, "-c", code], check=True, env=env, timeout=120)


@pytest.mark.parametrize(
    ("name", "kwargs"),
    [("blob", {}), ("torus", {}), ("miura", {"material_loss": True})],  # 3 and 5 variables
)
def test_designs_with_and_without_the_kernel(name, kwargs, monkeypatch):
    """The pipeline through either implementation: the same statuses, apices within 1e-5 of
    the mean edge (both land within rounding of the same optimum)."""
    designs = []
    monkeypatch.setattr(batch, "KERNEL_MIN_PROBLEMS", 0)
    for use in (False, True):
        monkeypatch.setattr(batch, "USE_KERNEL", use)
        designs.append(filletfold.round_mesh(name, tabs=False, layout="modules", **kwargs))
    a, b = designs
    assert a.vertices.status == b.vertices.status
    ok = np.array(a.vertices.status) == "ok"
    assert ok.any()
    gap = np.abs(a.vertices.apex[ok] - b.vertices.apex[ok]).max()
    assert gap <= 1e-5 * a.mesh.mean_edge_length


def test_small_batches_stay_with_numpy(monkeypatch):
    """Below KERNEL_MIN_PROBLEMS problems the numpy version runs, at or above it the kernel
    (the default threshold, 1, sends every batch to the kernel)."""
    called = []
    monkeypatch.setattr(batch, "USE_KERNEL", True)
    monkeypatch.setattr(batch, "_kernel_loaded", True)  # which path, not its loading
    monkeypatch.setattr(batch, "interior_point_numpy", lambda *a, **k: called.append("numpy"))
    monkeypatch.setattr(
        batch_kernel, "interior_point_numba", lambda *a, **k: called.append("numba")
    )
    calls = recorded_calls(problems_of(CASES[0]))
    rows, q, c, y, kw = calls[0]
    monkeypatch.setattr(batch, "KERNEL_MIN_PROBLEMS", len(rows.a) + 1)
    batch.interior_point(rows, q, c, y, **kw)
    monkeypatch.setattr(batch, "KERNEL_MIN_PROBLEMS", len(rows.a))
    batch.interior_point(rows, q, c, y, **kw)
    assert called == ["numpy", "numba"]
    assert batch.KERNEL_MIN_PROBLEMS >= 1


def test_importing_filletfold_does_not_import_numba():
    """numba (0.2 s, 50 MB) is imported on the kernel's first use only."""
    code = "import sys, filletfold, filletfold.vertex.batch; assert 'numba' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_a_warm_kernel_leaves_small_batches_to_numpy(monkeypatch):
    """After warm_kernel (the app warms it at start) small batches still use numpy: the path
    depends on the batch alone, so a design's bytes do not depend on what ran before it."""
    monkeypatch.setattr(batch, "USE_KERNEL", True)
    monkeypatch.setattr(batch, "_kernel_loaded", False)
    assert batch.warm_kernel() and batch._kernel_loaded
    called = []
    monkeypatch.setattr(batch, "interior_point_numpy", lambda *a, **k: called.append("numpy"))
    calls = recorded_calls(problems_of(CASES[0]))
    rows, q, c, y, kw = calls[0]
    monkeypatch.setattr(batch, "KERNEL_MIN_PROBLEMS", len(rows.a) + 1)
    batch.interior_point(rows, q, c, y, **kw)
    assert called == ["numpy"]
    monkeypatch.setattr(batch, "USE_KERNEL", False)
    assert not batch.warm_kernel()


def test_a_design_reports_the_kernel_loading(monkeypatch):
    """The first design whose solver batch loads the kernel (wanted, not loaded yet) says so
    in its progress: "compiling" only when numba's cache has no kernel (that first load takes
    about 15 s), "loading" when it has one. A design whose batches are all too small does not
    load it, nor does the icosahedron, whose vertices are all at their targets (no batch)."""
    from filletfold.vertex.batch import KERNEL_COMPILE_STAGE, KERNEL_STAGE

    monkeypatch.setattr(batch, "USE_KERNEL", True)
    cases = (
        ("tetrahedron", 5, True, None),  # one batch of 4 problems
        ("tetrahedron", 4, True, KERNEL_STAGE),
        ("tetrahedron", 4, False, KERNEL_COMPILE_STAGE),
        ("icosahedron", 1, True, None),
    )
    for mesh, n_min, cached, expected in cases:
        monkeypatch.setattr(batch, "_kernel_loaded", False)
        monkeypatch.setattr(batch, "KERNEL_MIN_PROBLEMS", n_min)
        monkeypatch.setattr(batch, "kernel_cached", lambda cached=cached: cached)
        stages = []

        def progress(stage, done, total, stages=stages):
            stages.append(stage)

        filletfold.round_mesh(mesh, tabs=False, progress=progress)
        shown = {KERNEL_STAGE, KERNEL_COMPILE_STAGE} & set(stages)
        assert shown == ({expected} if expected else set())
        assert batch._kernel_loaded == (expected is not None)


def test_the_kernel_cache_is_found_where_numba_writes_it(tmp_path, monkeypatch):
    """``kernel_cached`` sees an index file of the kernel's entry point under
    ``NUMBA_CACHE_DIR`` or numba's user-wide cache, and nothing in empty ones (the source's
    own ``__pycache__`` moved aside by pointing the package lookup at a copy without one)."""
    import importlib.util
    import shutil

    source = importlib.util.find_spec("filletfold.vertex.batch_kernel").origin
    copy = tmp_path / "pkg" / "batch_kernel.py"
    copy.parent.mkdir()
    shutil.copy(source, copy)
    spec = importlib.util.spec_from_file_location("filletfold.vertex.batch_kernel", copy)
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: spec)
    cache = tmp_path / "cache"
    cache.mkdir()
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(cache))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "user"))
    assert not batch.kernel_cached()
    (cache / "x").mkdir()
    (cache / "x" / "batch_kernel._kernel-204.py311.nbi").write_bytes(b"")
    assert batch.kernel_cached()
    # numba's user-wide cache (the source's folder read-only): $XDG_CACHE_HOME/numba/...
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    assert not batch.kernel_cached()
    user = tmp_path / "user" / "numba" / "site-packages_filletfold_vertex"
    user.mkdir(parents=True)
    index = user / "batch_kernel._kernel-204.py311.nbi"
    index.write_bytes(b"")
    assert batch.kernel_cached()
    # an index older than the source (a checkout or an upgrade changed it): compiled again
    os.utime(copy, (index.stat().st_mtime + 10, index.stat().st_mtime + 10))
    assert not batch.kernel_cached()


def test_a_kernel_that_cannot_load_falls_back_to_numpy(monkeypatch):
    """A numba that cannot compile the kernel (or be imported) turns it off with one warning;
    the batch is solved by numpy, and later ones too."""
    calls = recorded_calls(problems_of(CASES[0]))
    rows, q, c, y, kw = calls[-1]
    want = batch.interior_point_numpy(rows, q, c, y, **kw)

    def broken(*args, **kwargs):
        raise RuntimeError("numba too old for this numpy\nmore lines")

    monkeypatch.setattr(batch, "USE_KERNEL", True)
    monkeypatch.setattr(batch, "_kernel_loaded", False)
    monkeypatch.setattr(batch, "KERNEL_MIN_PROBLEMS", 0)
    monkeypatch.setattr(batch_kernel, "interior_point_numba", broken)
    with pytest.warns(RuntimeWarning, match="compiled solver is off .*numba too old"):
        got = batch.interior_point(rows, q, c, y, **kw)
    assert not batch.USE_KERNEL
    np.testing.assert_array_equal(got[0], want[0])
    assert not batch.warm_kernel()  # off for the rest of the process
    monkeypatch.setattr(batch, "USE_KERNEL", True)
    monkeypatch.setattr(batch_kernel, "AVAILABLE", False)
    with pytest.warns(RuntimeWarning, match="numba cannot be imported"):
        assert not batch.warm_kernel()


@settings(max_examples=60, deadline=None)
@given(
    groups=st.lists(st.integers(0, 40), min_size=0, max_size=400),
    n_threads=st.integers(1, 5),
)
def test_parts_keep_a_problems_copies_together(groups, n_threads):
    """Every problem in exactly one part; the copies of a problem (same group) in one part;
    no part below MIN_PER_THREAD problems unless there is only one."""
    groups = np.array(groups, dtype=np.int64)
    _, dense = np.unique(groups, return_inverse=True)
    parts = batch_kernel._parts(dense.reshape(-1), n_threads)
    assert 1 <= len(parts) <= max(1, n_threads)
    np.testing.assert_array_equal(np.sort(np.concatenate(parts)), np.arange(len(groups)))
    owner = {}
    for i, part in enumerate(parts):
        for g in set(groups[part].tolist()):
            assert owner.setdefault(g, i) == i
    if len(parts) > 1:
        assert min(len(p) for p in parts) >= 1
        assert len(groups) >= batch_kernel.MIN_PER_THREAD * len(parts)


def test_threads_give_the_results_of_one_thread(monkeypatch):
    """A batch split over threads (parts by group) gives each problem the point and flag it
    gets in one batch, in both phases."""
    calls = recorded_calls(first_attempts("geodesic-sphere:level=3", 0.1, 0.3, 1.0))
    big = [call for call in calls if len(call[3]) >= 2 * batch_kernel.MIN_PER_THREAD]
    assert {call[4].get("stop_slack") is None for call in big} == {True, False}
    for rows, q, c, y, kw in big:
        monkeypatch.setenv("FILLETFOLD_THREADS", "1")
        want = interior_point_numba(rows, q, c, y, **kw)
        monkeypatch.setenv("FILLETFOLD_THREADS", "2")
        got = interior_point_numba(rows, q, c, y, **kw)
        np.testing.assert_array_equal(got[1], want[1])
        np.testing.assert_array_equal(got[0][want[1]], want[0][want[1]])


def test_a_bad_thread_count_is_reported_not_taken_for_a_broken_kernel(monkeypatch):
    """FILLETFOLD_THREADS that is not a number stops the design with its own error; the
    kernel is not turned off as if numba had failed."""
    import warnings

    from filletfold.errors import ParameterError

    calls = recorded_calls(first_attempts("geodesic-sphere:level=3", 0.1, 0.3, 1.0))
    rows, q, c, y, kw = max(calls, key=lambda call: len(call[3]))
    monkeypatch.setattr(batch, "USE_KERNEL", True)
    monkeypatch.setattr(batch, "_kernel_loaded", False)
    monkeypatch.setattr(batch, "KERNEL_MIN_PROBLEMS", 0)
    monkeypatch.setenv("FILLETFOLD_THREADS", "two")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ParameterError, match="FILLETFOLD_THREADS"):
            batch.interior_point(rows, q, c, y, **kw)
    assert batch.USE_KERNEL
