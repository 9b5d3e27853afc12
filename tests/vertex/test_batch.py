"""The batched interior-point apex solver against the reference SLSQP solver (issue 6).

Random vertices: every vertex of random convex polyhedra at random radius, depth and margin,
plus the closed developments (5 variables) of a developable tessellation. The batched solver
must solve every problem the reference solves, land on a point that meets every sampled
constraint, and its distance to the target must be no worse than the reference's (within
1e-6 relative; the reference often stops short of the optimum, so it is usually better) or,
where the two land in different local minima of this non-convex problem, be a local minimum
itself. ``benchmarks/apex_solvers.py`` reports how often and by how much.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from filletfold.vertex import batch
from filletfold.vertex.batch import phase1_lp, solve_apex, solve_apex_batch
from filletfold.vertex.reference import project_slsqp, solve_apex_slsqp
from filletfold.vertex.rows import pack, pack_problems, rows_of
from filletfold.vertex.solve import apex_problems

from ..conftest import design_of, first_attempts, objective, random_convex


def check_against_reference(problems) -> None:
    batch = solve_apex_batch(*zip(*problems, strict=True))
    for (cons, target, starts), b in zip(problems, batch, strict=True):
        r = solve_apex_slsqp(cons, target, starts)
        if r.ok:
            assert b.ok, f"the reference solved a problem the batched solver did not: {b.failing}"
        if not b.ok:
            assert b.failing, "an infeasible result names the failing constraints"
            continue
        assert cons.values(b.x).min() >= -1e-12 * cons.scale
        if r.ok:
            fb, fr = objective(cons, target, b.x), objective(cons, target, r.x)
            if fb > fr * (1 + 1e-6) + 1e-12:
                # the problem is not convex (l <= l_max): another local minimum is allowed,
                # but the batched point must be one (SLSQP from it does not improve it)
                polished = objective(cons, target, project_slsqp(cons, target, b.x))
                assert polished >= fb * (1 - 1e-6) - 1e-12, (fb, fr, polished)
        if b.at_target:
            np.testing.assert_array_equal(b.x, target)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 10_000),
    radius=st.floats(0.03, 0.3),
    depth=st.floats(0.02, 1.2),
    margin=st.sampled_from([0.0, 0.1, 1.0, 2.0]),
)
def test_batched_matches_reference_on_random_vertices(seed, radius, depth, margin):
    problems = first_attempts(random_convex(seed), radius, depth, margin)
    if problems:
        check_against_reference(problems)


@pytest.mark.parametrize("depth", [0.05, 0.3, 1.0])
def test_batched_matches_reference_on_closed_developments(depth):
    """Developable vertices: the developed apex is a variable too (5 variables)."""
    problems = first_attempts("miura", 0.1, depth, loss=True)
    assert problems and all(c.n_vars == 5 for c, _, _ in problems)
    check_against_reference(problems)


def test_rows_reproduce_the_constraints():
    """The dimensionless rows a + A.y + alpha (|v|^2 - |V|^2) equal ``values`` everywhere."""
    rng = np.random.default_rng(3)
    for mesh, loss in (("icosahedron", False), ("miura", True)):
        for cons, target, _ in first_attempts(mesh, 0.1, 0.3, loss=loss)[:4]:
            a, A, alpha = rows_of(cons, target)
            block = pack([(a, A, alpha)], cons.n_vars)
            for _ in range(5):
                x = target + cons.scale * rng.normal(scale=0.5, size=cons.n_vars)
                y = (x - target) / cons.scale
                got = block.values(y[None])[0] * cons.scale
                np.testing.assert_allclose(got, cons.values(x), atol=1e-12 * cons.scale)


@pytest.mark.parametrize(("mesh", "loss"), [("random-convex", False), ("miura", True)])
def test_rows_of_many_problems_packed_at_once(mesh, loss):
    """pack_problems (rows of all problems computed together) is pack(rows_of) of each, bit
    for bit, with problems of different row counts in any order."""
    problems = first_attempts(mesh, 0.12, 0.3, loss=loss)
    problems += first_attempts(mesh, 0.12, 0.3, 2.0, loss=loss, samples=33)
    order = np.random.default_rng(5).permutation(len(problems))
    cons = [problems[i][0] for i in order]
    targets = np.stack([problems[i][1] for i in order])
    n = cons[0].n_vars
    assert len({len(c.quad_s) + len(c.lin_b) for c in cons}) > 1  # padding is exercised
    want = pack([rows_of(c, t) for c, t in zip(cons, targets, strict=True)], n)
    got = pack_problems(cons, targets, n)
    for name in ("a", "A", "alpha", "e", "mask"):
        np.testing.assert_array_equal(getattr(got, name), getattr(want, name), err_msg=name)


def test_infeasible_problem_names_its_constraints():
    """Two contradictory face rows: no feasible point; the failing rows are named."""
    cons, target, starts = first_attempts("icosahedron", 0.15, 0.3)[0]
    k = int(np.flatnonzero(cons.lin_kind == "face")[0])
    gap = 0.01 * cons.scale
    bad = dataclasses.replace(
        cons,
        lin_a=np.vstack([cons.lin_a, -cons.lin_a[k]]),
        lin_b=np.append(cons.lin_b, -cons.lin_b[k] - gap),
        lin_kind=np.append(cons.lin_kind, "face"),
        lin_element=np.append(cons.lin_element, cons.lin_element[k]),
    )
    sol = solve_apex(bad, target, starts)
    assert not sol.ok
    assert sol.failing and all(" at " in f for f in sol.failing)
    assert bad.values(sol.x).min() < 0


def test_mixed_batch_equals_separate_solves():
    """Chunking, padding and mixing 3- and 5-variable problems do not change any answer."""
    problems = first_attempts("blob", 0.1, 0.3)[:30] + first_attempts("miura", 0.1, 0.3, loss=True)
    together = solve_apex_batch(*zip(*problems, strict=True))
    for (cons, target, starts), t in zip(problems, together, strict=True):
        alone = solve_apex(cons, target, starts)
        assert alone.ok == t.ok
        if t.ok:
            np.testing.assert_allclose(t.x, alone.x, atol=1e-7 * cons.scale)


def test_kkt_point_certifies_a_projection_and_rejects_a_point_short_of_it():
    """The certificate that spares an SLSQP finish: at the solved apex of a vertex whose
    target is infeasible it holds; moved back toward the target along the boundary or pulled
    into the interior, it does not."""
    from filletfold.vertex.batch import kkt_point

    d = design_of("icosahedron", radius="10%", depth="60%")
    probs = apex_problems(d.mesh, d.rounding, d.stages.depths)
    checked = 0
    for p in probs:
        cons = p.constraints(9, 1.0)
        sol = solve_apex_batch([cons], [p.target], [p.starts])[0]
        if not sol.ok or sol.at_target:
            continue
        x = sol.x
        assert kkt_point(cons, p.target, x)
        inner = x + 0.01 * (p.target - x)  # not on the boundary toward P: infeasible
        interior = x + 1e-3 * cons.scale * (x - p.target) / np.linalg.norm(x - p.target)
        assert cons.values(inner).min() < 0 or not kkt_point(cons, p.target, inner)
        assert not kkt_point(cons, p.target, interior)  # no active row: not a projection
        checked += 1
    assert checked > 0


@pytest.mark.parametrize("mesh, loss", [("icosahedron", False), ("miura", True)])
def test_phase1_lp_reaches_a_feasible_point_and_never_loses_slack(mesh, loss):
    """From points about the target (where the interior-point phase 1 leaves its problems),
    the linear programmes reach a strictly feasible point (these problems have one); the slack
    returned is the point's, and never below the start's."""
    rng = np.random.default_rng(5)
    for cons, target, _ in first_attempts(mesh, 0.1, 0.3, loss=loss)[:4]:
        rows = pack_problems([cons], target[None], cons.n_vars)
        for _ in range(3):
            y0 = rng.normal(scale=0.1, size=cons.n_vars)
            y, t = phase1_lp(rows, y0[None])
            y, t = y[0], t[0]
            assert t == pytest.approx(rows.min_slack(y[None])[0], abs=1e-15)
            assert t >= rows.min_slack(y0[None])[0]
            assert t > 0


def _contradictory(cons):
    """``cons`` with its first face row repeated reversed and shifted: infeasible."""
    k = int(np.flatnonzero(cons.lin_kind == "face")[0])
    return dataclasses.replace(
        cons,
        lin_a=np.vstack([cons.lin_a, -cons.lin_a[k]]),
        lin_b=np.append(cons.lin_b, -cons.lin_b[k] - 0.01 * cons.scale),
        lin_kind=np.append(cons.lin_kind, "face"),
        lin_element=np.append(cons.lin_element, cons.lin_element[k]),
    )


def test_phase1_lp_stops_at_an_infeasible_problem():
    """Two contradictory face rows: the slack stays negative and the start is not lost."""
    cons, target, _ = first_attempts("icosahedron", 0.15, 0.3)[0]
    bad = _contradictory(cons)
    rows = pack_problems([bad], target[None], 3)
    y0 = np.zeros(3)
    _, t = phase1_lp(rows, y0[None])
    assert rows.min_slack(y0[None])[0] <= t[0] < 0


def test_phase1_lp_solves_a_batch_as_its_problems_one_by_one():
    """Problems of different row counts, a contradictory one among them, in one batch: each
    gets the slack it gets alone (the blocks share no variable), the infeasible one keeps its
    start's slack or better and stays negative."""
    rng = np.random.default_rng(11)
    probs = [(c, tg) for c, tg, _ in first_attempts("icosahedron", 0.1, 0.3)[:3]]
    cons, target, _ = first_attempts("icosahedron", 0.15, 0.3)[0]
    bad = _contradictory(cons)
    probs.insert(1, (bad, target))
    rows = pack_problems([c for c, _ in probs], np.stack([tg for _, tg in probs]), 3)
    y0 = rng.normal(scale=0.1, size=(len(probs), 3))
    y0[1] = 0.0
    y, t = phase1_lp(rows, y0)
    alone = [phase1_lp(rows.take(np.array([b])), y0[b : b + 1])[1][0] for b in range(len(probs))]
    np.testing.assert_allclose(t, rows.min_slack(y), atol=1e-15)
    assert rows.min_slack(y0)[1] <= t[1] < 0
    assert (np.delete(t, 1) > 0).all() and (np.delete(np.array(alone), 1) > 0).all()
    assert t[1] == pytest.approx(alone[1], abs=1e-12)


@pytest.mark.parametrize("mesh", ["torus", "blob"])
def test_a_problem_the_linear_programmes_solve_is_labelled(mesh, monkeypatch):
    """With the interior-point phase 1 made useless (it returns its start), a thorough solve
    reaches feasibility by the linear programmes alone and says so (``lp+ipm``); without them
    (``lp=False``, the first solve where a rescue follows) the same problem is not solved."""
    problems = [
        (c, t, s)
        for c, t, s in first_attempts(mesh, 0.1, 0.3)
        if pack_problems([c], t[None], c.n_vars).min_slack(np.zeros((1, c.n_vars)))[0] < 0
    ][:3]
    assert problems, "no problem whose target is infeasible"
    monkeypatch.setattr(batch, "_phase1", lambda rows, y0, *a, **k: y0)
    cons, targets, _ = zip(*problems, strict=True)
    starts = [[] for _ in cons]  # from the (infeasible) target alone
    with_lp = solve_apex_batch(cons, targets, starts, thorough=True)
    assert all(s.ok and s.solver.startswith("lp+ipm") for s in with_lp), [
        (s.ok, s.solver) for s in with_lp
    ]
    without = solve_apex_batch(cons, targets, starts, thorough=True, lp=False)
    assert not any(s.ok for s in without)


@pytest.mark.parametrize("fallback", ["starts", "again", "long"])
def test_a_problem_a_phase1_fallback_solves_is_labelled_and_off_when_left_out(
    fallback, monkeypatch
):
    """Phase 1 made to succeed only in the chosen fallback's run (the other starts, the quick
    restart from the best point, the long run without the give-up rule; the first run, from
    the best start, returns its start): the solution names that fallback
    (``<fallback>+ipm``, what ``fitting.cones_by_fallback`` counts), and with the fallback left
    out of ``settings.FALLBACKS`` the problem is not solved (the linear programmes left out
    throughout); the other starts are not tried where a rescue follows (``lp=False``)."""
    from filletfold.vertex import settings as solver_settings

    phase1_fallbacks = tuple(f for f in solver_settings.KNOWN_FALLBACKS if f != "lp")
    monkeypatch.setattr(solver_settings, "FALLBACKS", phase1_fallbacks)
    real = batch._phase1
    monkeypatch.setattr(batch, "_phase1", lambda rows, y0, *a, **k: y0)
    problems = [  # those no start solves without phase 1
        (c, t, s)
        for c, t, s in first_attempts("blob", 0.1, 0.3)
        if len(s) and not solve_apex_batch([c], [t], [s], lp=False)[0].ok
    ][:2]
    assert problems, "no problem that needs phase 1"
    calls = []

    def phase1_only_in_the_fallback(rows, y0, groups, max_iter, give_up=True):
        calls.append(give_up)
        chosen = not give_up if fallback == "long" else give_up and len(calls) == 2
        return real(rows, y0, groups, max_iter, give_up) if chosen else y0

    monkeypatch.setattr(batch, "_phase1", phase1_only_in_the_fallback)
    cons, targets, starts = zip(*problems, strict=True)
    thorough = fallback != "again"  # the quick restart is for quick solves only
    solved = solve_apex_batch(cons, targets, starts, thorough=thorough)
    assert all(s.ok and s.solver.startswith(f"{fallback}+ipm") for s in solved), [
        (s.ok, s.solver) for s in solved
    ]
    calls.clear()
    if fallback == "starts":  # not where a rescue follows (lp=False): it tries them again
        assert not any(s.ok for s in solve_apex_batch(cons, targets, starts, lp=False))
        calls.clear()
    others = tuple(f for f in phase1_fallbacks if f != fallback)
    monkeypatch.setattr(solver_settings, "FALLBACKS", others)
    unsolved = solve_apex_batch(cons, targets, starts, thorough=thorough)
    assert not any(s.ok for s in unsolved)
