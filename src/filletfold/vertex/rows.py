"""The constraint rows of a batch of apex problems, padded to one block.

Every row of sec. 3.2's problems (:class:`~filletfold.vertex.apex.ApexConstraints`) is written
about its problem's target ``P`` in the dimensionless variables ``y = (x - P) / L`` as
``a + A . y + alpha (y . e y)``, exact because the charts are rigid. The interior-point method
(:mod:`filletfold.vertex.batch`, and its compiled form :mod:`filletfold.vertex.batch_kernel`)
takes the rows of many problems as one padded :class:`RowBlock`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..arrays import run_owners, run_starts
from .apex import ApexConstraints
from .crease import (
    chart_apex,
    crease_denominator,
    crease_numerator,
    denominator_gradients,
    numerator_gradients,
)


@dataclass
class RowBlock:
    """Padded constraint rows of a batch, in the dimensionless variables ``y = (x - P) / L``.

    Attributes
    ----------
    a : (B, R) float
        Row values at ``y = 0``, over ``L``.
    A : (B, R, n) float
        Row gradients at ``y = 0``.
    alpha : (B, R) float
        Quadratic coefficient, times ``L``.
    e : (n,) float
        Signs of the quadratic form: -1 on ``V``, +1 on ``v``, 0 on a phase-1 slack.
    mask : (B, R) bool
        Real rows (padding rows are ``g = 1`` and ignored).
    """

    a: np.ndarray
    A: np.ndarray
    alpha: np.ndarray
    e: np.ndarray
    mask: np.ndarray

    def values(self, y: np.ndarray) -> np.ndarray:
        """(B, R) row values at ``y`` ((B, n) float)."""
        return row_values(self.a, self.A, self.alpha, self.e, y)

    def min_slack(self, y: np.ndarray) -> np.ndarray:
        """(B,) smallest value of the real rows at ``y``."""
        return np.where(self.mask, self.values(y), np.inf).min(axis=1)

    def take(self, idx: np.ndarray) -> RowBlock:
        return RowBlock(self.a[idx], self.A[idx], self.alpha[idx], self.e, self.mask[idx])


def rows_of(cons: ApexConstraints, target: np.ndarray):
    """The rows of one problem about ``target`` in the dimensionless form of :class:`RowBlock`.

    Returns
    -------
    a : (R,) float
    A : (R, n) float
    alpha : (R,) float
    """
    L = cons.scale
    a = cons.values(target) / L
    A = cons.jacobian(target)
    alpha = np.zeros(len(a))
    alpha[: len(cons.quad_sign)] = cons.quad_sign / cons.scale * L
    return a, A, alpha


def pack_problems(problems: Sequence[ApexConstraints], targets: np.ndarray, n: int) -> RowBlock:
    """:func:`pack` of :func:`rows_of` of every problem, computed on their rows together.

    Parameters
    ----------
    problems : sequence of ApexConstraints
        ``B`` problems with ``n`` variables each.
    targets : (B, n) float

    Returns
    -------
    RowBlock
    """
    B = len(problems)
    T = np.asarray(targets, dtype=float).reshape(B, n)
    nq = np.array([len(p.quad_s) for p in problems])
    nl = np.array([len(p.lin_b) for p in problems])
    L = np.array([p.scale for p in problems])
    qb, lb = run_owners(nq), run_owners(nl)  # problem of each row

    def cat(name: str) -> np.ndarray:
        return np.concatenate([getattr(p, name) for p in problems])

    Q, c, s = cat("quad_Q"), cat("quad_c"), cat("quad_s")
    sign, coef, R_q = cat("quad_sign"), cat("quad_coef"), cat("quad_R")
    lin_a = cat("lin_a")
    V = T[:, :3]
    v = T[:, 3:5] if n == 5 else np.array([p.v_fixed for p in problems])
    Lq, Vq = L[qb], V[qb]
    # ApexConstraints.values and .jacobian, row by row
    vi = chart_apex(Q, cat("quad_t"), v[qb])
    num = crease_numerator(Vq, vi, s, c)
    dn = crease_denominator(Vq, vi, cat("quad_M"), R_q)
    quad = (sign * num - coef * dn) / Lq + cat("quad_const")
    lin = np.einsum("ij,ij->i", lin_a, V[lb]) + cat("lin_b")
    num_V, num_v = numerator_gradients(Vq, vi, s, c, Q)
    dn_V, dn_v = denominator_gradients(R_q, Q)
    g_quad = sign[:, None] * num_V - coef[:, None] * dn_V
    if n == 5:
        g_quad = np.hstack([g_quad, sign[:, None] * num_v - coef[:, None] * dn_v])
    R = int((nq + nl).max(initial=0))
    out = RowBlock(
        np.ones((B, R)),
        np.zeros((B, R, n)),
        np.zeros((B, R)),
        np.array([-1.0, -1.0, -1.0, 1.0, 1.0][:n]),
        np.zeros((B, R), dtype=bool),
    )
    # each row's place in the padded block, as a flat index (b * R + place in its problem)
    q_at = np.arange(len(qb)) + (qb * R - (run_starts(nq)[:-1])[qb])
    l_at = np.arange(len(lb)) + (lb * R - (run_starts(nl)[:-1])[lb] + nq[lb])
    a, alpha, mask = out.a.reshape(-1), out.alpha.reshape(-1), out.mask.reshape(-1)  # views
    A = out.A.reshape(-1, n)
    a[q_at], a[l_at] = quad / Lq, lin / L[lb]
    A[q_at] = g_quad / Lq[:, None]
    A[l_at, :3] = lin_a
    alpha[q_at] = sign / Lq * Lq
    mask[q_at] = mask[l_at] = True
    return out


def pack(rows: Sequence[tuple], n: int) -> RowBlock:
    """Stack per-problem rows (from :func:`rows_of`) into one padded :class:`RowBlock`."""
    B = len(rows)
    R = max(len(r[0]) for r in rows)
    a = np.ones((B, R))
    A = np.zeros((B, R, n))
    alpha = np.zeros((B, R))
    mask = np.zeros((B, R), dtype=bool)
    for b, (a_, A_, al_) in enumerate(rows):
        k = len(a_)
        a[b, :k], A[b, :k, : A_.shape[1]], alpha[b, :k], mask[b, :k] = a_, A_, al_, True
    e = np.array([-1.0, -1.0, -1.0, 1.0, 1.0][:n])
    return RowBlock(a, A, alpha, e, mask)


def row_values(a, A, alpha, e, y) -> np.ndarray:
    """(B, R) values ``a + A . y + alpha (y . e y)`` of padded rows at ``y`` ((B, n) float)."""
    return a + matvec(A, y) + alpha * (y * e * y).sum(axis=1)[:, None]


def matvec(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(B, R) products of (B, R, n) matrices with (B, n) vectors."""
    return np.matmul(A, x[:, :, None])[:, :, 0]
