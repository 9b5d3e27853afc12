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
(maximise the smallest slack) before the projection of ``P`` (METHOD-NOTES); the solver is
:func:`filletfold.vertex.batch.solve_apex_batch`, which solves many vertices at once. Every
result is then validated densely, without margin, by :func:`validate_apex`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..tolerances import tol
from .frame import VertexFrame, apply, invert

KINDS = {
    "patch": "valid patch (developed height above spatial height)",
    "l_min": "crease beyond the midpoint base curve (l < 0)",
    "l_max": "crease beyond the tangent-line crossing T (l > l_max)",
    "nonint": "cone self-intersects the cylinder (non-intersection, eq. 2)",
    "chord": "apex on the wrong side of the cylinder's chord plane",
    "face": "apex on the wrong side of a face",
    "centre": "the straight crease passes the face piece's centre",
}


@dataclass
class ApexConstraints:
    """Sampled sec. 3.2 constraints of one vertex as arrays, ``g(x) >= 0`` in length units.

    The variables ``x`` are the spatial apex ``V`` (3,) for an open development, or ``V`` and
    the developed apex ``v`` (5,) for a closed one (``v_fixed is None``).

    Rows of the first kind depend on both apices through the crease length of eq. (1):
    ``(sign num - coef Dn) / scale + const`` with ``num = |v_i - c|^2 - |V - C|^2`` and
    ``Dn = (v_i)_y - (V - M) . R``, where ``v_i = Q v + t`` is the developed apex in the
    cylinder's chart and ``c = (s, 0)``. Rows of the second kind are linear in ``V``:
    ``lin_a @ V + lin_b``.

    Attributes
    ----------
    scale : float
        Length used to scale quadratic rows (mean incident edge length).
    v_fixed : (2,) float or None
    kind, element : list of str
        What each row is (see ``KINDS``) and the mesh edge or face it belongs to.
    """

    scale: float
    v_fixed: np.ndarray | None
    quad_c: np.ndarray  # (q, 3) base point C(s)
    quad_R: np.ndarray  # (q, 3)
    quad_M: np.ndarray  # (q, 3)
    quad_Q: np.ndarray  # (q, 2, 2) rotation of v into the cylinder chart
    quad_t: np.ndarray  # (q, 2) translation of v into the cylinder chart
    quad_s: np.ndarray  # (q,) arc parameter: c = (s, 0)
    quad_coef: np.ndarray  # (q,) multiplier of Dn
    quad_sign: np.ndarray  # (q,) multiplier of num
    quad_const: np.ndarray  # (q,)
    lin_a: np.ndarray
    lin_b: np.ndarray
    kind: list = field(default_factory=list)
    element: list = field(default_factory=list)

    @property
    def n_vars(self) -> int:
        return 3 if self.v_fixed is not None else 5

    def _split(self, x):
        V = x[:3]
        v = self.v_fixed if self.v_fixed is not None else x[3:5]
        vi = np.einsum("qij,j->qi", self.quad_Q, v) + self.quad_t
        return V, vi

    def values(self, x: np.ndarray) -> np.ndarray:
        """(n_rows,) constraint values at ``x``."""
        V, vi = self._split(x)
        d = V - self.quad_c
        num = (vi[:, 0] - self.quad_s) ** 2 + vi[:, 1] ** 2 - np.einsum("ij,ij->i", d, d)
        dn = vi[:, 1] - np.einsum("ij,ij->i", V - self.quad_M, self.quad_R)
        quad = (self.quad_sign * num - self.quad_coef * dn) / self.scale + self.quad_const
        return np.concatenate([quad, self.lin_a @ V + self.lin_b])

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """(n_rows, n_vars) derivative of :meth:`values`."""
        V, vi = self._split(x)
        d = V - self.quad_c
        gV = -2 * self.quad_sign[:, None] * d + self.quad_coef[:, None] * self.quad_R
        lin = self.lin_a
        if self.v_fixed is None:
            r = vi - np.stack([self.quad_s, np.zeros_like(self.quad_s)], axis=1)
            gv = 2 * self.quad_sign[:, None] * np.einsum("qji,qj->qi", self.quad_Q, r)
            gv -= self.quad_coef[:, None] * self.quad_Q[:, 1, :]
            gV = np.hstack([gV, gv])
            lin = np.hstack([lin, np.zeros((len(lin), 2))])
        return np.vstack([gV / self.scale, lin])

    def describe(self, rows) -> list[str]:
        """Human-readable names of constraint rows, one per distinct (kind, element)."""
        seen = []
        for r in rows:
            text = f"{KINDS[self.kind[r]]} at {self.element[r]}"
            if text not in seen:
                seen.append(text)
        return seen


def build_constraints(
    frame: VertexFrame,
    v: np.ndarray | None,
    sigma: int,
    n_samples: int,
    margin: float,
    lmax_scale: np.ndarray | None = None,
) -> ApexConstraints:
    """Sample the sec. 3.2 constraints of a closed-ring vertex.

    Parameters
    ----------
    frame : VertexFrame
    v : (2,) float or None
        Developed apex in the common frame, or None to make it a variable (closed
        development, sec. 3).
    sigma : int
    n_samples : int
        Samples per arc (>= 3, both ends included).
    margin : float
        Safety margin ``m`` (length).
    lmax_scale : (n_sides, 2) float, optional
        Factors on ``l_max`` at the start and end of each side (default 1): shorter creases
        keep the straight crease on a face away from the face piece's centre.
    """
    scale = float(np.mean([s.length for s in frame.sides]))
    if lmax_scale is None:
        lmax_scale = np.ones((len(frame.sides), 2))
    quad = {k: [] for k in ("c", "R", "M", "Q", "t", "s", "coef", "sign", "const")}
    kind, elem = [], []
    la, lb, lkind, lelem = [], [], [], []

    def add(C, side, Q, t, s, coef, sign, const, k, e):
        n = len(s)
        quad["c"].append(C)
        quad["R"].append(np.repeat(side.R[None], n, 0))
        quad["M"].append(np.repeat(side.M[None], n, 0))
        quad["Q"].append(np.repeat(Q[None], n, 0))
        quad["t"].append(np.repeat(t[None], n, 0))
        quad["s"].append(s)
        quad["coef"].append(np.full(n, coef))
        quad["sign"].append(np.full(n, sign))
        quad["const"].append(np.full(n, const))
        kind.extend([k] * n)
        elem.extend([e] * n)

    for i, side in enumerate(frame.sides):
        e = f"edge {side.edge}"
        inv = invert(frame.cyl_map[i])
        Q, t = inv[:2, :2], inv[:2, 2]
        k_s = n_samples if side.arc > 0 else 1
        s = np.linspace(0.0, side.arc, k_s)
        C = side.base(s)
        N = side.normal(s)
        # l >= m at every sample:  num - 2 m Dn >= 0
        add(C, side, Q, t, s, 2 * margin, 1.0, 0.0, "l_min", e)
        # l <= l_max - m at both ends:  2 Dn (l_max - m) - num >= 0
        for idx, lmax in (
            (0, frame.lmax_start[i] * lmax_scale[i, 0]),
            (-1, frame.lmax_end[i] * lmax_scale[i, 1]),
        ):
            add(C[[idx]], side, Q, t, s[[idx]], -2 * (lmax - margin), -1.0, 0.0, "l_max", e)
        # valid patch: Dn - m >= 0
        add(C[[0]], side, Q, t, s[[0]], -scale, 0.0, -margin, "patch", e)
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
    for i, f in enumerate(frame.ring.faces):
        n = np.cross(frame.face_frames[i][1], frame.face_frames[i][2])
        la.append(sigma * n[None])
        lb.append(np.array([-sigma * n @ frame.T_end[i] - margin]))
        lkind.append("face")
        lelem.append(f"face {int(f)}")
    cat = {
        k: (np.vstack(v_) if k in ("c", "R", "M", "t") else np.concatenate(v_))
        for k, v_ in quad.items()
    }
    return ApexConstraints(
        scale=scale,
        v_fixed=None if v is None else np.asarray(v, dtype=float),
        quad_c=cat["c"],
        quad_R=cat["R"],
        quad_M=cat["M"],
        quad_Q=cat["Q"],
        quad_t=cat["t"],
        quad_s=cat["s"],
        quad_coef=cat["coef"],
        quad_sign=cat["sign"],
        quad_const=cat["const"],
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
    x : (3,) or (5,) float
        The variables (the best point found, also when not ok): the spatial apex, then the
        developed apex for a closed development.
    failing : list of str
        Constraints that cannot be met (when not ok).
    at_target : bool
        True when the target itself was feasible.
    """

    ok: bool
    x: np.ndarray
    failing: list
    at_target: bool

    @property
    def apex(self) -> np.ndarray:
        """(3,) float: the spatial apex V."""
        return self.x[:3]

    @property
    def developed(self) -> np.ndarray | None:
        """(2,) float: the developed apex v when it was a variable, else None."""
        return self.x[3:5] if len(self.x) == 5 else None


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
    frame: VertexFrame,
    V: np.ndarray,
    v: np.ndarray,
    sigma: int,
    n_samples: int = 257,
    centres: np.ndarray | None = None,
) -> ApexCheck:
    """Check every condition densely along every arc, without margin.

    Conditions: ``Dn > 0``; ``l(s) >= 0``; ``l <= l_max`` at both ends; ``sigma (V - C) . N > 0``
    along the arc; ``sigma (V - T) . N_f > 0`` for every face; and, given the face pieces'
    ``centres`` ((n_faces, 3) float), the straight crease on every face runs between the
    corner T and the centre, so the vertex's share of the face stays a simple polygon.
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
        if centres is None:
            continue
        j = (i + 1) % len(frame.sides)
        ends = []
        for k, s_ in ((i, frame.sides[i].arc), (j, 0.0)):
            l_end, _ = crease_length(frame, k, V, v, np.array([s_]))
            ends.append(frame.sides[k].base([s_])[0] + l_end[0] * frame.sides[k].R)
        d = ends[1] - ends[0]
        if np.linalg.norm(d) <= eps:
            continue
        d = d / np.linalg.norm(d)
        side_t = float(np.cross(d, frame.T_end[i] - ends[0]) @ n)
        side_c = float(np.cross(d, centres[f] - ends[0]) @ n)
        val = -side_c * np.sign(side_t) if side_t != 0 else abs(side_c)
        slack.append(val)
        if val < eps:
            failing.append(f"{KINDS['centre']} on face {int(f)}")
    return ApexCheck(not failing, float(np.min(slack)), failing)
