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
from .crease import chart_apex, denominator_gradients


class _FixedApexRows:
    """:meth:`ApexConstraints.values` and :meth:`~ApexConstraints.jacobian` of an open
    development (``v_fixed`` set), for SLSQP's many calls at one problem.

    What does not depend on the spatial apex ``V`` (the developed apex in every chart, its
    part of the numerator, the denominator's and the linear rows' gradients) is computed once,
    and the rest is written into buffers: the same arithmetic in the same order, so every
    value and derivative equals the methods' to the bit (``tests/vertex/test_reference.py``),
    in half the time (SLSQP's fallback solves are most of a large design's apex stage).

    Parameters
    ----------
    cons : ApexConstraints
        With ``v_fixed`` set (3 variables).
    slack : bool
        The functions of :func:`_max_slack`: a fourth variable ``t`` is subtracted from every
        row (:meth:`values` and :meth:`jacobian` then take ``(4,)`` points, and the jacobian
        has a fourth column of -1).
    """

    def __init__(self, cons: ApexConstraints, slack: bool = False):
        vi = chart_apex(cons.quad_Q, cons.quad_t, cons.v_fixed)
        q, p = len(cons.quad_s), len(cons.lin_b)
        self.cons, self.q, self.slack = cons, q, slack
        self.vy = vi[:, 1]
        self.vv = (vi[:, 0] - cons.quad_s) ** 2 + vi[:, 1] ** 2  # as in crease_numerator
        # V - C(s) and V - M of every quadratic row, in one subtraction into one buffer
        self.points = np.concatenate([cons.quad_c, cons.quad_M])
        self.diff = np.empty_like(self.points)
        dn_V, _ = denominator_gradients(cons.quad_R, cons.quad_Q)
        self.coef_dn = cons.quad_coef[:, None] * dn_V
        self.jac = np.empty((q + p, 4 if slack else 3))
        self.jac[q:, :3] = cons.lin_a
        if slack:
            self.jac[:, 3] = -1.0

    def values(self, x: np.ndarray) -> np.ndarray:
        """(n_rows,) float: ``cons.values(x[:3])``, less ``x[3]`` with ``slack``."""
        c, q, V = self.cons, self.q, x[:3]
        out = np.empty(len(self.jac))
        d = np.subtract(V, self.points, out=self.diff)
        num = self.vv - np.einsum("ij,ij->i", d[:q], d[:q])
        dn = self.vy - np.einsum("ij,ij->i", d[q:], c.quad_R)
        quad = np.multiply(c.quad_sign, num, out=out[:q])
        quad -= c.quad_coef * dn
        quad /= c.scale
        quad += c.quad_const
        lin = np.einsum("ij,j->i", c.lin_a, V, out=out[q:])
        lin += c.lin_b
        if self.slack:
            out -= x[3]
        return out

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """(n_rows, 3) float: ``cons.jacobian(x[:3])``; with ``slack`` (n_rows, 4), the last
        column -1."""
        c = self.cons
        gV = c.quad_sign[:, None] * (-2 * (x[:3] - c.quad_c)) - self.coef_dn
        out = self.jac.copy()
        out[: self.q, :3] = gV / c.scale
        return out


def _max_slack(cons: ApexConstraints, x_init: np.ndarray) -> tuple[np.ndarray, float]:
    """Maximise the smallest constraint value from ``x_init``; return the point and value."""
    from scipy.optimize import minimize  # 0.1-0.3 s to import: only when needed

    L = cons.scale
    n = cons.n_vars
    g = cons.values(x_init)
    grad = np.zeros(n + 1)
    grad[-1] = -1.0 / L
    if cons.v_fixed is not None:
        rows = _FixedApexRows(cons, slack=True)
        fun, jac = rows.values, rows.jacobian
    else:
        fun = lambda x: cons.values(x[:n]) - x[-1]  # noqa: E731
        jac = lambda x: np.hstack([cons.jacobian(x[:n]), -np.ones((len(g), 1))])  # noqa: E731
    res = minimize(
        lambda x: -x[-1] / L,
        np.concatenate([x_init, [g.min()]]),
        jac=lambda x: grad,
        constraints=[{"type": "ineq", "fun": fun, "jac": jac}],
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
    rows = _FixedApexRows(cons) if cons.v_fixed is not None else cons
    res = minimize(
        lambda x: ((x - target) @ (x - target)) / L**2,
        start,
        jac=lambda x: 2 * (x - target) / L**2,
        constraints=[{"type": "ineq", "fun": rows.values, "jac": rows.jacobian}],
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 500},
    )
    return res.x if cons.values(res.x).min() >= -tol.roundoff * L else start
