"""Reference apex solver: scipy SLSQP per vertex, with a feasibility phase from several starts.

The pipeline uses :func:`filletfold.vertex.batch.solve_apex_batch`, which calls
:func:`project_slsqp` only to finish the rare problems its interior-point iteration did not
converge on. :func:`solve_apex_slsqp` is the independent reference that tests and
``benchmarks/apex_solvers.py`` compare the batched solver with.
"""

from __future__ import annotations

import numpy as np

from ..tolerances import tol
from .apex import ApexConstraints, ApexSolution


def _max_slack(cons: ApexConstraints, x_init: np.ndarray) -> tuple[np.ndarray, float]:
    """Maximise the smallest constraint value from ``x_init``; return the point and value."""
    from scipy.optimize import minimize  # 0.1-0.3 s to import: only when needed

    L = cons.scale
    n = cons.n_vars
    g = cons.values(x_init)
    grad = np.zeros(n + 1)
    grad[-1] = -1.0 / L
    res = minimize(
        lambda x: -x[-1] / L,
        np.concatenate([x_init, [g.min()]]),
        jac=lambda x: grad,
        constraints=[
            {
                "type": "ineq",
                "fun": lambda x: cons.values(x[:n]) - x[-1],
                "jac": lambda x: np.hstack([cons.jacobian(x[:n]), -np.ones((len(g), 1))]),
            }
        ],
        bounds=[(None, None)] * n + [(None, L)],
        method="SLSQP",
        options={"ftol": 1e-14, "maxiter": 500},
    )
    t = float(cons.values(res.x[:n]).min())
    if not np.isfinite(t) or t < g.min():
        return x_init, float(g.min())
    return res.x[:n], t


def solve_apex_slsqp(cons: ApexConstraints, target: np.ndarray, starts=None) -> ApexSolution:
    """Project ``target`` onto the sampled feasible set (feasibility phase first).

    Parameters
    ----------
    cons : ApexConstraints
    target : (3,) or (5,) float
        ``P = U + d D``, followed by the target ``p`` of the developed apex when it is a
        variable (closed development: the objective is ``|V - P|^2 + |v - p|^2``).
    starts : sequence of (3,) or (5,) float, optional
        Further starting points for the feasibility phase, tried in order when the phase
        started at ``target`` does not reach a feasible point.

    Returns
    -------
    ApexSolution
    """
    g0 = cons.values(target)
    if g0.min() >= 0:
        return ApexSolution(True, target.copy(), [], True, "target")
    # phase 1: maximise the smallest slack t, from the target and then from further starts
    # (the l <= l_max constraints are reverse-convex, so one start can stall)
    best_start, best_t = target, g0.min()
    for x_init in [target, *(starts if starts is not None else [])]:
        start, t = _max_slack(cons, x_init)
        if t > best_t:
            best_start, best_t = start, t
        if best_t >= 0:
            break
    start = best_start
    g1 = cons.values(start)
    if g1.min() < 0:
        rows = np.nonzero(g1 < 0)[0]
        return ApexSolution(False, start, cons.describe(rows), False)
    # phase 2: closest feasible point to the target
    return ApexSolution(True, project_slsqp(cons, target, start), [], False)


def project_slsqp(cons: ApexConstraints, target: np.ndarray, start: np.ndarray) -> np.ndarray:
    """SLSQP from the feasible ``start`` to the closest feasible point to ``target``.

    Returns the point, or ``start`` when SLSQP ends on an infeasible one.
    """
    from scipy.optimize import minimize  # 0.1-0.3 s to import: only when needed

    L = cons.scale
    res = minimize(
        lambda x: ((x - target) @ (x - target)) / L**2,
        start,
        jac=lambda x: 2 * (x - target) / L**2,
        constraints=[{"type": "ineq", "fun": cons.values, "jac": cons.jacobian}],
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 500},
    )
    return res.x if cons.values(res.x).min() >= -tol.roundoff * L else start
