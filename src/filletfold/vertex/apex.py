"""The spatial apex of a vertex cone: constrained optimisation (paper sec. 3.2).

Given the developed apex ``v`` (fixed point of ``rho``), the spatial apex ``V`` minimises
``|V - P|^2`` (``P = U + d D``, METHOD-NOTES 4) subject to, on every incident cylinder ``i``:

* valid patch: ``Dn_i = (v - c(s)) . r - (V - C(s)) . R > 0`` (constant along the arc);
* valid range: ``0 <= l_i(s)`` along the arc and ``l_i <= l_max`` at both ends, where
  ``l = num / (2 Dn)`` and ``num = |v - c(s)|^2 - |V - C(s)|^2`` (eq. 1); written as
  ``num - 2 m Dn >= 0`` and ``2 Dn (l_max - m) - num >= 0`` with a safety margin ``m``;
* non-intersection (eq. 2): ``sigma (V - C(s)) . N(s) > 0`` along the arc (sampled; the paper's
  chord-plane linearisation ``sigma (V - T_0) . N_e > 0`` is kept as well);
* every incident face: ``sigma (V - T) . N_f > 0`` (METHOD-NOTES 3).

The quadratic range constraints are sampled at a few points per arc during the solve. The
constraint ``l <= l_max`` is reverse-convex, so the solve starts with a feasibility phase
(maximise the smallest slack) before the projection of ``P`` (METHOD-NOTES). Every result is
then validated densely, without margin, by :func:`validate_apex`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from ..tolerances import tol
from .frame import VertexFrame, apply, invert

KINDS = {
    "patch": "valid patch (developed height above spatial height)",
    "l_min": "crease beyond the midpoint base curve (l < 0)",
    "l_max": "crease beyond the tangent-line crossing T (l > l_max)",
    "nonint": "cone self-intersects the cylinder (non-intersection, eq. 2)",
    "chord": "apex on the wrong side of the cylinder's chord plane",
    "face": "apex on the wrong side of a face",
}


@dataclass
class ApexConstraints:
    """Sampled sec. 3.2 constraints of one vertex as arrays, ``g(V) >= 0`` in length units.

    Attributes
    ----------
    scale : float
        Length used to scale quadratic constraints (mean incident edge length).
    quad_* : arrays over quadratic rows (``l`` lower and upper bounds)
    lin_a : (k, 3) float, lin_b : (k,) float
        Linear rows ``lin_a @ V + lin_b``.
    kind, edge : (n_rows,) str / int
        What each row is (see ``KINDS``) and the mesh edge or face it belongs to.
    """

    scale: float
    quad_c: np.ndarray  # (q, 3) centre C(s)
    quad_R: np.ndarray  # (q, 3)
    quad_M: np.ndarray  # (q, 3)
    quad_q: np.ndarray  # (q,) |v - c(s)|^2
    quad_vy: np.ndarray  # (q,) developed height of v in the cylinder chart
    quad_coef: np.ndarray  # (q,) multiplier of Dn
    quad_sign: np.ndarray  # (q,) +1 for num - 2 m Dn, -1 for 2 Dn (lmax - m) - num
    lin_a: np.ndarray
    lin_b: np.ndarray
    kind: list = field(default_factory=list)
    element: list = field(default_factory=list)

    def values(self, V: np.ndarray) -> np.ndarray:
        """(n_rows,) constraint values at apex ``V``."""
        d = V - self.quad_c
        num = self.quad_q - np.einsum("ij,ij->i", d, d)
        dn = self.quad_vy - np.einsum("ij,ij->i", V - self.quad_M, self.quad_R)
        quad = self.quad_sign * num - self.quad_coef * dn
        return np.concatenate([quad / self.scale, self.lin_a @ V + self.lin_b])

    def jacobian(self, V: np.ndarray) -> np.ndarray:
        """(n_rows, 3) derivative of :meth:`values`."""
        d = V - self.quad_c
        gq = -2 * self.quad_sign[:, None] * d + self.quad_coef[:, None] * self.quad_R
        return np.vstack([gq / self.scale, self.lin_a])

    def describe(self, rows) -> list[str]:
        """Human-readable names of constraint rows, one per distinct (kind, element)."""
        seen = []
        for r in rows:
            text = f"{KINDS[self.kind[r]]} at {self.element[r]}"
            if text not in seen:
                seen.append(text)
        return seen


def build_constraints(
    frame: VertexFrame, v: np.ndarray, sigma: int, n_samples: int, margin: float
) -> ApexConstraints:
    """Sample the sec. 3.2 constraints of a closed vertex.

    Parameters
    ----------
    frame : VertexFrame
    v : (2,) float
        Developed apex in the common frame.
    sigma : int
    n_samples : int
        Samples per arc (>= 3, both ends included).
    margin : float
        Safety margin ``m`` (length).
    """
    qc, qR, qM, qq, qvy, qcoef, qsign, kind, elem = ([] for _ in range(9))
    la, lb, lkind, lelem = [], [], [], []
    scale = float(np.mean([s.length for s in frame.sides]))
    for i, side in enumerate(frame.sides):
        e = f"edge {side.edge}"
        vi = apply(invert(frame.cyl_map[i]), v)[0]
        k_s = n_samples if side.arc > 0 else 1
        s = np.linspace(0.0, side.arc, k_s)
        C = side.base(s)
        N = side.normal(s)
        q = (vi[0] - s) ** 2 + vi[1] ** 2
        # l >= m at every sample
        qc.append(C)
        qR.append(np.repeat(side.R[None], k_s, 0))
        qM.append(np.repeat(side.M[None], k_s, 0))
        qq.append(q)
        qvy.append(np.full(k_s, vi[1]))
        qcoef.append(np.full(k_s, 2 * margin))
        qsign.append(np.ones(k_s))
        kind += ["l_min"] * k_s
        elem += [e] * k_s
        # l <= l_max - m at both ends
        for idx, lmax in ((0, frame.lmax_start[i]), (-1, frame.lmax_end[i])):
            qc.append(C[[idx]])
            qR.append(side.R[None])
            qM.append(side.M[None])
            qq.append(q[[idx]])
            qvy.append(np.array([vi[1]]))
            qcoef.append(np.array([-2 * (lmax - margin)]))
            qsign.append(np.array([-1.0]))
            kind.append("l_max")
            elem.append(e)
        # valid patch: vy - (V - M) . R >= m
        la.append(-side.R[None])
        lb.append(np.array([vi[1] + side.M @ side.R - margin]))
        lkind.append("patch")
        lelem.append(e)
        # non-intersection along the arc
        la.append(sigma * N)
        lb.append(-sigma * np.einsum("ij,ij->i", N, C) - margin)
        lkind += ["nonint"] * k_s
        lelem += [e] * k_s
        if side.arc == 0:
            continue
        # chord plane through C(0), C(a), T_0
        ne = np.cross(C[-1] - C[0], side.R)
        ne /= np.linalg.norm(ne)
        la.append(sigma * ne[None])
        lb.append(np.array([-sigma * ne @ frame.T_start[i] - margin]))
        lkind.append("chord")
        lelem.append(e)
    normals = [frame.face_frames[i][1:] for i in range(len(frame.ring.faces))]
    for i, f in enumerate(frame.ring.faces):
        n = np.cross(normals[i][0], normals[i][1])
        la.append(sigma * n[None])
        lb.append(np.array([-sigma * n @ frame.T_end[i] - margin]))
        lkind.append("face")
        lelem.append(f"face {int(f)}")
    return ApexConstraints(
        scale=scale,
        quad_c=np.vstack(qc),
        quad_R=np.vstack(qR),
        quad_M=np.vstack(qM),
        quad_q=np.concatenate(qq),
        quad_vy=np.concatenate(qvy),
        quad_coef=np.concatenate(qcoef),
        quad_sign=np.concatenate(qsign),
        lin_a=np.vstack(la),
        lin_b=np.concatenate(lb),
        kind=kind + lkind,
        element=elem + lelem,
    )


@dataclass
class ApexSolution:
    """Result of one apex solve.

    Attributes
    ----------
    ok : bool
    apex : (3,) float
        The apex (the best point found, also when not ok).
    failing : list of str
        Constraints that cannot be met (when not ok).
    at_target : bool
        True when ``P`` itself was feasible.
    """

    ok: bool
    apex: np.ndarray
    failing: list
    at_target: bool


def _max_slack(cons: ApexConstraints, x_init: np.ndarray) -> tuple[np.ndarray, float]:
    """Maximise the smallest constraint value from ``x_init``; return the point and value."""
    L = cons.scale
    g = cons.values(x_init)
    res = minimize(
        lambda x: -x[3] / L,
        np.concatenate([x_init, [g.min()]]),
        jac=lambda x: np.array([0, 0, 0, -1.0 / L]),
        constraints=[
            {
                "type": "ineq",
                "fun": lambda x: cons.values(x[:3]) - x[3],
                "jac": lambda x: np.hstack([cons.jacobian(x[:3]), -np.ones((len(g), 1))]),
            }
        ],
        bounds=[(None, None)] * 3 + [(None, L)],
        method="SLSQP",
        options={"ftol": 1e-14, "maxiter": 500},
    )
    t = float(cons.values(res.x[:3]).min())
    if not np.isfinite(t) or t < g.min():
        return x_init, float(g.min())
    return res.x[:3], t


def solve_apex(cons: ApexConstraints, target: np.ndarray, starts=None) -> ApexSolution:
    """Project ``target`` onto the sampled feasible set (feasibility phase first).

    Parameters
    ----------
    cons : ApexConstraints
    target : (3,) float
        ``P = U + d D``.
    starts : sequence of (3,) float, optional
        Further starting points for the feasibility phase, tried in order when the phase
        started at ``target`` does not reach a feasible point.

    Returns
    -------
    ApexSolution
    """
    g0 = cons.values(target)
    if g0.min() >= 0:
        return ApexSolution(True, target.copy(), [], True)
    L = cons.scale
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
    res = minimize(
        lambda V: ((V - target) @ (V - target)) / L**2,
        start,
        jac=lambda V: 2 * (V - target) / L**2,
        constraints=[{"type": "ineq", "fun": cons.values, "jac": cons.jacobian}],
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 500},
    )
    best = res.x if cons.values(res.x).min() >= -1e-12 * L else start
    return ApexSolution(True, best, [], False)


@dataclass
class ApexCheck:
    """Dense validation of an apex (no margin).

    Attributes
    ----------
    ok : bool
    margin : float
        Smallest slack over all conditions, in length units (negative when violated).
    failing : list of str
    """

    ok: bool
    margin: float
    failing: list


def crease_length(frame: VertexFrame, i: int, V: np.ndarray, v: np.ndarray, s: np.ndarray):
    """Eq. (1): ruling length ``l(s)`` of the crease on cylinder ``i``.

    Parameters
    ----------
    frame : VertexFrame
    i : int
        Side index.
    V : (3,) float
        Spatial apex.
    v : (2,) float
        Developed apex in the common frame.
    s : (k,) float
        Arc parameters in ``[0, a_i]``.

    Returns
    -------
    l : (k,) float
    dn : float
        The denominator ``(v - c) . r - (V - C) . R`` (constant along the arc; > 0 when valid).
    """
    side = frame.sides[i]
    vi = apply(invert(frame.cyl_map[i]), v)[0]
    C = side.base(s)
    num = (vi[0] - s) ** 2 + vi[1] ** 2 - np.einsum("ij,ij->i", V - C, V - C)
    dn = vi[1] - (V - side.M) @ side.R
    return 0.5 * num / dn, float(dn)


def validate_apex(
    frame: VertexFrame, V: np.ndarray, v: np.ndarray, sigma: int, n_samples: int = 257
) -> ApexCheck:
    """Check every condition densely along every arc, without margin.

    Conditions: ``Dn > 0``; ``l(s) >= 0``; ``l <= l_max`` at both ends; ``sigma (V - C) . N > 0``
    along the arc; ``sigma (V - T) . N_f > 0`` for every face.
    """
    scale = float(np.mean([s.length for s in frame.sides]))
    eps = tol.validate * scale
    slack, failing = [], []
    for i, side in enumerate(frame.sides):
        s = np.linspace(0.0, side.arc, n_samples if side.arc > 0 else 1)
        l, dn = crease_length(frame, i, V, v, s)
        C = side.base(s)
        N = side.normal(s)
        checks = {
            "patch": dn,
            "l_min": l.min() if dn > 0 else -np.inf,
            "l_max": min(frame.lmax_start[i] - l[0], frame.lmax_end[i] - l[-1])
            if dn > 0
            else -np.inf,
            "nonint": float(np.min(sigma * np.einsum("ij,ij->i", V - C, N))),
        }
        for k, val in checks.items():
            slack.append(val)
            strict = k in ("patch", "nonint")
            if val < (eps if strict else -eps):
                failing.append(f"{KINDS[k]} at edge {side.edge}")
    for i, f in enumerate(frame.ring.faces):
        n = np.cross(frame.face_frames[i][1], frame.face_frames[i][2])
        val = float(sigma * (V - frame.T_end[i]) @ n)
        slack.append(val)
        if val < eps:
            failing.append(f"{KINDS['face']} at face {int(f)}")
    return ApexCheck(not failing, float(np.min(slack)), failing)
