"""The spatial apex of a vertex cone: constrained optimisation (paper sec. 3.2).

Given the developed apex ``v`` (fixed point of ``rho``), the spatial apex ``V`` minimises
``|V - P|^2`` (``P = U + d D``, not the paper's ``V + d D``: docs/method.md,
'Corrections to the paper', 4) subject to, on every incident cylinder ``i``:

* valid patch: ``Dn_i = (v - c(s)) . r - (V - C(s)) . R > 0`` (constant along the arc);
* valid range: ``0 <= l_i(s)`` along the arc and ``l_i <= l_max`` at both ends, where
  ``l = num / (2 Dn)`` and ``num = |v - c(s)|^2 - |V - C(s)|^2`` (eq. 1, computed by
  :mod:`filletfold.vertex.crease`); written as ``num - 2 m Dn >= 0`` and
  ``2 Dn (l_max - m) - num >= 0`` with a safety margin ``m``;
* non-intersection (eq. 2): ``sigma (V - C(s)) . N(s) > 0`` along the arc (sampled; the paper's
  chord-plane linearisation ``sigma (V - T_0) . N_e > 0`` is kept as well);
* every incident face: ``sigma (V - T) . N_f > 0`` (the paper omits ``sigma``: docs/method.md,
  'Corrections to the paper', 3), and the apex above three planes through T tilted from the
  face by a little more than ``tol.fold``, so that the straight crease on the face folds by
  less than 180 degrees minus ``tol.fold`` (see :func:`fold_planes`).

The quadratic range constraints are sampled at a few points per arc during the solve. The
constraint ``l <= l_max`` is reverse-convex, so the solve starts with a feasibility phase
(maximise the smallest slack) before the projection of ``P`` (docs/method.md, 'Where an
implementation trips'); the solver is :func:`filletfold.vertex.batch.solve_apex_batch`, which
solves many vertices at once. Every result is then validated densely, without margin, by
:func:`validate_apices` (all the vertices of a round at once).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, fields
from typing import NamedTuple

import numpy as np

from ..arrays import run_owners, run_starts
from ..tolerances import tol
from .crease import (
    chart_apex,
    crease_denominator,
    crease_height,
    crease_numerator,
    denominator_gradients,
    numerator_arc_derivatives,
    numerator_gradients,
)
from .frame import SideArrays, VertexFrame
from .runs import run_means

#: numpy string type of a row's kind (the longest key of ``KINDS``).
_KIND_TYPE = "<U6"

KINDS = {
    "patch": "valid patch (developed height above spatial height)",
    "l_min": "crease beyond the midpoint base curve (l < 0)",
    "l_max": "crease beyond the tangent-line crossing T (l > l_max)",
    "nonint": "cone self-intersects the cylinder (non-intersection, eq. 2)",
    "chord": "apex on the wrong side of the cylinder's chord plane",
    "face": "apex on the wrong side of a face",
    "centre": "the straight crease passes the face piece's centre",
    "fold": "straight crease folds flat (apex too near a face's plane, over the face)",
    "crease": "curved crease folds flat (apex too near the cylinder's tangent plane)",
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
    quad_kind, lin_kind : (q,) and (p,) str
        What each row is (a key of ``KINDS``).
    quad_element, lin_element : (q,) and (p,) int
        The mesh edge (or, for a ``face`` row, the mesh face) each row belongs to.
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
    quad_kind: np.ndarray
    quad_element: np.ndarray
    lin_kind: np.ndarray
    lin_element: np.ndarray

    @property
    def kind(self) -> np.ndarray:
        """(n_rows,) str: what each row of :meth:`values` is (a key of ``KINDS``)."""
        return np.concatenate([self.quad_kind, self.lin_kind])

    @property
    def element(self) -> np.ndarray:
        """(n_rows,) int: the mesh edge, or face for a ``face`` row, of each row."""
        return np.concatenate([self.quad_element, self.lin_element])

    @property
    def n_vars(self) -> int:
        return 3 if self.v_fixed is not None else 5

    def _split(self, x):
        V = x[:3]
        v = self.v_fixed if self.v_fixed is not None else x[3:5]
        return V, chart_apex(self.quad_Q, self.quad_t, v)

    def values(self, x: np.ndarray) -> np.ndarray:
        """(n_rows,) constraint values at ``x``."""
        V, vi = self._split(x)
        num = crease_numerator(V, vi, self.quad_s, self.quad_c)
        dn = crease_denominator(V, vi, self.quad_M, self.quad_R)
        quad = (self.quad_sign * num - self.quad_coef * dn) / self.scale + self.quad_const
        # einsum, not BLAS: the same sums as the rows of many problems together
        # (rows.pack_problems)
        return np.concatenate([quad, np.einsum("ij,j->i", self.lin_a, V) + self.lin_b])

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """(n_rows, n_vars) derivative of :meth:`values`."""
        V, vi = self._split(x)
        sign, coef = self.quad_sign[:, None], self.quad_coef[:, None]
        num_V, num_v = numerator_gradients(V, vi, self.quad_s, self.quad_c, self.quad_Q)
        dn_V, dn_v = denominator_gradients(self.quad_R, self.quad_Q)
        gV = sign * num_V - coef * dn_V
        lin = self.lin_a
        if self.v_fixed is None:
            gV = np.hstack([gV, sign * num_v - coef * dn_v])
            lin = np.hstack([lin, np.zeros((len(lin), 2))])
        return np.vstack([gV / self.scale, lin])

    def describe(self, rows) -> list[str]:
        """Human-readable names of constraint rows, one per distinct (kind, element)."""
        seen = []
        kinds, elements = self.kind, self.element
        for r in rows:
            kind = str(kinds[r])
            text = f"{KINDS[kind]} at {'face' if kind == 'face' else 'edge'} {elements[r]}"
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
    extra: np.ndarray | None = None,
    floor: float = 0.0,
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
    extra : (m, 2) float, optional
        ``(side, s)``: further arc parameters at which ``l >= m`` and the non-intersection
        condition are sampled (where an earlier solution failed between the samples).
    floor : float
        Shortest crease ruling (length): the ``l >= m`` rows keep ``l >= max(m, floor)``, and
        the ``l <= l_max - m`` rows keep the crease short of T by ``floor / (2 sin(alpha /
        2))`` too (``alpha`` the face's corner; at most a quarter of ``l_max``), so that no
        straight crease is shorter than ``floor``.
    """
    return build_constraints_many(
        [frame], [v], [sigma], [n_samples], [margin], [lmax_scale], [extra], [floor]
    )[0]


def build_constraints_many(
    frames: Sequence[VertexFrame],
    vs,
    sigmas,
    n_samples,
    margins,
    lmax_scales=None,
    extras=None,
    floors=None,
) -> list[ApexConstraints]:
    """:func:`build_constraints` of many vertices at once (one value of each parameter per
    vertex, in sequences of equal length; ``lmax_scales``, ``extras`` and ``floors`` may be
    None for all). The arcs of all vertices are sampled together.

    Every row of every vertex is computed in one pass over flat arrays, already in each
    vertex's row order, so a vertex's constraints are views of them; each row's arithmetic is
    the one of a vertex alone.

    Returns
    -------
    list of ApexConstraints
    """
    n = len(frames)
    if n == 0:
        return []
    arrays = [frame.arrays for frame in frames]
    sa = _stack(arrays)
    k = np.array([len(a.arc) for a in arrays])  # sides (= ring faces) per vertex
    so, sv = run_starts(k)[:-1], run_owners(k)  # first side, vertex of each side
    side, first, last, s, C, N = sa.samples(np.repeat(np.asarray(n_samples).reshape(n), k))
    cone = sa.conical
    extras = [] if extras is None else [(j, x) for j, x in enumerate(extras) if x is not None]
    if any(len(x) for _, x in extras):  # each vertex's extra samples after its own
        x_vert = np.concatenate([np.full(len(x), j) for j, x in extras])
        x_side = np.concatenate([x[:, 0] for _, x in extras]).astype(np.int64) + so[x_vert]
        x_s = np.concatenate([x[:, 1] for _, x in extras])
        x_C, x_N = sa.base_normal(x_side, x_s)
        order = np.argsort(np.concatenate([2 * sv[side], 2 * x_vert + 1]), kind="stable")
        side, s = np.concatenate([side, x_side])[order], np.concatenate([s, x_s])[order]
        C, N = np.vstack([C, x_C])[order], np.vstack([N, x_N])[order]
        n_x = np.bincount(x_vert, minlength=n)
        shift = (run_starts(n_x)[:-1])[sv]  # extra samples of the vertices before
        first, last = first + shift, last + shift
    if cone.any():  # a fillet's surface normal is the cone's, not the cylinder's
        N = sa.surface_normal(side, s, N=N)
    m = np.bincount(sv[side], minlength=n)  # samples per vertex
    mo, mv = run_starts(m)[:-1], run_owners(m)  # first sample, vertex of each
    margin = np.asarray(margins, dtype=float).reshape(n)
    sigma = np.asarray(sigmas).reshape(n)
    scale = run_means(sa.length, k)
    lmax = np.stack(
        [
            np.concatenate([f.lmax_start for f in frames]),
            np.concatenate([f.lmax_end for f in frames]),
        ],
        axis=1,
    )
    if lmax_scales is not None and any(x is not None for x in lmax_scales):
        factor = np.ones_like(lmax)
        for j, x in enumerate(lmax_scales):
            if x is not None:
                factor[so[j] : so[j] + k[j]] = x
        lmax = lmax * factor
    # quadratic rows, per vertex: l >= m at every sample, l <= l_max - m at both ends, Dn >= m
    q_start = np.cumsum(m + 3 * k) - (m + 3 * k)
    at = np.arange(len(s)) - mo[mv] + q_start[mv]  # the samples' rows
    end = np.arange(len(sv)) - so[sv] + q_start[sv] + m[sv]  # the sides' first end row
    rows = int((m + 3 * k).sum())
    q_side, q_sample = np.empty(rows, dtype=np.int64), np.empty(rows, dtype=np.int64)
    coef, sign, const = np.empty(rows), np.empty(rows), np.empty(rows)
    sides = np.arange(len(sv))
    q_side[at], q_sample[at] = side, np.arange(len(s))
    floor = np.zeros(n) if floors is None else np.asarray(floors, dtype=float).reshape(n)
    coef[at], sign[at], const[at] = 2 * np.maximum(margin, floor)[mv], 1.0, 0.0
    ms = margin[sv]
    # short of T by the floor too, over 2 sin(corner / 2): the straight crease between two
    # ends that short of T is at least the floor long (a crease through T exactly is merged)
    corner = np.concatenate([np.asarray(f.corner_angle, dtype=float) for f in frames])
    prev = so[sv] + (sides - so[sv] - 1) % k[sv]  # side i starts on face i - 1
    short = floor[sv, None] / (2 * np.sin(0.5 * np.stack([corner[prev], corner], axis=1)))
    m_t = np.maximum(ms[:, None], np.fmin(short, 0.25 * lmax))
    q_kind = np.full(rows, "l_min", dtype=_KIND_TYPE)
    for block, (smp, c_, g_) in enumerate(
        [
            (first, -2 * (lmax[:, 0] - m_t[:, 0]), 0.0),
            (last, -2 * (lmax[:, 1] - m_t[:, 1]), 0.0),
            (first, -scale[sv], -ms),
        ]
    ):
        r = end + block * k[sv]
        q_side[r], q_sample[r] = sides, smp
        coef[r], sign[r], const[r] = c_, (-1.0 if block < 2 else 0.0), g_
        q_kind[r] = "l_max" if block < 2 else "patch"
    # linear rows, per vertex: non-intersection along the arc, the chord plane, every face,
    # then three fold planes per face
    chord = np.flatnonzero(sa.arc > 0)
    c = np.bincount(sv[chord], minlength=n)
    l_count = m + c + 4 * k
    l_start = run_starts(l_count)[:-1]
    along = sa.R[chord]
    if cone.any():  # the chord plane of a fillet passes through its apex
        along = np.where(cone[chord, None], C[first[chord]] - sa.S[chord], along)
    ne = np.cross(C[last[chord]] - C[first[chord]], along)
    ne /= np.linalg.norm(ne, axis=1)[:, None]
    T_start = np.concatenate([f.T_start for f in frames])
    T_end = np.concatenate([f.T_end[: len(f.ring.faces)] for f in frames])
    lin_rows = int(l_count.sum())
    lin_a, lin_b = np.empty((lin_rows, 3)), np.empty(lin_rows)
    l_kind = np.empty(lin_rows, dtype=_KIND_TYPE)
    l_element = np.empty(lin_rows, dtype=np.int64)
    chord_rank = np.arange(len(chord)) - (run_starts(c)[:-1])[sv[chord]]
    ring_faces = np.concatenate([np.asarray(f.ring.faces, dtype=np.int64) for f in frames])
    face_row = sides - so[sv] + l_start[sv] + m[sv] + c[sv]
    nxt = so[sv] + (sides - so[sv] + 1) % k[sv]
    R_end, R_start = sa.R, sa.R[nxt]  # the sides' lines on each face, at its T
    if cone.any():
        R_end = sa.chart(sides, sa.arc)[1]
        R_start = sa.chart(nxt, np.zeros(len(nxt)))[1]
    tilted = fold_planes(sa.face_normal, R_end, R_start, sigma[sv])
    for idx, vert, normal, point, kind, element in (
        (np.arange(len(s)) - mo[mv] + l_start[mv], mv, N, C, "nonint", sa.edge[side]),
        (chord_rank + l_start[sv[chord]] + m[sv[chord]], sv[chord], ne, T_start[chord], "chord",
         sa.edge[chord]),
        (face_row, sv, sa.face_normal, T_end, "face", ring_faces),
        *((face_row + (1 + j) * k[sv], sv, tilted[:, j], T_end, "fold", ring_faces)
          for j in range(3)),
    ):  # fmt: skip
        a_ = sigma[vert][:, None] * normal
        lin_a[idx] = a_
        lin_b[idx] = -np.einsum("ij,ij->i", a_, point) - margin[vert]
        l_kind[idx], l_element[idx] = kind, element
    quad_c, quad_s = C[q_sample], s[q_sample]
    if cone.any():  # per-row charts in which a fillet reads as a cylinder
        quad_Q, quad_t, quad_R, quad_M = sa.row_maps(q_side, quad_s)
    else:
        quad_R, quad_M, quad_Q, quad_t = sa.R[q_side], sa.M[q_side], sa.Q[q_side], sa.t[q_side]
    q_element = sa.edge[q_side]
    q_end, l_end = q_start + m + 3 * k, l_start + l_count
    out = []
    for j, (q0, q1, l0, l1) in enumerate(
        zip(q_start.tolist(), q_end.tolist(), l_start.tolist(), l_end.tolist(), strict=True)
    ):
        v = vs[j]
        out.append(
            ApexConstraints(
                scale=float(scale[j]),
                v_fixed=None if v is None else np.asarray(v, dtype=float),
                quad_c=quad_c[q0:q1],
                quad_R=quad_R[q0:q1],
                quad_M=quad_M[q0:q1],
                quad_Q=quad_Q[q0:q1],
                quad_t=quad_t[q0:q1],
                quad_s=quad_s[q0:q1],
                quad_coef=coef[q0:q1],
                quad_sign=sign[q0:q1],
                quad_const=const[q0:q1],
                lin_a=lin_a[l0:l1],
                lin_b=lin_b[l0:l1],
                quad_kind=q_kind[q0:q1],
                quad_element=q_element[q0:q1],
                lin_kind=l_kind[l0:l1],
                lin_element=l_element[l0:l1],
            )
        )
    return out


def fold_planes(face_normal, R_end, R_start, sigma) -> np.ndarray:
    """The fold rows' normals of :func:`build_constraints_many`: three planes through the
    corner T of each face, tilted from the face by a little more than ``tol.fold``.

    The straight crease on a face joins a point of the side line ending there (through T,
    along ``R_end``) to a point of the side line starting there (along ``R_start``), both
    between T and the edge midpoints. The cone triangle over it meets the face at
    ``atan2(h, w)``, ``h`` the apex's height over the face and ``w`` its distance beyond the
    crease line, over the face piece: at ``tol.fold`` or more when the apex lies above the
    plane through the crease tilted by ``tol.fold`` over the piece. Moving that line toward T
    only raises the plane there, so the planes through T whose in-plane normals ``n`` point
    into the face between those of the two side lines (``n_a``, ``n_b``, at the angle
    ``pi`` minus the face's corner) bound every crease's plane; the three with ``n_a``, ``n_b``
    and their bisector do, with the tilt ``delta`` of ``tan(delta) = tan(tol.fold) /
    cos(theta / 4)`` (``theta`` the angle between ``n_a`` and ``n_b``), since between two of
    them ``n . x <= max(n_1 . x, n_2 . x) / cos(theta / 4)``.

    Parameters
    ----------
    face_normal : (k, 3) float
        Front normal of each face.
    R_end, R_start : (k, 3) float
        Unit directions (toward the vertex) of the side ending on the face and of the side
        starting on it.
    sigma : (k,) int
        Side of the apex (+1 front, -1 back).

    Returns
    -------
    (k, 3, 3) float
        Per face, the normals ``w`` of its three rows ``sigma w . (V - T) >= margin``:
        ``cos(delta) N - sigma sin(delta) n``, for ``n = n_a``, the bisector, ``n_b``.
    """
    ca, cb = np.cross(face_normal, R_end), np.cross(face_normal, R_start)
    # into the face: n_a toward the starting side's line away from T (along -R_start)
    n_a = ca * np.where(_dot_rows(ca, R_start) > 0, -1.0, 1.0)[:, None]
    n_b = cb * np.where(_dot_rows(cb, R_end) > 0, -1.0, 1.0)[:, None]
    mid = n_a + n_b
    two_cos_half = np.linalg.norm(mid, axis=1)  # 2 cos(theta / 2)
    mid = mid / np.where(two_cos_half > 0, two_cos_half, 1.0)[:, None]
    cos_quarter = np.sqrt(0.5 * (1.0 + 0.5 * two_cos_half))
    tan_tilt = np.tan(tol.fold) / cos_quarter
    cos_tilt = 1.0 / np.sqrt(1.0 + tan_tilt**2)
    sin_tilt = tan_tilt * cos_tilt
    n = np.stack([n_a, mid, n_b], axis=1)  # (k, 3, 3)
    s = (np.asarray(sigma, dtype=float) * sin_tilt)[:, None, None]
    return cos_tilt[:, None, None] * face_normal[:, None, :] - s * n


def _dot_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


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
    solver : str
        What found it: ``"target"``, ``"ipm"`` (the batched interior-point method),
        ``"<fallback>+ipm"`` (a fallback of its feasibility phase found the feasible point:
        ``starts``, ``again``, ``lp`` (the linear programmes) or ``long``, see
        :data:`~filletfold.vertex.settings.FALLBACKS`), either with ``"+slsqp"`` (finished
        by SLSQP), ``"slsqp"`` (the reference solver).
    """

    ok: bool
    x: np.ndarray
    failing: list
    at_target: bool
    solver: str = "slsqp"

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
    cuts : (m, 2) float
        ``(side, s)``: where ``l < 0`` or the non-intersection condition fails on a side, the
        arc parameter of its worst point (a sample to add to the next solve).
    """

    ok: bool
    margin: float
    failing: list
    cuts: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)), compare=False)


def crease_length(
    frame: VertexFrame, i, V: np.ndarray, v: np.ndarray, s: np.ndarray, C: np.ndarray | None = None
):
    """Eq. (1): ruling length ``l(s)`` of the crease on cylinder ``i``, or on several.

    The crease functions of :mod:`filletfold.vertex.crease` on a vertex frame's sides.

    Parameters
    ----------
    frame : VertexFrame
    i : int or (k,) int
        Side index, or the side of each arc parameter.
    V : (3,) float
        Spatial apex.
    v : (2,) float
        Developed apex in the common frame.
    s : (k,) float
        Arc parameters in ``[0, a_i]``.
    C : (k, 3) float, optional
        The base-curve points ``C(s)``, when known.

    Returns
    -------
    l : (k,) float
    dn : float or (k,) float
        The denominator ``(v - c) . r - (V - C) . R`` (constant along a cylinder's arc, not
        along a conical fillet's; > 0 when valid), per side given: a float for one side (the
        smallest on a fillet), else one per arc parameter.
    """
    sa = frame.arrays
    s = np.asarray(s, dtype=float)
    one = np.ndim(i) == 0
    side = np.full(len(s), i) if one else np.asarray(i)
    if C is None:
        C = sa.base(side, s)
    if sa.conical[side].any():  # a fillet's chart turns with s: dn varies along its arc
        Q, t, R, M = sa.row_maps(side, s)
        vi = chart_apex(Q, t, v)
        dn = crease_denominator(V, vi, M, R)
        l = crease_height(crease_numerator(V, vi, s, C), dn)
        return l, float(dn.min()) if one else dn
    vi = chart_apex(sa.Q, sa.t, v)  # per side of the ring
    dn = crease_denominator(V, vi, sa.M, sa.R)
    l = crease_height(crease_numerator(V, vi[side], s, C), dn[side])
    return l, float(dn[i]) if one else dn[side]


def validate_apex(
    frame: VertexFrame,
    V: np.ndarray,
    v: np.ndarray,
    sigma: int,
    n_samples: int = 65,
    centres: np.ndarray | None = None,
) -> ApexCheck:
    """One vertex through :func:`validate_apices`.

    Parameters
    ----------
    frame : VertexFrame
    V : (3,) float
        Spatial apex.
    v : (2,) float
        Developed apex in the common frame.
    sigma : int
    n_samples : int
    centres : (n_faces, 3) float, optional
    """
    return validate_apices([frame], [V], [v], [sigma], n_samples, centres)[0]


def validate_apices(
    frames: Sequence[VertexFrame],
    apices,
    developed,
    sigmas,
    n_samples: int = 65,
    centres: np.ndarray | None = None,
    floors=None,
) -> list[ApexCheck]:
    """Check every condition along every arc of many vertices at once, without margin.

    Conditions: ``Dn > 0``; ``l(s) >= 0`` (at least the vertex's ``floor``); ``l <= l_max`` at
    both ends; ``sigma (V - C) . N > 0`` along the arc; ``sigma (V - T) . N_f > 0`` for every
    face; the cone triangle over the straight crease on every face meets the face at
    ``tol.fold`` or more (the crease folds by at most 180 degrees less that); and, given the
    face pieces' ``centres``, the straight crease on every face runs between the corner T and
    the centre, so the vertex's share of the face stays a simple polygon.

    The two conditions along an arc are checked at ``n_samples`` points and then at the
    minimum between them, found by Newton steps on their closed forms (a convex quadratic
    plus a sinusoid over at most half its period: at most two local minima, which the samples
    separate). The sides of all vertices are stacked into one :class:`SideArrays` (sides of a
    vertex one after another), so every step runs once for the whole batch; each vertex's
    result is the same as when it is checked alone.

    Parameters
    ----------
    frames : sequence of VertexFrame
        Closed-ring vertices, ``n`` of them.
    apices : (n, 3) float
        Spatial apex ``V`` of each vertex.
    developed : (n, 2) float
        Developed apex ``v`` of each vertex, in its common frame.
    sigmas : (n,) int
        Side of each apex (+1 front, -1 back).
    n_samples : int
        Samples per arc (both ends included).
    centres : (n_faces, 3) float, optional
        Face pieces' centres, indexed by mesh face: adds the face-centre condition.
    floors : (n,) float, optional
        Shortest crease ruling of each vertex (length; default 0).

    Returns
    -------
    list of ApexCheck
        One per vertex, in the order of ``frames``; ``failing`` lists, per vertex, the
        conditions of its sides in order (patch, l_min, l_max, nonint per side), then those of
        its faces (face, centre, fold per face).
    """
    n = len(frames)
    if n == 0:
        return []
    arrs = [f.arrays for f in frames]
    sa = _stack(arrs)  # the sides of every vertex, vertex after vertex
    n_sides = np.array([len(a.arc) for a in arrs])
    n_faces = np.array([len(f.ring.faces) for f in frames])
    vert = run_owners(n_sides)  # (K,) vertex of each side
    fvert = run_owners(n_faces)  # (F,) vertex of each face
    offset = run_starts(n_sides)[:-1]  # first side of each vertex
    scale = run_means(sa.length, n_sides)
    eps = tol.validate * scale  # (n,)
    sigma = np.asarray(sigmas).reshape(n)
    V = np.asarray(apices, dtype=float).reshape(n, 3)[vert]  # (K, 3) per side
    v = np.asarray(developed, dtype=float).reshape(n, 2)[vert]  # (K, 2)
    lmax_start = np.concatenate([f.lmax_start for f in frames])
    lmax_end = np.concatenate([f.lmax_end for f in frames])
    faces = np.concatenate([f.ring.faces for f in frames])  # (F,) mesh faces
    T_face = np.concatenate([f.T_end[:nf] for f, nf in zip(frames, n_faces, strict=True)])
    samples = _Samples(*sa.samples(n_samples))
    side, first, last, s, C, N = samples
    vi = chart_apex(sa.Q, sa.t, v)  # developed apex in each cylinder's chart
    d = V[side] - C
    if sa.conical.any():  # a fillet's chart turns with s: eq. (1) row by row, dn varies
        chart = sa.cone_chart(side, s)  # the fillets' charts, once for both below
        Q_s, t_s, R_s, M_s = sa.row_maps(side, s, cone_chart=chart)
        vi_s = chart_apex(Q_s, t_s, v[side])
        num = crease_numerator(V[side], vi_s, s, C)
        dn_s = crease_denominator(V[side], vi_s, M_s, R_s)
        dn = np.minimum.reduceat(dn_s, first)
        N = sa.surface_normal(side, s, cone_chart=chart, N=N)
    else:
        num = crease_numerator(V[side], vi[side], s, C)
        dn = crease_denominator(V, vi, sa.M, sa.R)
        dn_s, R_s = dn[side], sa.R[side]
    valid = dn > 0
    l = crease_height(num, np.where(valid[side], dn_s, 1.0))
    nonint = sigma[vert][side] * np.einsum("ij,ij->i", d, N)
    # the minima between samples: Newton from the smallest sample on the closed forms
    l_min, l_at = _refined_min(sa, V, l, s, first, vi=vi, dn=dn)
    nonint_min, nonint_at = _refined_min(sa, V, nonint, s, first, sigma=sigma[vert])
    if sa.conical.any():  # no closed form on a fillet: densely between the samples beside
        # each side's smallest one
        cone = np.flatnonzero(sa.conical)
        for values, best, at, kind in ((l, l_min, l_at, "l"), (nonint, nonint_min, nonint_at, "n")):
            b, t = _conical_dense_min(sa, V, v, sigma[vert], cone, values, samples, kind)
            lower = b < best[cone]
            best[cone[lower]], at[cone[lower]] = b[lower], t[lower]
    floor = np.zeros(n) if floors is None else np.asarray(floors, dtype=float).reshape(n)
    crease = _curved_crease_fold(sa, V, vi, dn, samples._replace(N=N), l, nonint, valid)
    checks = np.stack(
        [
            dn,
            np.where(valid, l_min - floor[vert], -np.inf),
            np.where(valid, np.minimum(lmax_start - l[first], lmax_end - l[last]), -np.inf),
            nonint_min,
            np.minimum.reduceat(crease, first),
        ],
        axis=1,
    )  # (K, 5): patch, l_min, l_max, nonint, crease
    strict = np.array([True, False, False, True, True])
    e_side = eps[vert][:, None]
    bad = np.where(strict, checks < e_side, checks < -e_side)
    # faces: side i of a vertex ends on its face i, side i + 1 starts on it
    local = np.arange(len(faces)) - np.repeat(run_starts(n_faces)[:-1], n_faces)
    fside = offset[fvert] + local  # (F,) side ending on each face
    nxt = offset[fvert] + (local + 1) % n_sides[fvert]  # (F,) side starting on it
    nrm = sa.face_normal
    face_val = sigma[fvert] * np.einsum("ij,ij->i", V[fside] - T_face, nrm)
    # the straight crease on each face, from side i's end to side i + 1's start
    p0 = C[last[fside]] + l[last[fside], None] * R_s[last[fside]]
    p1 = C[first[nxt]] + l[first[nxt], None] * R_s[first[nxt]]
    dvec = p1 - p0
    length = np.linalg.norm(dvec, axis=1)
    e_face = eps[fvert]
    crease = length > e_face
    dvec = dvec / np.where(crease, length, 1.0)[:, None]
    side_t = np.einsum("ij,ij->i", np.cross(dvec, T_face - p0), nrm)
    # fold: the cone triangle meets the face at atan2(h, w) >= tol.fold (h the apex's height
    # over the face, w its distance beyond the crease line, over the piece: away from T)
    beyond = -np.sign(side_t)[:, None] * np.cross(nrm, dvec)  # in-plane normal away from T
    w = np.einsum("ij,ij->i", V[fside] - p0, beyond)
    fold_val = np.cos(tol.fold) * face_val - np.sin(tol.fold) * w
    fold_val = np.where(crease, fold_val, np.inf)  # no crease: no fold
    centre_val = np.full(len(faces), np.inf)
    if centres is not None:
        side_c = np.einsum("ij,ij->i", np.cross(dvec, centres[faces] - p0), nrm)
        centre_val = np.where(side_t != 0, -side_c * np.sign(side_t), np.abs(side_c))
        centre_val = np.where(crease, centre_val, np.inf)  # no crease: no condition
    # the smallest slack per vertex (a NaN anywhere propagates, as in np.min)
    margin = np.full(n, np.inf)
    np.minimum.at(margin, vert, checks.min(axis=1))
    np.minimum.at(margin, fvert, np.minimum(np.minimum(face_val, centre_val), fold_val))
    failing = [[] for _ in range(n)]
    names = ("patch", "l_min", "l_max", "nonint", "crease")
    for i, c in zip(*np.nonzero(bad), strict=True):
        failing[vert[i]].append(f"{KINDS[names[c]]} at edge {sa.edge[i]}")
    face_bad = np.stack([face_val < e_face, centre_val < e_face, fold_val < e_face], axis=1)
    texts = (f"{KINDS['face']} at face", f"{KINDS['centre']} on face", f"{KINDS['fold']} at face")
    for j, c in zip(*np.nonzero(face_bad), strict=True):
        failing[fvert[j]].append(f"{texts[c]} {int(faces[j])}")
    # where l or the non-intersection condition fails: the worst point, a sample to add
    cut_side, cut_kind = np.nonzero(bad[:, [1, 3]])
    cut_s = np.where(cut_kind == 0, l_at[cut_side], nonint_at[cut_side])
    local_side = cut_side - offset[vert[cut_side]]
    cuts = [[] for _ in range(n)]
    for i, j, t in zip(vert[cut_side].tolist(), local_side.tolist(), cut_s.tolist(), strict=True):
        cuts[i].append((j, t))
    return [
        ApexCheck(not fail, float(m), fail, np.array(c, dtype=float).reshape(-1, 2))
        for fail, m, c in zip(failing, margin, cuts, strict=True)
    ]


class _Samples(NamedTuple):
    """The samples along every side's arc (:meth:`SideArrays.samples`): ``side`` (m,) the
    side of each, ``first`` / ``last`` (k,) each side's first and last sample, ``s`` (m,) the
    arc parameter, ``C`` (m, 3) the base-curve point, ``N`` (m, 3) the surface normal."""

    side: np.ndarray
    first: np.ndarray
    last: np.ndarray
    s: np.ndarray
    C: np.ndarray
    N: np.ndarray


def _curved_crease_fold(sa, V, vi, dn, samples: _Samples, l, nonint, valid) -> np.ndarray:
    """(m,) slack of the curved crease's fold at every sample (length units, >= 0 valid):
    the cone meets the cylinder along ``F(s)`` at an interior angle of at least ``tol.fold``,
    so that no curved crease folds by more than 180 degrees less that angle.

    In the plane across the crease (normal to ``F'(s) = C'(s) + l'(s) R``) the cylinder leaves
    the crease along ``h``, ``-R`` made normal to ``F'``, and the cone along ``w``, ``V - F``
    made normal to it; ``w . sigma N`` is the non-intersection value (eq. 2: ``F - C`` is
    along ``R``, normal to ``N``). With ``alpha`` the angle from ``h`` to ``w``, the slack is
    ``|w| sin(alpha - fold) = cos(fold) (w . sigma N) - sin(fold) (w . h)``. A conical side
    (its chart turns with ``s``) is not measured here (``inf``)."""
    side, s, C = samples.side, samples.s, samples.C
    out = np.full(len(s), np.inf)
    rows = np.flatnonzero(~sa.conical[side] & (sa.radius[side] > 0) & valid[side])
    if not len(rows):
        return out
    i, t = side[rows], s[rows]
    r, kappa = sa.radius[i], sa.kappa[i]
    P = np.einsum("ij,ij->i", V[i] - sa.O[i], sa.N0[i])
    Q = np.einsum("ij,ij->i", V[i] - sa.O[i], sa.B[i])
    d1, _ = numerator_arc_derivatives(vi[i, 0], t, kappa, r, P, Q)
    c, sn = np.cos(t / r), np.sin(t / r)
    dC = kappa[:, None] * (-sn[:, None] * sa.N0[i] + c[:, None] * sa.B[i])
    R = sa.R[i]
    dF = dC + (d1 / (2.0 * dn[i]))[:, None] * R
    u = dF / np.linalg.norm(dF, axis=1)[:, None]
    w = V[i] - (C[rows] + l[rows, None] * R)
    w = w - np.einsum("ij,ij->i", w, u)[:, None] * u
    h = -(R - np.einsum("ij,ij->i", R, u)[:, None] * u)
    hn = np.linalg.norm(h, axis=1)
    h /= np.where(hn > 0, hn, 1.0)[:, None]  # a crease along R: no direction, no bound
    out[rows] = np.cos(tol.fold) * nonint[rows] - np.sin(tol.fold) * np.einsum("ij,ij->i", w, h)
    return out


def _stack(arrays: Sequence[SideArrays]) -> SideArrays:
    """The sides (and faces) of many vertices in one :class:`SideArrays`, one after another."""
    return SideArrays(
        **{x.name: np.concatenate([getattr(a, x.name) for a in arrays]) for x in fields(SideArrays)}
    )


#: Points between the two samples beside a conical side's smallest one where the validation
#: evaluates its conditions again (a fillet's crease has no closed form to refine on).
CONICAL_DENSE = 33


def _conical_dense_min(sa, V, v, sigma, sides, values, samples: _Samples, kind):
    """(k,) smallest value and where, of ``l(s)`` (``kind`` "l") or ``sigma (V - C) . N``
    ("n") on conical ``sides`` (k,), over :data:`CONICAL_DENSE` points between the samples
    beside each side's smallest sample. ``V``, ``v``, ``sigma`` per side."""
    s, first, last = samples.s, samples.first, samples.last
    lo = np.empty(len(sides))
    hi = np.empty(len(sides))
    for j, i in enumerate(sides.tolist()):
        a, b = int(first[i]), int(last[i])
        k = a + int(np.argmin(values[a : b + 1]))
        lo[j], hi[j] = s[max(k - 1, a)], s[min(k + 1, b)]
    t = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, CONICAL_DENSE)[None]
    side = np.repeat(sides, CONICAL_DENSE)
    t = t.ravel()
    C = sa.base(side, t)
    if kind == "l":
        Q, tr, R, M = sa.row_maps(side, t)
        vi = chart_apex(Q, tr, v[side])
        dn = crease_denominator(V[side], vi, M, R)
        val = crease_height(crease_numerator(V[side], vi, t, C), np.where(dn > 0, dn, 1.0))
        val = np.where(dn > 0, val, -np.inf)
    else:
        N = sa.surface_normal(side, t)
        val = sigma[side] * np.einsum("ij,ij->i", V[side] - C, N)
    val = val.reshape(len(sides), CONICAL_DENSE)
    arg = np.argmin(val, axis=1)
    rows = np.arange(len(sides))
    return val[rows, arg], t.reshape(len(sides), CONICAL_DENSE)[rows, arg]


def _refined_min(sa, V, values, s, first, *, vi=None, dn=None, sigma=1):
    """(k,) smallest value per side along its arc: the smallest sample, refined by Newton steps
    on the closed form between the samples; and (k,) the arc parameter where it is reached.

    With ``vi`` ((k, 2) float) and ``dn`` ((k,) float) the values are the crease lengths
    ``l(s) = num(s) / (2 dn)`` of eq. (1) (``num(s) = (v_x - s)^2 + v_y^2 - |V - C(s)|^2``);
    without, ``sigma (V - C(s)) . N(s)``. With ``C(s) = O + kappa r N(s)`` both are
    trigonometric in ``s / r``. ``V`` ((3,) or (k, 3) float) and ``sigma`` (int or (k,)) may be
    given per side, so that the sides of many vertices are refined at once. A conical side
    keeps its smallest sample (its rows' charts turn with ``s``).
    """
    ends = np.append(first[1:], len(values))
    best = np.minimum.reduceat(values, first)
    r, arc = sa.radius, sa.arc
    ok = (r > 0) & ~sa.conical  # a conical fillet's closed form is not this one: samples only
    # the first sample of each side that attains its smallest value (the side's first sample
    # where none does: a NaN)
    side = run_owners(ends - first)
    hit = np.flatnonzero(values == best[side])
    lead = np.ones(len(hit), dtype=bool)
    lead[1:] = side[hit[1:]] != side[hit[:-1]]
    arg = first.copy()
    arg[side[hit[lead]]] = hit[lead]
    t = s[arg].copy()
    if not ok.any():
        return best, t
    rr = np.where(ok, r, 1.0)
    P = np.einsum("ij,ij->i", V - sa.O, sa.N0)
    Q = np.einsum("ij,ij->i", V - sa.O, sa.B)
    for _ in range(4):
        if vi is not None:  # derivatives of num(s)
            d1, d2 = numerator_arc_derivatives(vi[:, 0], t, sa.kappa, rr, P, Q)
        else:
            c, sn = np.cos(t / rr), np.sin(t / rr)
            d1 = sigma / rr * (-P * sn + Q * c)
            d2 = sigma / rr**2 * (-P * c - Q * sn)
        step = np.where(d2 > 0, d1 / np.where(d2 > 0, d2, 1.0), 0.0)
        t = np.clip(t - step, 0.0, arc)
    i = np.arange(len(first))
    C, N = sa.base_normal(i, t)
    if vi is not None:
        val = crease_height(crease_numerator(V, vi, t, C), np.where(dn > 0, dn, 1.0))
    else:
        val = sigma * np.einsum("ij,ij->i", V - C, N)
    return np.where(ok, np.minimum(best, val), best), np.where(ok & (val < best), t, s[arg])
