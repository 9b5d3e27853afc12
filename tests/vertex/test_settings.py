"""Settings of the batched apex solver (:mod:`filletfold.vertex.settings`): the relations the
comments state, and the numpy and numba interior-point methods reading the same constants."""

from __future__ import annotations

import inspect
import math

import numpy as np
import pytest

from filletfold.tolerances import tol
from filletfold.vertex import batch, settings
from filletfold.vertex.batch import interior_point_numpy
from filletfold.vertex.rows import pack

from ..conftest import first_attempts

#: The constants of the interior-point method, read by both versions (settings.py says).
IPM_CONSTANTS = (
    "IPM_TOL",
    "MULTIPLIER_START_FLOOR",
    "GIVE_UP_SLACK",
    "PRIMAL_WEIGHT_MU",
    "HESSIAN_FLOOR",
    "ARMIJO",
    "MERIT_ROUNDOFF",
    "MULTIPLIER_FLOOR",
)


def test_the_constants_are_in_range():
    known = settings.KNOWN_FALLBACKS
    assert known == ("starts", "again", "lp", "long")  # the order they are tried
    assert settings.FALLBACKS == tuple(f for f in known if f in settings.FALLBACKS)
    for name in dir(settings):
        if name.isupper() and not name.endswith("FALLBACKS"):
            value = getattr(settings, name)
            assert math.isfinite(value) and value > 0, name
    for name in ("CHUNK", "ROW_BUDGET", "PARALLEL_STARTS"):
        assert isinstance(getattr(settings, name), int) and getattr(settings, name) >= 1
    assert 0 < settings.ARMIJO < 1  # a sufficient-decrease constant


def test_documented_relations():
    # the exact multipliers take over (fast local convergence) before the method is done
    assert settings.IPM_TOL < settings.PRIMAL_WEIGHT_MU
    assert settings.PROJECTION_TOL < settings.PRIMAL_WEIGHT_MU
    # a point the interior-point method calls stationary (STAT_TOL) passes kkt_point's test
    assert settings.STAT_TOL < settings.KKT_TOL
    # a start's rulings further than START_PARALLEL (|sin|) from parallel are never parallel
    # to the line crossing (sin^2 below tol.parallel)
    assert settings.START_PARALLEL**2 >= tol.parallel
    # phase 1 succeeds at T_CAP / 2 and gives up below -GIVE_UP_SLACK: far apart
    assert -settings.GIVE_UP_SLACK < 0 < 0.5 * settings.T_CAP


def test_both_versions_default_to_ipm_tol():
    pytest.importorskip("numba")
    from filletfold.vertex.batch_kernel import interior_point_numba

    for f in (interior_point_numpy, interior_point_numba):
        assert inspect.signature(f).parameters["tol"].default == settings.IPM_TOL
    from filletfold.vertex import batch_kernel

    for name in IPM_CONSTANTS:
        assert getattr(batch, name) == getattr(settings, name), name
        if hasattr(batch_kernel, name):
            assert getattr(batch_kernel, name) == getattr(settings, name), name


def small_problem():
    """Three variables, two rows ``1 + y0 > 0`` and ``1 + y1 > 0``; minimise
    ``|y|^2 + c.y``: the optimum ``(-1, -1, -0.5)`` with both rows active for ``c = (10, 10, 1)``,
    ``(-0.25, -1, -0.5)`` with one for ``c = (0.5, 10, 1)``."""
    rows = pack([(np.ones(2), np.eye(2, 3), np.zeros(2))] * 2, 3)
    q = np.full(3, 2.0)
    c = np.array([[10.0, 10.0, 1.0], [0.5, 10.0, 1.0]])
    return rows, q, c, np.zeros((2, 3)), np.array([[-1.0, -1.0, -0.5], [-0.25, -1.0, -0.5]])


def test_numpy_and_numba_agree_on_a_small_problem():
    pytest.importorskip("numba")
    from filletfold.vertex.batch_kernel import interior_point_numba

    rows, q, c, y0, optimum = small_problem()
    y1, conv1 = interior_point_numpy(rows, q, c, y0)
    y2, conv2 = interior_point_numba(rows, q, c, y0)
    assert conv1.all() and conv2.all()
    np.testing.assert_allclose(y1, optimum, atol=1e-6)
    np.testing.assert_allclose(y2, y1, rtol=0, atol=1e-10)
    assert np.all(rows.values(y2)[rows.mask] > 0)


def test_numpy_and_numba_agree_on_real_vertices(monkeypatch):
    """The whole batched solve of a convex example's vertices with either version."""
    pytest.importorskip("numba")
    from filletfold.vertex.batch_kernel import interior_point_numba

    problems = first_attempts("icosahedron", 0.3, 0.6, 0.0)  # every target infeasible
    monkeypatch.setattr(batch, "interior_point", interior_point_numpy)
    ref = batch.solve_apex_batch(*zip(*problems, strict=True))
    monkeypatch.setattr(batch, "interior_point", interior_point_numba)
    got = batch.solve_apex_batch(*zip(*problems, strict=True))
    for (cons, _, _), r, s in zip(problems, ref, got, strict=True):
        assert r.ok and s.ok and r.solver == s.solver == "ipm"
        np.testing.assert_allclose(s.x, r.x, rtol=0, atol=1e-9 * cons.scale)


def test_the_compiled_kernel_reads_no_setting_from_a_cached_global():
    """A setting reaches the numba kernel as an argument (as ``tol``, ``T_CAP`` and
    ``STAT_TOL`` do), or the function reading it is not cached on disk: else editing
    settings.py leaves a stale compiled constant (numba's documented cache behaviour)."""
    pytest.importorskip("numba")
    from filletfold.vertex import batch_kernel

    names = {n for n in dir(settings) if n.isupper()}
    frozen = {}
    for fname, f in vars(batch_kernel).items():
        if hasattr(f, "py_func") and type(f._cache).__name__ != "NullCache":
            used = sorted(names & set(f.py_func.__code__.co_names))
            if used:
                frozen[fname] = used
    assert not frozen, f"cached kernel functions read settings as globals: {frozen}"
