"""A compiled (numba) version of :func:`filletfold.vertex.batch.interior_point_numpy`.

Same algorithm, step by step, as the numpy version (see that function and the module
docstring of :mod:`filletfold.vertex.batch`): the same barrier update, stopping rules
(``stop_slack``, ``groups``, ``give_up``, the stuck rule), the same shift of the Newton
matrix to positive definite, the same fraction-to-the-boundary rule and backtracking line
search. Only the order of the loops differs: an outer loop over the iterations and, inside
it, a loop over the live problems that does all of a problem's work (rows, Newton matrix, its
smallest eigenvalue, the solve, the line search) in loops over its rows, so no ``(B, R, n)``
temporary is ever made. The iteration count stays the outer loop so that the rules that look
at the whole batch behave exactly as in the numpy version:

* a problem whose copies (``groups``) reached the slack cap is done in the same iteration;
* finished problems are dropped once a quarter of the live ones are done (until then they
  keep iterating, which can un-stick a stuck problem, as in the numpy version).

The results agree with the numpy version's up to rounding: sums in another order (the row
loops are vectorised), ``sum(log g)`` as logarithms of products of 8 rows, Jacobi rotations
instead of LAPACK's ``syevd`` for the smallest eigenvalue (only computed when a Cholesky
factorisation shows that a shift is needed), a hand-written LU instead of ``gesv``. One
deliberate difference: a singular Newton matrix (never seen: the matrix is shifted to
positive definite) is solved by least squares for that problem alone, where the numpy
version switches the whole batch to least squares.

The code is written for numba: loops over problems inside the functions (a numba call with
a dozen array arguments costs ~100 ns, a problem's iteration ~1 µs), rows indexed as
``x[b, j]`` rather than through per-problem views (each view costs two atomic reference
count updates), the gradients stored by variable (``G[b, k, j] = A[b, j, k]``) so that the
inner loops run over contiguous rows and vectorise.

A batch of at least ``2 * MIN_PER_THREAD`` problems is split into parts (the copies of a
problem in one part) that run in threads at once, the compiled kernel releasing the GIL
(:func:`filletfold.parallel.threads`; ``FILLETFOLD_THREADS`` sets their number). Each part
is a batch of its own; a problem's iterations depend on the rest of its batch only through
the rule for dropping finished problems, which changes nothing for a problem that converges.

The kernel has no copy of the crease formula of eq. (1) (:mod:`filletfold.vertex.crease`):
it receives every constraint row already evaluated about the target, as
``a + A . y + alpha (y . e y)`` (:func:`filletfold.vertex.rows.pack_problems`), which is exact
for those rows because the charts are rigid (tests/vertex/test_batch.py checks the rows
against :meth:`~filletfold.vertex.apex.ApexConstraints.values` away from the target).

numba is optional: without it this module still imports, :data:`AVAILABLE` is False and
:func:`interior_point_numba` runs the same code as plain (very slow) Python.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..parallel import thread_map, threads
from .settings import (
    ARMIJO,
    GIVE_UP_SLACK,
    HESSIAN_FLOOR,
    IPM_TOL,
    MERIT_ROUNDOFF,
    MULTIPLIER_FLOOR,
    MULTIPLIER_START_FLOOR,
    PRIMAL_WEIGHT_MU,
    STAT_TOL,
    T_CAP,
)

try:
    from numba import njit

    AVAILABLE = True
except ImportError:  # pragma: no cover - exercised only without numba
    AVAILABLE = False

    def njit(*args, **kwargs):
        """Stand-in for :func:`numba.njit` without numba: the function itself."""
        if len(args) == 1 and callable(args[0]) and not kwargs:
            return args[0]
        return lambda f: f


if TYPE_CHECKING:
    from .rows import RowBlock

#: LLVM fast-math flags of the row loops: reassociation (vectorised sums), contraction (fused
#: multiply-add), reciprocals and signed zeros; not the ones that assume no NaN or infinity.
FAST = {"reassoc", "contract", "arcp", "nsz"}

# Places in the array of :func:`_settings`.
_MULTIPLIER_START_FLOOR, _GIVE_UP_SLACK, _PRIMAL_WEIGHT_MU, _MERIT_ROUNDOFF = 0, 1, 2, 3
_ARMIJO, _MULTIPLIER_FLOOR, _HESSIAN_FLOOR = 4, 5, 6


def _settings() -> np.ndarray:
    """The solver settings the compiled functions read, as one array passed to them.

    Not read as globals: numba's disk cache would freeze a global at its value when the
    kernel was compiled and keep it after an edit of ``settings.py`` (the cache is renewed
    only when this file changes), while the numpy version reads the new value.
    """
    return np.array(
        [
            MULTIPLIER_START_FLOOR,
            GIVE_UP_SLACK,
            PRIMAL_WEIGHT_MU,
            MERIT_ROUNDOFF,
            ARMIJO,
            MULTIPLIER_FLOOR,
            HESSIAN_FLOOR,
        ]
    )


def interior_point_numba(
    rows: RowBlock,
    q: np.ndarray,
    c: np.ndarray,
    y: np.ndarray,
    *,
    stop_slack: int | None = None,
    groups: np.ndarray | None = None,
    give_up: bool = False,
    max_iter: int = 80,
    tol: float = IPM_TOL,
) -> tuple[np.ndarray, np.ndarray]:
    """Minimise ``0.5 y.q.y + c.y`` subject to ``rows(y) > 0`` from strictly feasible ``y``.

    Drop-in replacement of :func:`filletfold.vertex.batch.interior_point_numpy` (same parameters,
    same results up to rounding), compiled with numba.

    The parameters ``rows`` (B problems of R rows), ``q`` (n,), ``c`` (B, n), ``y`` (B, n),
    ``stop_slack``, ``groups``, ``give_up``, ``max_iter``, ``tol`` and the results ``y``
    (B, n) and ``converged`` (B,) are those of the numpy version.
    """
    B = rows.A.shape[0]
    if groups is not None and stop_slack is not None and B:
        _, dense = np.unique(np.asarray(groups), return_inverse=True)
        dense = np.ascontiguousarray(dense.reshape(-1), dtype=np.int64)
        n_groups = int(dense.max()) + 1
    else:
        dense, n_groups = np.zeros(B, dtype=np.int64), 0
    f8 = np.float64
    arrays = (
        np.ascontiguousarray(rows.a, dtype=f8),
        np.ascontiguousarray(np.asarray(rows.A, dtype=f8).transpose(0, 2, 1)),
        np.ascontiguousarray(rows.alpha, dtype=f8),
        np.ascontiguousarray(rows.mask, dtype=f8),
        np.ascontiguousarray(c, dtype=f8),
        np.ascontiguousarray(y, dtype=f8),
    )
    e, q = np.ascontiguousarray(rows.e, dtype=f8), np.ascontiguousarray(q, dtype=f8)
    rules = (bool(give_up), int(max_iter), float(tol), float(T_CAP), float(STAT_TOL), _settings())
    slack = -1 if stop_slack is None else int(stop_slack)

    def run(idx):
        """The kernel on problems ``idx`` (all when None)."""
        a, G, al, mf, c_, y_ = (x if idx is None else x[idx] for x in arrays)
        grp = dense if idx is None else dense[idx]
        if idx is not None and n_groups:
            _, grp = np.unique(grp, return_inverse=True)
        k = int(grp.max()) + 1 if n_groups and len(grp) else 0
        return _kernel(a, G, al, e, mf, q, c_, y_, slack, grp.astype(np.int64), k, *rules)

    parts = _parts(dense if n_groups else np.arange(B), threads())
    if len(parts) == 1:
        return run(None)
    y_out, conv = np.empty((B, y.shape[1])), np.empty(B, dtype=bool)
    for idx, (y_p, conv_p) in zip(parts, thread_map(run, parts, "kernel"), strict=True):
        y_out[idx], conv[idx] = y_p, conv_p
    return y_out, conv


#: Problems per thread below which the kernel runs in one thread.
MIN_PER_THREAD = 64


def _parts(groups: np.ndarray, n_threads: int) -> list[np.ndarray]:
    """Problems split into at most ``n_threads`` parts of at least :data:`MIN_PER_THREAD`,
    the copies of a problem (same ``groups`` value) in the same part.

    Every problem's iterations are independent of the others' except through its group and
    the batch's rule for dropping finished problems, so each part is a batch of its own.
    """
    n = min(n_threads, len(groups) // MIN_PER_THREAD)
    if n <= 1:
        return [np.arange(len(groups))]
    part = np.minimum(groups * n // (int(groups.max()) + 1), n - 1)
    return [np.flatnonzero(part == i) for i in range(n)]


# --------------------------------------------------------------------------- drivers
# The driver's parameters:
#
#   a, G, al : (B, R), (B, n, R), (B, R) float -- the padded rows of the RowBlock, with the
#       gradients stored by variable, G[b, k, j] = A[b, j, k]
#   e : (n,) float; mf : (B, R) float, the mask as 0/1; q : (n,) float; c, y0 : (B, n) float
#   stop_slack : int, phase 1's t or -1
#   groups : (B,) int64, dense group numbers 0 .. n_groups - 1 (ignored when n_groups is 0)
#   give_up : bool; max_iter : int; tol, t_cap, stat_tol : float
#
# and its results: y (B, n) float, converged (B,) bool.


@njit(cache=True, nogil=True)
def _kernel(a, G, al, e, mf, q, c, y0, stop_slack, groups, n_groups, give_up, max_iter, tol,
            t_cap, stat_tol, st):  # fmt: skip
    """The iterations of all problems (see the comment above for the parameters)."""
    B, _, R = G.shape
    yl, y_out = y0.copy(), y0.copy()
    g, lam = np.empty((B, R)), np.empty((B, R))
    mu, count = np.empty(B), np.empty(B)
    conv, stuck = np.zeros(B, dtype=np.bool_), np.zeros(B, dtype=np.bool_)
    done, reached, gave_up = (np.zeros(B, dtype=np.bool_), np.zeros(B, dtype=np.bool_),
                              np.zeros(B, dtype=np.bool_))  # fmt: skip
    hit = np.zeros(max(n_groups, 1), dtype=np.bool_)
    live = np.arange(B)
    n_live = B
    _start(live, a, G, al, e, mf, q, c, yl, g, lam, mu, count, stop_slack >= 0, st)
    for _ in range(max_iter):
        _status(live[:n_live], G, al, e, mf, q, c, yl, g, lam, mu, count, done, reached,
                gave_up, stop_slack, give_up, tol, t_cap, stat_tol, st)  # fmt: skip
        n_live = _settle(live, n_live, groups, n_groups, hit, yl, y_out, conv, stuck, done,
                         reached, gave_up)  # fmt: skip
        if n_live == 0:
            return y_out, conv
        _step(live[:n_live], a, G, al, e, mf, q, c, yl, g, lam, mu, stuck, st)
    _finish(live[:n_live], yl, y_out, conv)
    return y_out, conv


# --------------------------------------------------------------------------- the iteration
@njit(cache=True, fastmath=FAST)
def _start(idx, a, G, al, e, mf, q, c, yl, g, lam, mu, count, phase1, st):
    """Row values, multipliers and barrier parameter of the problems ``idx`` at their start.

    Phase 1: multipliers that balance the objective's gradient, spread over the rows;
    phase 2: a barrier-like start, larger on the rows close to their boundary.

    Parameters
    ----------
    idx : (m,) int
        The problems.
    a, G, al, e, mf, q, c
        As in the drivers.
    yl : (B, n) float
        Starting points.
    g, lam : (B, R) float
        Set: row values at ``yl`` and multipliers.
    mu, count : (B,) float
        Set: barrier parameters and numbers of real rows.
    phase1 : bool
    st : (k,) float
        :func:`_settings`.
    """
    _, n, R = G.shape
    for b in idx:
        _rows_at(b, a, G, al, e, yl[b], g[b])
        cnt = 0.0
        for j in range(R):
            cnt += mf[b, j]
        scale = 0.0
        for k in range(n):
            scale = max(scale, abs(yl[b, k] * q[k] + c[b, k]))
        scale = max(st[_MULTIPLIER_START_FLOOR], scale)
        comp = 0.0
        for j in range(R):
            lam[b, j] = mf[b, j] * (scale / cnt) if phase1 else mf[b, j] * scale / g[b, j]
            comp += lam[b, j] * g[b, j]
        count[b] = cnt
        mu[b] = 0.1 * comp / cnt


@njit(cache=True, fastmath=FAST)
def _status(idx, G, al, e, mf, q, c, yl, g, lam, mu, count, done, reached, gave_up,
            stop_slack, give_up, tol, t_cap, stat_tol, st):  # fmt: skip
    """Stationarity, complementarity and the stopping tests of the problems ``idx``; lowers
    the barrier parameter of those near their central-path point.

    Sets ``done`` (stationary and complementary to ``tol``), ``reached`` (phase 1's ``t``
    reached the cap, or is positive and at least the duality gap) and ``gave_up`` (``t``
    plus the gap is negative, with ``give_up``), all (B,) bool, and updates ``mu``.
    """
    _, n, R = G.shape
    grad, lam_A = np.empty(n), np.empty(n)
    for b in idx:
        m = mu[b]
        lam_al = 0.0
        comp = 0.0
        dev = 0.0  # largest |lambda g - mu| over the real rows
        for j in range(R):
            lam_al += lam[b, j] * al[b, j]
            comp += lam[b, j] * g[b, j]
            dev = max(dev, abs(mf[b, j] * (lam[b, j] * g[b, j] - m)))
        # stationarity, relative to the size of the terms that cancel in it
        gmax = 0.0
        lmax = 0.0
        for k in range(n):
            grad[k] = yl[b, k] * q[k] + c[b, k]
            s = 0.0
            for j in range(R):
                s += lam[b, j] * G[b, k, j]
            lam_A[k] = s
            gmax = max(gmax, abs(grad[k]))
            lmax = max(lmax, abs(s))
        size = 1.0 + gmax + lmax
        stat = 0.0
        for k in range(n):
            stat = max(stat, abs((grad[k] - lam_A[k] - 2 * lam_al * (e[k] * yl[b, k])) / size))
        # monotone barrier: lower mu once the iterate is close to its central-path point
        central = max(stat, dev)
        if central <= 10 * m or central <= stat_tol:  # (stationarity ends at rounding)
            mu[b] = max(0.1 * tol, 0.2 * m)
        done[b] = stat <= stat_tol and comp / count[b] <= tol
        reached[b] = False
        gave_up[b] = False
        if stop_slack >= 0:
            t = yl[b, stop_slack]
            reached[b] = t >= 0.5 * t_cap or (t > 0 and comp <= t)
            gave_up[b] = give_up and t + comp < -st[_GIVE_UP_SLACK]


@njit(cache=True)
def _settle(live, n_live, groups, n_groups, hit, yl, y_out, conv, stuck, done, reached,
            gave_up):  # fmt: skip
    """The batch-wide rules after :func:`_status`: groups, stuck problems, dropping.

    Records the point of every problem done for the first time. Returns 0 when every live
    problem is done (the results are then final); otherwise drops the done problems from
    ``live`` once they are a quarter of the ``n_live`` live ones, as the numpy version does,
    and returns the new number of live problems.
    """
    if n_groups > 0:  # every copy of a problem is done once one reached the cap
        hit[:] = False
        for i in range(n_live):
            if reached[live[i]]:
                hit[groups[live[i]]] = True
        for i in range(n_live):
            reached[live[i]] = hit[groups[live[i]]]
    n_done = 0
    for i in range(n_live):
        b = live[i]
        d = done[b] or reached[b] or gave_up[b]
        if d and not conv[b]:
            y_out[b] = yl[b]
            conv[b] = True
        d = d or stuck[b]  # no step possible: keep the point (not converged)
        done[b] = d
        n_done += d
    if n_done == n_live:
        _finish(live[:n_live], yl, y_out, conv)
        return 0
    if n_done * 4 < n_live:
        return n_live
    k = 0  # drop finished problems once a quarter is done
    for i in range(n_live):
        b = live[i]
        if not done[b]:
            live[k] = b
            k += 1
        elif not conv[b]:
            y_out[b] = yl[b]
    return k


@njit(cache=True)
def _finish(idx, yl, y_out, conv):
    """The last iterate of every problem of ``idx`` that did not converge is its result."""
    for b in idx:
        if not conv[b]:
            y_out[b] = yl[b]


@njit(cache=True, fastmath=FAST)
def _step(idx, a, G, al, e, mf, q, c, yl, g, lam, mu, stuck, st):
    """One primal-dual Newton step of each problem of ``idx``, with the line search of the
    numpy version; updates ``yl``, ``g``, ``lam`` and sets ``stuck`` where no step is
    possible.

    Newton matrix: ``sum_j w_j grad g_j grad g_j^T`` (``grad g_j = A_j + 2 alpha_j e y``) plus
    the diagonal ``q - 2 (sum_j w_j g_j alpha_j) e``, with curvature weights
    ``w = lambda / g``, or the primal ``mu / g^2`` where ``lambda`` lags behind (rows that
    just became nearly active would otherwise be crossed by every step; late on, while
    ``mu <= 1e-8``, the exact ``lambda`` again, for fast local convergence).
    """
    _, n, R = G.shape
    w, wa, v, ig = np.empty(R), np.empty(R), np.empty(R), np.empty(R)
    Ad, dlam, gt = np.empty(R), np.empty(R), np.empty(R)
    ey, u, rhs, dy, yt = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    H, W = np.empty((n, n)), np.empty((n, n))
    for b in idx:
        m = mu[b]
        primal = m > st[_PRIMAL_WEIGHT_MU]
        # Newton matrix and right-hand side
        s_waal = 0.0  # sum w alpha^2
        s_lal = 0.0  # sum lambda_h alpha
        s_val = 0.0  # sum (mu / g) alpha
        for j in range(R):
            ig[j] = 1.0 / g[b, j]
            vj = m * ig[j]
            lh = max(lam[b, j], mf[b, j] * vj) if primal else lam[b, j]
            wj = lh * ig[j]
            w[j] = wj
            wa[j] = wj * al[b, j]
            v[j] = vj
            s_waal += wj * al[b, j] * al[b, j]
            s_lal += lh * al[b, j]
            s_val += vj * al[b, j]
        for k in range(n):
            ey[k] = e[k] * yl[b, k]
            su = 0.0
            sr = 0.0
            for j in range(R):
                su += wa[j] * G[b, k, j]
                sr += v[j] * G[b, k, j]
            u[k] = su
            rhs[k] = sr
            for l in range(k, n):
                sh = 0.0
                for j in range(R):
                    sh += w[j] * (G[b, k, j] * G[b, l, j])
                H[k, l] = sh
        for k in range(n):
            for l in range(k, n):
                H[k, l] += 2 * (u[k] * ey[l] + ey[k] * u[l]) + 4 * s_waal * ey[k] * ey[l]
                H[l, k] = H[k, l]
            H[k, k] += q[k] - 2 * s_lal * e[k]
            rhs[k] = -(yl[b, k] * q[k] + c[b, k]) + rhs[k] + 2 * s_val * ey[k]
        # the reverse-convex rows make H indefinite at times: shift it to positive definite
        _shift_or_reset(H, rhs, W, st[_HESSIAN_FLOOR])
        _solve(H, rhs, dy, W)
        # directional derivatives, multiplier step, merit at the current point
        p = 0.0
        qq = 0.0
        slope = 0.0
        merit0 = 0.0
        for k in range(n):
            p += ey[k] * dy[k]
            qq += dy[k] * e[k] * dy[k]
            slope -= rhs[k] * dy[k]
            merit0 += 0.5 * (yl[b, k] * q[k] * yl[b, k]) + c[b, k] * yl[b, k]
        slope = min(slope, 0.0)
        merit0 -= m * _sum_log(g[b])
        _rows_times(b, G, dy, Ad)
        # fraction to the boundary for lambda, then backtracking on g > 0 and the merit
        ratio = math.inf
        for j in range(R):
            lj, gj = lam[b, j], g[b, j]
            dl = mf[b, j] * (m - lj * gj - lj * (Ad[j] + 2 * al[b, j] * p)) * ig[j]
            dlam[j] = dl
            ratio = min(ratio, lj / -dl if dl < 0 else math.inf)
        step = min(1.0, 0.995 * ratio)
        tiny = st[_MERIT_ROUNDOFF] * max(1.0, abs(merit0))
        found = False
        for _ in range(40):
            quad = 2 * step * p + step * step * qq
            bad = False
            for j in range(R):
                gt[j] = g[b, j] + step * Ad[j] + al[b, j] * quad
                bad |= not gt[j] > 0.005 * g[b, j]
            if not bad:
                mt = 0.0
                for k in range(n):
                    yt[k] = yl[b, k] + step * dy[k]
                    mt += 0.5 * (yt[k] * q[k] * yt[k]) + c[b, k] * yt[k]
                mt -= m * _sum_log(gt)
                if mt <= merit0 + st[_ARMIJO] * step * slope + tiny:
                    found = True
                    break
            step *= 0.5
        if found:
            for k in range(n):
                yt[k] = yl[b, k] + step * dy[k]
            # the rows again, from scratch: rounding can put a row a hair from its boundary
            # onto it, and then there is no step
            _rows_at(b, a, G, al, e, yt, gt)
            for j in range(R):
                if gt[j] <= 0:
                    found = False
        if not found:
            step = 0.0
        stuck[b] = step == 0
        if step != 0:
            for k in range(n):
                yl[b, k] = yt[k]
            for j in range(R):
                g[b, j] = gt[j]
        for j in range(R):
            lam[b, j] = max(lam[b, j] + step * dlam[j], st[_MULTIPLIER_FLOOR] * mf[b, j])


# --------------------------------------------------------------------------- row helpers
@njit(cache=True, fastmath=FAST)
def _rows_at(b, a, G, al, e, y, out):
    """Row values ``a + A.y + alpha (y.e y)`` of problem ``b`` at ``y`` ((n,) float) into
    ``out`` ((R,) float)."""
    _, n, R = G.shape
    yey = 0.0
    for k in range(n):
        yey += y[k] * e[k] * y[k]
    _rows_times(b, G, y, out)
    for j in range(R):
        out[j] = a[b, j] + out[j] + al[b, j] * yey


@njit(cache=True, fastmath=FAST)
def _rows_times(b, G, y, out):
    """``A.y`` of problem ``b`` (``G[b]`` is ``A`` transposed, (n, R)) at ``y`` ((n,) float)
    into ``out`` ((R,) float)."""
    _, n, R = G.shape
    for j in range(R):
        out[j] = 0.0
    for k in range(n):
        yk = y[k]
        for j in range(R):
            out[j] += G[b, k, j] * yk


@njit(cache=True, fastmath=FAST)
def _sum_log(x):
    """``sum(log(x))`` of positive (R,) float ``x``, with a logarithm per 8 values (of their
    product, when all 8 are within 1e-30 .. 1e30; else one each)."""
    R = x.shape[0]
    acc = 0.0
    j = 0
    while j + 8 <= R:
        lo = x[j]
        hi = x[j]
        prod = 1.0
        for i in range(j, j + 8):
            lo = min(lo, x[i])
            hi = max(hi, x[i])
            prod *= x[i]
        if lo > 1e-30 and hi < 1e30:
            acc += math.log(prod)
        else:
            for i in range(j, j + 8):
                acc += math.log(x[i])
        j += 8
    while j < R:
        acc += math.log(x[j])
        j += 1
    return acc


# --------------------------------------------------------------------------- small matrices
@njit(cache=True)
def _shift_or_reset(H, rhs, W, hessian_floor):
    """Shift ``H`` ((n, n) symmetric) to positive definite, its smallest eigenvalue at least
    ``hessian_floor`` times its largest diagonal entry (or 1); a non-finite system becomes
    ``I x = 0``. ``W`` is scratch."""
    n = H.shape[0]
    finite = True
    for k in range(n):
        finite = finite and math.isfinite(rhs[k])
        for m in range(n):
            finite = finite and math.isfinite(H[k, m])
    if not finite:  # cannot happen with g > 0; never let one problem stop the batch
        for k in range(n):
            rhs[k] = 0.0
            for m in range(n):
                H[k, m] = 1.0 if k == m else 0.0
        return
    floor = 0.0
    for k in range(n):
        floor = max(floor, abs(H[k, k]))
    floor = hessian_floor * max(1.0, floor)
    if _positive_definite(H, floor, W):  # the usual case: no shift, no eigenvalue needed
        return
    shift = max(floor - _smallest_eigenvalue(H, W), 0.0)
    for k in range(n):
        H[k, k] += shift


@njit(cache=True)
def _positive_definite(H, floor, W):
    """Whether ``H - floor I`` ((n, n) symmetric) has a Cholesky factor (into ``W``)."""
    n = H.shape[0]
    for k in range(n):
        for m in range(k + 1):
            s = H[k, m] - (floor if k == m else 0.0)
            for i in range(m):
                s -= W[k, i] * W[m, i]
            if k == m:
                if not s > 0:
                    return False
                W[k, k] = math.sqrt(s)
            else:
                W[k, m] = s / W[m, m]
    return True


@njit(cache=True)
def _smallest_eigenvalue(H, W):
    """Smallest eigenvalue of the symmetric matrix ``H`` ((n, n), n small) by cyclic Jacobi
    rotations on the copy ``W`` (scratch, (n, n))."""
    n = H.shape[0]
    total = 0.0
    for k in range(n):
        for m in range(n):
            W[k, m] = H[k, m]
            total += H[k, m] * H[k, m]
    for _ in range(50):
        off = 0.0
        for k in range(n):
            for m in range(k + 1, n):
                off += W[k, m] * W[k, m]
        if off <= 1e-30 * total:  # (rounding leaves about 1e-32)
            break
        for k in range(n - 1):
            for m in range(k + 1, n):
                apq = W[k, m]
                if apq == 0.0:
                    continue
                theta = (W[m, m] - W[k, k]) / (2.0 * apq)
                t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                if theta < 0:
                    t = -t
                cs = 1.0 / math.sqrt(t * t + 1.0)
                sn = t * cs
                for i in range(n):  # columns k, m
                    wik, wim = W[i, k], W[i, m]
                    W[i, k] = cs * wik - sn * wim
                    W[i, m] = sn * wik + cs * wim
                for i in range(n):  # rows k, m
                    wki, wmi = W[k, i], W[m, i]
                    W[k, i] = cs * wki - sn * wmi
                    W[m, i] = sn * wki + cs * wmi
                W[k, m] = 0.0
                W[m, k] = 0.0
    low = W[0, 0]
    for k in range(1, n):
        low = min(low, W[k, k])
    return low


@njit(cache=True)
def _solve(H, r, x, W):
    """``x = H^-1 r`` by Gaussian elimination with partial pivoting (LAPACK ``gesv``'s method)
    on the copy ``W``; least squares when ``H`` is exactly singular."""
    n = H.shape[0]
    for k in range(n):
        x[k] = r[k]
        for m in range(n):
            W[k, m] = H[k, m]
    for k in range(n):
        piv = k
        for i in range(k + 1, n):
            if abs(W[i, k]) > abs(W[piv, k]):
                piv = i
        if W[piv, k] == 0.0:
            sol = np.linalg.lstsq(H.copy(), r.copy())[0]
            for i in range(n):
                x[i] = sol[i]
            return
        if piv != k:
            for m in range(n):
                W[k, m], W[piv, m] = W[piv, m], W[k, m]
            x[k], x[piv] = x[piv], x[k]
        for i in range(k + 1, n):
            f = W[i, k] / W[k, k]
            for m in range(k + 1, n):
                W[i, m] -= f * W[k, m]
            x[i] -= f * x[k]
    for k in range(n - 1, -1, -1):
        s = x[k]
        for m in range(k + 1, n):
            s -= W[k, m] * x[m]
        x[k] = s / W[k, k]
