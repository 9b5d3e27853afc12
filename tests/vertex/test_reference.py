"""The SLSQP reference apex solver (:mod:`filletfold.vertex.reference`): a feasible target is
its own answer; otherwise a point meeting every sampled constraint, a first-order point of the
projection, the batched solver's point on convex examples; an infeasible problem names the
constraints it cannot meet."""

from __future__ import annotations

import numpy as np
import pytest

from filletfold.vertex.batch import kkt_point, solve_apex_batch
from filletfold.vertex.reference import _FixedApexRows, project_slsqp, solve_apex_slsqp

from ..conftest import first_attempts, objective

#: (mesh, radius, depth, margin, material loss) whose targets are all infeasible: projections
#: of open (3 variables) and closed (5: miura with material loss) developments.
PROJECTED = [
    ("icosahedron", 0.3, 0.6, 0.0, False),
    ("cube", 0.1, 1.0, 2.0, False),
    ("miura", 0.1, 0.3, 1.0, True),
]


@pytest.fixture(scope="module", params=PROJECTED, ids=lambda c: c[0])
def solved(request):
    """(problems, reference solutions, batched solutions) of every vertex's first attempt."""
    mesh, r, d, m, loss = request.param
    problems = first_attempts(mesh, r, d, m, loss)
    reference = [solve_apex_slsqp(cons, target, starts) for cons, target, starts in problems]
    return problems, reference, solve_apex_batch(*zip(*problems, strict=True))


def test_a_feasible_target_is_its_own_answer():
    problems = first_attempts("dimpled-cube", 0.1, 0.3)
    feasible = [(c, t, s) for c, t, s in problems if c.values(t).min() >= 0]
    assert feasible
    for cons, target, starts in feasible:
        sol = solve_apex_slsqp(cons, target, starts)
        assert sol.ok and sol.at_target and sol.solver == "target" and sol.failing == []
        np.testing.assert_array_equal(sol.x, target)
        assert sol.x is not target  # a copy


def test_the_point_meets_every_constraint(solved):
    problems, reference, _ = solved
    for (cons, target, _), sol in zip(problems, reference, strict=True):
        assert cons.values(target).min() < 0  # the target is not feasible: projected
        assert sol.ok and not sol.at_target and sol.failing == []
        assert sol.x.shape == (cons.n_vars,)
        assert cons.values(sol.x).min() >= -1e-12 * cons.scale
        np.testing.assert_array_equal(sol.apex, sol.x[:3])


def test_the_point_is_a_first_order_point_of_the_projection(solved):
    """The objective's gradient is a nonnegative combination of the active rows' gradients,
    and SLSQP from the point does not improve it."""
    problems, reference, _ = solved
    for (cons, target, _), sol in zip(problems, reference, strict=True):
        assert kkt_point(cons, target, sol.x)
        again = project_slsqp(cons, target, sol.x)
        f, g = objective(cons, target, sol.x), objective(cons, target, again)
        assert g == pytest.approx(f, rel=1e-6, abs=1e-12)


def test_it_agrees_with_the_batched_solver(solved):
    problems, reference, batched = solved
    for (cons, target, _), r, b in zip(problems, reference, batched, strict=True):
        assert b.ok and b.solver == "ipm"
        fr, fb = objective(cons, target, r.x), objective(cons, target, b.x)
        assert fr == pytest.approx(fb, rel=1e-6, abs=1e-12)
        np.testing.assert_allclose(r.x, b.x, rtol=0, atol=1e-6 * cons.scale)


def test_project_slsqp_from_a_feasible_start_gets_back_to_the_solution(solved):
    """From a feasible start beyond the solution (away from the target), a feasible point
    closer to the target than the start: the solution again."""
    problems, reference, _ = solved
    for (cons, target, _), sol in zip(problems, reference, strict=True):
        start = sol.x + 0.5 * (sol.x - target)
        assert cons.values(start).min() >= 0
        got = project_slsqp(cons, target, start)
        assert cons.values(got).min() >= -1e-12 * cons.scale
        f = objective(cons, target, got)
        assert f < objective(cons, target, start)
        assert f == pytest.approx(objective(cons, target, sol.x), rel=1e-6, abs=1e-12)


def test_an_infeasible_problem_names_what_it_cannot_meet():
    problems = first_attempts("octahedron", 0.45, 0.02, 5.0)
    assert problems
    for cons, target, starts in problems:
        sol = solve_apex_slsqp(cons, target, starts)
        assert not sol.ok and not sol.at_target
        g = cons.values(sol.x)
        assert g.min() < 0
        # phase 1 got no worse than the target, and names exactly the rows still violated
        assert g.min() >= cons.values(target).min()
        assert sol.failing == cons.describe(np.flatnonzero(g < 0))
        assert sol.failing and all(isinstance(text, str) and text for text in sol.failing)
        assert not solve_apex_batch([cons], [target], [starts])[0].ok  # as the batched solver


@pytest.mark.parametrize("mesh", ["icosahedron", "dimpled-cube", "octahedron"])
def test_the_open_development_rows_are_the_constraints_to_the_bit(mesh):
    """SLSQP's faster functions of an open development give the very values and derivatives
    of ``cons.values`` and ``cons.jacobian`` (with the feasibility phase's slack column), at
    points near the target and far from it."""
    rng = np.random.default_rng(5)
    problems = [p for p in first_attempts(mesh, 0.3, 0.6) if p[0].v_fixed is not None]
    assert problems
    for cons, target, _ in problems:
        plain, slack = _FixedApexRows(cons), _FixedApexRows(cons, slack=True)
        for scale in (1e-9, 1e-3, 1.0, 30.0):
            V = target + scale * cons.scale * rng.normal(size=3)
            x = np.append(V, scale * cons.scale * rng.normal())
            g, J = cons.values(V), cons.jacobian(V)
            assert np.array_equal(plain.values(V), g)
            assert np.array_equal(plain.jacobian(V), J)
            assert np.array_equal(slack.values(x), g - x[3])
            assert np.array_equal(slack.jacobian(x), np.hstack([J, -np.ones((len(g), 1))]))
