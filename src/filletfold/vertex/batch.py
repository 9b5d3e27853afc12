"""Batched apex solver: a primal-dual interior-point method over many vertices at once.

Every apex problem of sec. 3.2 (see :mod:`filletfold.vertex.apex`) has the same shape: a few
variables ``x`` (the spatial apex ``V``, and the developed apex ``v`` of a closed
development), the objective ``|x - P|^2`` and constraint rows that are all of the form ::

    g_j(x) = a_j + A_j . x + alpha_j (|v|^2 - |V|^2) >= 0

(linear rows have ``alpha_j = 0``; the crease-length rows of eq. (1) are quadratic with an
identity Hessian up to sign because the charts are rigid). The solver stacks the problems of
many vertices into padded arrays and runs one primal-dual interior-point iteration for all of
them in lockstep (numpy, no Python loop over vertices; or compiled by numba when installed,
see :data:`USE_KERNEL`):

* **phase 1** (only for targets that violate a row and starts that do too): maximise ``t``
  subject to ``g_j(x) >= t`` and ``t <= t_cap``, from the best start, until ``t > 0``; the
  reverse-convex rows (``l <= l_max``) can stall it, so the remaining starts are tried next
  (and, in a thorough solve, linear programmes on the linearised rows: :func:`phase1_lp`);
* **phase 2**: from the strictly feasible point, the closest point to ``P``, to a mean
  complementarity of ``1e-12`` (relative to the squared length scale).

The Newton matrix is ``diag(q - 2 (sum_j lambda_j alpha_j) e) + sum_j (lambda_j / g_j)
grad g_j grad g_j^T``, shifted to positive definite where the reverse-convex rows make it
indefinite. Steps keep ``g > 0`` and ``lambda > 0`` and decrease the barrier merit function.
"""

from __future__ import annotations

import importlib.util
import os
import threading
import warnings
from collections.abc import Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import FilletfoldError
from . import settings
from .apex import ApexConstraints, ApexSolution
from .reference import project_slsqp
from .rows import RowBlock, matvec, pack, pack_problems, row_values
from .settings import (
    ARMIJO,
    CHUNK,
    GIVE_UP_SLACK,
    HESSIAN_FLOOR,
    IPM_TOL,
    KKT_ACTIVE,
    KKT_TOL,
    LP_RADIUS,
    LP_ROUNDS,
    LP_STALL,
    MERIT_ROUNDOFF,
    MULTIPLIER_FLOOR,
    MULTIPLIER_START_FLOOR,
    PARALLEL_STARTS,
    PRIMAL_WEIGHT_MU,
    PROJECTION_TOL,
    PROX,
    ROW_BUDGET,
    STAT_TOL,
    T_CAP,
)

#: Run the interior-point method through the numba kernel (:mod:`.batch_kernel`, 3-6x
#: faster) when numba is installed; ``FILLETFOLD_NUMBA=0`` turns it off. Its first use ever
#: compiles it (about 15 s, once: the result is cached on disk; ``make install`` does it) and
#: every process pays about 0.5-1 s to load it. It solves every batch of at least
#: :data:`KERNEL_MIN_PROBLEMS` problems (1: all of them, so the app's small examples get it
#: too: blob's slider change 1.2 s -> 0.33 s of compute). Which path solves a batch depends on
#: the batch's size alone, never on what the process solved before, so a design gives the same
#: bytes first or last in a long process, in the CLI, the API and the app (the two paths agree
#: only to rounding). numba itself is imported and the kernel loaded on the first batch it
#: solves, not with filletfold nor before the apex stage: a design whose every vertex is at
#: its target (the icosahedron, the cube) never loads it (its CLI run: 1.26 -> 0.85 s wall).
USE_KERNEL = (
    importlib.util.find_spec("numba") is not None and os.environ.get("FILLETFOLD_NUMBA", "1") != "0"
)
KERNEL_MIN_PROBLEMS = 1


def interior_point(rows: RowBlock, q, c, y, **kwargs) -> tuple[np.ndarray, np.ndarray]:
    """:func:`interior_point_numpy`, or its compiled twin
    :func:`~filletfold.vertex.batch_kernel.interior_point_numba` when :data:`USE_KERNEL` and
    the batch has at least :data:`KERNEL_MIN_PROBLEMS` problems (its size alone decides)."""
    if USE_KERNEL and len(rows.a) >= KERNEL_MIN_PROBLEMS:
        return _kernel(rows, q, c, y, **kwargs)
    return interior_point_numpy(rows, q, c, y, **kwargs)


#: The progress stage shown while the numba kernel loads from numba's cache (about 0.3-1 s).
KERNEL_STAGE = "loading the compiled solver"
#: The progress stage shown instead when numba's cache has no kernel: its first use compiles it.
KERNEL_COMPILE_STAGE = "compiling the solver (first use only, about 15 s)"

_kernel_loaded = False
_load_lock = threading.Lock()
#: ``progress(stage, done, total)`` callbacks of the apex stages running now
#: (:func:`loading_shown`): told when the kernel loads (or compiles) during one of them.
_watchers: list = []


@contextmanager
def loading_shown(progress):
    """While in the block, a first load of the kernel (in any thread) is reported to
    ``progress`` as the stage :data:`KERNEL_STAGE` (or :data:`KERNEL_COMPILE_STAGE` when
    numba's cache has no kernel), 0/1 then 1/1."""
    if progress is None:
        yield
        return
    _watchers.append(progress)  # not under _load_lock: a load in progress does not hold it up
    try:
        yield
    finally:
        _watchers.remove(progress)


def _kernel(rows: RowBlock, q, c, y, **kwargs):
    """:func:`~filletfold.vertex.batch_kernel.interior_point_numba`, loaded first
    (:func:`warm_kernel`); numpy solves when it cannot be loaded."""
    if not (_kernel_loaded or warm_kernel()):
        return interior_point_numpy(rows, q, c, y, **kwargs)
    from . import batch_kernel

    return batch_kernel.interior_point_numba(rows, q, c, y, **kwargs)


def _turn_kernel_off(why: str) -> None:
    """Stop using the numba kernel, and say why (once)."""
    global USE_KERNEL
    USE_KERNEL = False
    warnings.warn(
        f"filletfold: the compiled solver is off ({why.splitlines()[0]}); solving with numpy "
        "(set FILLETFOLD_NUMBA=0 to skip the attempt)",
        RuntimeWarning,
        stacklevel=3,
    )


def kernel_cached() -> bool:
    """Whether numba's on-disk cache holds a compiled kernel (its index file for the kernel's
    entry point, in one of the places numba caches to: ``NUMBA_CACHE_DIR``, beside the source,
    or the user's cache folder when the source's is read-only): then loading it takes about
    0.3-1 s; without it the first use compiles it (about 15 s). An index older than the
    kernel's source does not count: numba compiles again when the source changed (a
    checkout, an upgrade), and rewrites the index then. Looked up without importing numba."""
    spec = importlib.util.find_spec(f"{__package__}.batch_kernel")
    if spec is None or spec.origin is None:
        return False
    try:
        changed = Path(spec.origin).stat().st_mtime
    except OSError:
        return False
    pattern = "batch_kernel._kernel-*.nbi"
    user = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    places = [Path(spec.origin).parent / "__pycache__", Path(user) / "numba"]
    if os.environ.get("NUMBA_CACHE_DIR"):
        places.insert(0, Path(os.environ["NUMBA_CACHE_DIR"]))
    return any(
        index.stat().st_mtime >= changed
        for place in places
        if place.is_dir()
        for index in place.rglob(pattern)
    )


def warm_kernel() -> bool:
    """Load (or compile, the first time ever: about 15 s) the numba kernel now, e.g. in a
    background thread of the app; otherwise the first batch it solves does. Once: a thread
    that comes while another loads it waits. A first load is reported to the ``progress`` of
    :func:`loading_shown`. (Which batches it solves does not change: see :data:`USE_KERNEL`.)

    When numba cannot be imported or cannot compile the kernel (e.g. a numba too old for the
    installed numpy), the kernel is turned off with a warning and numpy solves.

    Returns
    -------
    bool
        Whether the kernel is in use (False without numba, with ``FILLETFOLD_NUMBA=0``, or
        when it could not be loaded).
    """
    global _kernel_loaded
    with _load_lock:
        if USE_KERNEL and not _kernel_loaded:
            watchers = list(_watchers)
            stage = KERNEL_STAGE if not watchers or kernel_cached() else KERNEL_COMPILE_STAGE
            for progress in watchers:
                progress(stage, 0, 1)
            try:
                from . import batch_kernel

                if not batch_kernel.AVAILABLE:
                    raise ImportError("numba cannot be imported")
                rows = pack([(np.ones(2), np.eye(2, 3), np.zeros(2))], 3)
                batch_kernel.interior_point_numba(
                    rows, np.full(3, 2.0), np.ones((1, 3)), np.zeros((1, 3))
                )
            except FilletfoldError:  # the user's error (e.g. FILLETFOLD_THREADS), not numba's
                raise
            except Exception as exc:  # only the first call (import and compile) is guarded
                _turn_kernel_off(f"{type(exc).__name__}: {exc}")
            else:
                _kernel_loaded = True
            for progress in watchers:
                progress(stage, 1, 1)
    return USE_KERNEL and _kernel_loaded


def interior_point_numpy(
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

    Parameters
    ----------
    rows : RowBlock
    q : (n,) float
        Diagonal of the objective's Hessian.
    c : (B, n) float
        Linear term of the objective.
    y : (B, n) float
        Strictly feasible starting points.
    stop_slack : int, optional
        Index of a variable (phase 1's ``t``): a problem is done once it exceeds
        ``T_CAP / 2`` or is positive and at least the duality gap (within a factor 2 of the
        largest).
    groups : (B,) int, optional
        With ``stop_slack``: problems with the same group are copies from different starts;
        all are done when one reaches ``T_CAP / 2``.
    give_up : bool
        With ``stop_slack``: also stop once ``t`` plus the duality gap is negative (a proof of
        infeasibility for a convex problem; only a hint for this one, whose ``l <= l_max``
        rows are reverse-convex).
    max_iter : int
    tol : float
        Mean complementarity ``lambda g`` at which a problem is done (with stationarity
        :data:`STAT_TOL`).

    Returns
    -------
    y : (B, n) float
        Final points (strictly feasible).
    converged : (B,) bool
    """
    y = y.copy()
    B, _, n = rows.A.shape
    e = rows.e
    diag_idx = np.arange(n)
    converged = np.zeros(B, dtype=bool)
    live = np.arange(B)
    a, A, al, mf, cl = rows.a, rows.A, rows.alpha, rows.mask.astype(float), c
    outer = (A[:, :, :, None] * A[:, :, None, :]).reshape(B, -1, n * n)
    count = mf.sum(axis=1)
    yl = y
    g = row_values(a, A, al, e, yl)
    # phase 1: multipliers that balance the objective's gradient, spread over the rows;
    # phase 2: a barrier-like start, larger on the rows close to their boundary
    scale = np.maximum(MULTIPLIER_START_FLOOR, np.abs(yl * q + cl).max(axis=1))
    lam = mf * (scale / count)[:, None] if stop_slack is not None else mf * scale[:, None] / g
    stuck = np.zeros(B, dtype=bool)
    mu = 0.1 * (lam * g).sum(axis=1) / count
    for _ in range(max_iter):
        ey = e * yl
        lam_al = (lam * al).sum(axis=1)
        grad_f = yl * q + cl
        lam_A = _vecmat(lam, A)
        # stationarity, relative to the size of the terms that cancel in it
        size = 1.0 + np.abs(grad_f).max(axis=1) + np.abs(lam_A).max(axis=1)
        stat = (grad_f - lam_A - 2 * lam_al[:, None] * ey) / size[:, None]
        comp = (lam * g).sum(axis=1)
        # monotone barrier: lower mu once the iterate is close to its central-path point
        central = np.maximum(np.abs(stat).max(axis=1), np.abs(mf * (lam * g - mu[:, None])).max(1))
        near = (central <= 10 * mu) | (central <= STAT_TOL)  # (stationarity ends at rounding)
        mu = np.where(near, np.maximum(0.1 * tol, 0.2 * mu), mu)
        done = (np.abs(stat).max(axis=1) <= STAT_TOL) & (comp / count <= tol)
        if stop_slack is not None:
            t = yl[:, stop_slack]
            reached = (t >= 0.5 * T_CAP) | ((t > 0) & (comp <= t))
            if groups is not None and reached.any():
                reached = np.isin(groups[live], groups[live[reached]])
            done |= reached
            if give_up:
                done |= t + comp < -GIVE_UP_SLACK
        new = done & ~converged[live]
        y[live[new]], converged[live[new]] = yl[new], True
        done |= stuck  # no step possible: keep the point (not converged)
        if done.all():
            rest = ~converged[live]
            y[live[rest]] = yl[rest]
            return y, converged
        if done.sum() * 4 >= len(live):  # drop finished problems once a quarter is done
            k = ~done
            gone = done & ~converged[live]
            y[live[gone]] = yl[gone]
            live, a, A, al, mf, cl, outer, count, yl, g, lam, stuck = (
                live[k], a[k], A[k], al[k], mf[k], cl[k], outer[k], count[k], yl[k], g[k],
                lam[k], stuck[k],
            )  # fmt: skip
            ey, mu = ey[k], mu[k]
        # Newton matrix: sum_j w_j grad g_j grad g_j^T (grad g_j = A_j + 2 alpha_j e*y) + diag
        # curvature weights: lambda, or the primal mu / g where lambda lags behind (rows that
        # just became nearly active would otherwise be crossed by every step)
        # (late on, the exact lambda again, for fast local convergence)
        primal = (mu > PRIMAL_WEIGHT_MU)[:, None]
        lam_h = np.where(primal, np.maximum(lam, mf * mu[:, None] / g), lam)
        w = lam_h / g
        wa = w * al
        u = _vecmat(wa, A)
        H = _vecmat(w, outer).reshape(-1, n, n)
        H += 2 * (u[:, :, None] * ey[:, None, :] + ey[:, :, None] * u[:, None, :])
        H += 4 * (wa * al).sum(axis=1)[:, None, None] * ey[:, :, None] * ey[:, None, :]
        H[:, diag_idx, diag_idx] += q - 2 * (lam_h * al).sum(axis=1)[:, None] * e
        # the reverse-convex rows make H indefinite at times: shift it to positive definite
        low = np.linalg.eigvalsh(H)[:, 0]
        floor = HESSIAN_FLOOR * np.maximum(1.0, np.abs(H[:, diag_idx, diag_idx]).max(axis=1))
        H[:, diag_idx, diag_idx] += np.maximum(floor - low, 0.0)[:, None]
        v = mu[:, None] / g
        rhs = -(yl * q + cl) + _vecmat(v, A) + 2 * (v * al).sum(axis=1)[:, None] * ey
        bad = ~(np.isfinite(H).all(axis=(1, 2)) & np.isfinite(rhs).all(axis=1))
        if bad.any():  # cannot happen with g > 0; never let one problem stop the batch
            H[bad], rhs[bad] = np.eye(n), 0.0
        dy = _solve_small(H, rhs)
        Ad = matvec(A, dy)
        p = (ey * dy).sum(axis=1)
        qq = (dy * e * dy).sum(axis=1)
        dlam = mf * (mu[:, None] - lam * g - lam * (Ad + 2 * al * p[:, None])) / g
        # fraction to the boundary for lambda, then backtracking on g > 0 and the merit
        ratio = np.where(dlam < 0, lam / np.where(dlam < 0, -dlam, 1.0), np.inf)
        step = np.minimum(1.0, 0.995 * ratio.min(axis=1))
        merit0 = 0.5 * (yl * q * yl).sum(axis=1) + (cl * yl).sum(axis=1)
        merit0 -= mu * np.log(g).sum(axis=1)
        slope = np.minimum(-(rhs * dy).sum(axis=1), 0.0)
        todo = np.arange(len(yl))
        for _ in range(40):
            s_ = step[todo]
            gt = g[todo] + s_[:, None] * Ad[todo]
            gt += al[todo] * (2 * s_ * p[todo] + s_ * s_ * qq[todo])[:, None]
            ok = np.all(gt > 0.005 * g[todo], axis=1)
            yt = yl[todo] + s_[:, None] * dy[todo]
            mt = 0.5 * (yt * q * yt).sum(axis=1) + (cl[todo] * yt).sum(axis=1)
            mt -= mu[todo] * np.log(np.where(ok[:, None], gt, 1.0)).sum(axis=1)
            bound = merit0[todo] + ARMIJO * s_ * slope[todo]
            ok &= mt <= bound + MERIT_ROUNDOFF * np.maximum(1.0, np.abs(merit0[todo]))
            todo = todo[~ok]
            if len(todo) == 0:
                break
            step[todo] *= 0.5
        step[todo] = 0.0
        y_new = yl + step[:, None] * dy
        g_new = row_values(a, A, al, e, y_new)
        # rounding can put a row a hair from its boundary onto it: no step then
        step[np.any(g_new <= 0, axis=1)] = 0.0
        stuck = step == 0
        yl = np.where(stuck[:, None], yl, y_new)
        g = np.where(stuck[:, None], g, g_new)
        lam = np.maximum(lam + step[:, None] * dlam, MULTIPLIER_FLOOR * mf)
    rest = ~converged[live]
    y[live[rest]] = yl[rest]
    return y, converged


def _solve_small(H: np.ndarray, r: np.ndarray) -> np.ndarray:
    """(B, n) solutions of ``H x = r``; least squares for the (rare) singular ``H``."""
    try:
        return np.linalg.solve(H, r[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.stack([np.linalg.lstsq(h, b, rcond=None)[0] for h, b in zip(H, r, strict=True)])


def _vecmat(x: np.ndarray, A: np.ndarray) -> np.ndarray:
    """(B, k) products of (B, R) row vectors with (B, R, k) matrices."""
    return np.matmul(x[:, None, :], A)[:, 0, :]


def _phase1(
    rows: RowBlock, y0: np.ndarray, groups: np.ndarray, max_iter: int, give_up: bool = True
) -> np.ndarray:
    """(B, n) points of larger smallest slack, maximised from ``y0`` (see :func:`interior_point`
    for ``groups``)."""
    B, R, n = rows.A.shape
    g0 = rows.min_slack(y0)
    t0 = g0 - np.maximum(0.1, 0.1 * np.abs(g0))
    # rows g - t >= 0, plus the cap T_CAP - t >= 0
    a = np.concatenate([rows.a, np.full((B, 1), T_CAP)], axis=1)
    A = np.zeros((B, R + 1, n + 1))
    A[:, :R, :n] = rows.A
    A[:, :R, n] = np.where(rows.mask, -1.0, 0.0)
    A[:, R, n] = -1.0
    alpha = np.concatenate([rows.alpha, np.zeros((B, 1))], axis=1)
    mask = np.concatenate([rows.mask, np.ones((B, 1), dtype=bool)], axis=1)
    ext = RowBlock(a, A, alpha, np.append(rows.e, 0.0), mask)
    q = np.append(np.full(n, PROX), 0.0)
    c = np.concatenate([-PROX * y0, -np.ones((B, 1))], axis=1)
    z, _ = interior_point(
        ext, q, c, np.concatenate([y0, t0[:, None]], axis=1), stop_slack=n, groups=groups,
        give_up=give_up, max_iter=max_iter,
    )  # fmt: skip
    return z[:, :n]


def phase1_lp(rows: RowBlock, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Larger smallest slacks of problems by sequential linear programming from ``y``.

    Each round maximises, per problem, ``s`` subject to ``g_j(y) + grad g_j(y) . d >= s`` on
    its real rows and ``|d|_inf <= delta`` (a linear programme), takes the step when the
    smallest slack grows and adjusts the problem's trust region ``delta`` by how much of the
    predicted gain was realised. A problem stops at a positive slack, after
    :data:`LP_ROUNDS` programmes, or once a programme predicts less than :data:`LP_STALL`
    (a local maximum). The problems of a round are one programme for HiGHS, block by block
    (they share no variable, so each block's optimum is its problem's): one call per round
    instead of one per problem and round.

    The interior-point phase 1 can stall short of a thin feasible window that one such step
    reaches (the reverse-convex ``l <= l_max`` rows, many rows nearly active at once); this is
    what the thorough solve tries before calling a problem infeasible.

    Parameters
    ----------
    rows : RowBlock
        ``B`` problems.
    y : (B, n) float

    Returns
    -------
    y : (B, n) float
        The best point found per problem.
    t : (B,) float
        Its smallest slack.
    """
    from scipy.optimize import linprog  # 0.1-0.3 s to import: only when needed
    from scipy.sparse import csr_array

    y = np.array(y, dtype=float, ndmin=2)
    n_prob, n = y.shape
    e = rows.e
    g = np.where(rows.mask, rows.values(y), np.inf)
    t = g.min(axis=1)
    delta = np.full(n_prob, LP_RADIUS)
    live = t <= 0
    for _ in range(LP_ROUNDS):
        idx = np.flatnonzero(live)
        if not len(idx):
            break
        k = len(idx)
        J = rows.A[idx] + 2 * rows.alpha[idx][:, :, None] * (e * y[idx])[:, None, :]
        bi, ri = np.nonzero(rows.mask[idx])  # the real rows, problem after problem
        m = len(bi)
        A_ub = csr_array(
            (
                np.concatenate([-J[bi, ri].ravel(), np.ones(m)]),
                (
                    np.concatenate([np.repeat(np.arange(m), n), np.arange(m)]),
                    np.concatenate(
                        [(bi[:, None] * (n + 1) + np.arange(n)).ravel(), bi * (n + 1) + n]
                    ),
                ),
            ),
            shape=(m, k * (n + 1)),
        )
        bounds = np.full((k, n + 1, 2), np.inf)
        bounds[..., 0] = -np.inf
        bounds[:, :n, 0] = -delta[idx, None]
        bounds[:, :n, 1] = delta[idx, None]
        cost = np.zeros((k, n + 1))
        cost[:, n] = -1.0
        lp = linprog(
            cost.ravel(), A_ub=A_ub, b_ub=g[idx][bi, ri], bounds=bounds.reshape(-1, 2),
            method="highs",
        )  # fmt: skip
        if lp.x is None:
            break
        X = lp.x.reshape(k, n + 1)
        gain = X[:, n] - t[idx]
        go = gain > LP_STALL
        y_new = y[idx] + X[:, :n]
        g_new = np.where(rows.mask[idx], rows.take(idx).values(y_new), np.inf)
        t_new = g_new.min(axis=1)
        better = go & (t_new > t[idx])
        delta[idx[better & (t_new - t[idx] > 0.5 * gain)]] *= 2
        delta[idx[go & ~better]] *= 0.25
        up = idx[better]
        y[up], g[up], t[up] = y_new[better], g_new[better], t_new[better]
        live[idx[~go]] = False
        live &= t <= 0
    return y, t


@dataclass
class ApexWork:
    """What the apex solver did for one design, in counts (seconds depend on the machine,
    these do not): a solve that grows one of them shows in a test before anyone times it.

    Passed to :func:`solve_apex_batch` (and through
    :func:`~filletfold.vertex.solve.solve_apices`), which add to it; safe to share between
    threads. The design reports it as ``fitting.apex_work``.

    Attributes
    ----------
    problems : int
        Apex problems solved: one per vertex and attempt (a vertex solved again after a
        change of radii counts again).
    phase1 : int
        Interior-point feasibility (phase-1) runs, every start and fallback counted.
    programmes : int
        Block linear programmes run (:func:`phase1_lp`, one per chunk that needed them).
    """

    problems: int = 0
    phase1: int = 0
    programmes: int = 0
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False, compare=False)

    def add(self, problems: int = 0, phase1: int = 0, programmes: int = 0) -> None:
        with self._lock:
            self.problems += int(problems)
            self.phase1 += int(phase1)
            self.programmes += int(programmes)

    def as_dict(self) -> dict:
        """``{"problems": .., "phase1_runs": .., "programmes": ..}`` (the report's keys)."""
        return {
            "problems": self.problems,
            "phase1_runs": self.phase1,
            "programmes": self.programmes,
        }


def solve_apex_batch(
    problems: Sequence[ApexConstraints],
    targets: Sequence[np.ndarray],
    starts: Sequence[Sequence[np.ndarray]] | None = None,
    *,
    thorough=True,
    lp: bool = True,
    max_iter: int = 80,
    work: ApexWork | None = None,
) -> list[ApexSolution]:
    """Project every target onto its problem's feasible set, all problems at once.

    Parameters
    ----------
    problems : sequence of ApexConstraints
        One per vertex; 3 variables (open development) and 5 (closed) may be mixed.
    targets : sequence of (3,) or (5,) float
        ``P = U + d D`` (followed by the developed apex's target for 5 variables).
    starts : sequence of (k, 3) or (k, 5) float, optional
        Further starting points per problem for the feasibility phase (arrays, or sequences
        of points).
    thorough : bool or sequence of bool
        Per problem (or for all): before calling a problem infeasible, try every start,
        continue the feasibility phase from the best point by linear programmes
        (:func:`phase1_lp`), then without the give-up rule. (The reference SLSQP solver,
        :func:`~filletfold.vertex.reference.solve_apex_slsqp`, is not tried after them: from
        the best point, the target and two starts it made 1 of 2,616 such problems feasible
        on two public meshes of 2,903 and 6,475 vertices, at a third of the apex stage's
        time.) Without it only the
        :data:`PARALLEL_STARTS` best starts are tried and a problem is given up once it looks
        infeasible (after one more run from its best point): for attempts that have a more
        permissive one after them. Only the fallbacks named in
        :data:`~filletfold.vertex.settings.FALLBACKS` are tried; each solution's ``solver``
        names the one that found its feasible point.
    lp : bool
        Whether a thorough solve tries the fallbacks that a rescue would redo with smaller
        radii: phase 1 from every other start (``starts``) and the linear programmes
        (:func:`phase1_lp`). On a 2,904-vertex scan the programmes made 3 of 590 problems of
        the first solve feasible in 2.0 s (the vertex rescue then finds those with smaller
        radii), and 126 of 236 of the rescue's last factors in 0.6 s; the other starts found
        no cone more there, for a quarter of its phase-1 runs: the design skips both where a
        rescue follows.
    max_iter : int
        Interior-point iterations per phase.
    work : ApexWork, optional
        Adds the problems, phase-1 runs and linear programmes solved here.

    Returns
    -------
    list of ApexSolution
        In the order of ``problems``; ``ok`` is False when no start reached a feasible point,
        and ``failing`` then names the violated constraints at the best point found.
    """
    out: list[ApexSolution | None] = [None] * len(problems)
    work = ApexWork() if work is None else work
    work.add(problems=len(problems))
    thorough = np.broadcast_to(np.asarray(thorough, dtype=bool), (len(problems),))
    sizes = np.array([len(p.lin_b) + len(p.quad_s) for p in problems])
    for n in (3, 5):
        idx = [i for i in np.argsort(sizes, kind="stable") if problems[i].n_vars == n]
        # chunks of similar row counts, within the row budget
        while idx:
            k = max(1, min(len(idx), ROW_BUDGET // int(sizes[idx[min(len(idx), CHUNK) - 1]])))
            k = min(k, CHUNK)
            chunk, idx = idx[:k], idx[k:]
            sols = _solve_chunk(
                [problems[i] for i in chunk],
                [np.asarray(targets[i], dtype=float) for i in chunk],
                [
                    np.asarray(starts[i] if starts is not None else [], dtype=float).reshape(-1, n)
                    for i in chunk
                ],
                thorough[chunk],
                n,
                max_iter,
                lp,
                work,
            )
            for i, s in zip(chunk, sols, strict=True):
                out[i] = s
    return out


def kkt_point(cons: ApexConstraints, target: np.ndarray, x: np.ndarray) -> bool:
    """Whether the feasible point ``x`` is a first-order (KKT) point of the projection of
    ``target``: the objective's gradient is a nonnegative combination of the gradients of the
    rows active at ``x`` (within :data:`KKT_ACTIVE` of the scale), to :data:`KKT_TOL` of its size.

    The interior-point method can stop short of its stationarity test at a degenerate vertex
    of the feasible set (many rows active together); such a point needs no SLSQP finish.

    Parameters
    ----------
    cons : ApexConstraints
    target, x : (n,) float
    """
    from scipy.optimize import nnls  # 0.1-0.3 s to import: only when needed

    L = cons.scale
    grad = 2 * (x - target) / L
    size = np.linalg.norm(grad)
    if size == 0:
        return True
    active = cons.values(x) <= KKT_ACTIVE * L
    if not active.any():
        return False
    _, residual = nnls(cons.jacobian(x)[active].T, grad)
    return bool(residual <= KKT_TOL * size)


def solve_apex(cons: ApexConstraints, target: np.ndarray, starts=None) -> ApexSolution:
    """One problem through :func:`solve_apex_batch` (same parameters, one of each)."""
    return solve_apex_batch([cons], [target], [list(starts) if starts is not None else []])[0]


def _solve_chunk(
    problems, targets, starts, thorough, n, max_iter, lp, work: ApexWork
) -> list[ApexSolution]:
    B = len(problems)
    T = np.stack(targets)
    rows = pack_problems(problems, T, n)

    def phase1(idx: np.ndarray, y0: np.ndarray, iters: int, **kwargs) -> np.ndarray:
        """:func:`_phase1` of problems ``idx`` from ``y0``, counted in ``work``."""
        work.add(phase1=len(idx))
        return _phase1(rows.take(idx), y0, idx, iters, **kwargs)

    L = np.array([p.scale for p in problems])
    at_target = rows.min_slack(np.zeros((B, n))) >= 0
    # candidate starts in y coordinates, the target (y = 0) first
    n_starts = np.array([len(s) for s in starts])
    n_s = 1 + int(n_starts.max(initial=0))
    cand = np.zeros((B, n_s, n))
    if n_s > 1 and (n_starts == n_s - 1).all():
        cand[:, 1:] = (np.stack(starts) - T[:, None]) / L[:, None, None]
    else:
        for b, s in enumerate(starts):
            cand[b, 1 : 1 + len(s)] = (s - T[b]) / L[b]
    valid = np.arange(n_s) <= n_starts[:, None]
    gmin = np.stack([rows.min_slack(cand[:, j]) for j in range(n_s)], axis=1)
    gmin = np.where(valid, gmin, -np.inf)
    order = np.argsort(-gmin, axis=1)
    ar = np.arange(B)
    # the best point per problem so far (a start that is already strictly feasible skips
    # phase 1); phase 2 starts from it once its smallest slack is positive
    best = cand[ar, order[:, 0]]
    best_g = gmin[ar, order[:, 0]]
    need = ~at_target
    fallbacks = settings.FALLBACKS
    # the fallback that made each problem feasible ("": its best start, or phase 1 from it);
    # each step below runs only on problems not feasible yet, so none is overwritten
    found = np.full(B, "", dtype=object)

    def keep_best(idx: np.ndarray, y: np.ndarray, step: str) -> None:
        """Take the phase-1 points ``y`` of problems ``idx`` (repeats allowed) that beat
        their problem's best point; note ``step`` for those it makes feasible."""
        g_y = rows.take(idx).min_slack(y)
        for k in np.argsort(g_y):  # ascending: the best point per problem wins
            if g_y[k] > best_g[idx[k]]:
                best[idx[k]], best_g[idx[k]] = y[k], g_y[k]
        found[idx[g_y > 0]] = step

    # phase 1 from the PARALLEL_STARTS best starts first, then from the others
    for lo, hi in ((0, PARALLEL_STARTS), (PARALLEL_STARTS, n_s)):
        if lo and not (lp and "starts" in fallbacks):  # a rescue follows: it redoes them
            break
        feasible = need & (best_g > 0)
        todo_b, todo_j = [np.zeros(0, dtype=int)], [np.zeros(0, dtype=int)]
        for j in range(lo, min(hi, n_s)):
            b = np.nonzero(need & ~feasible & valid[ar, order[:, j]] & (thorough | (lo == 0)))[0]
            todo_b.append(b)
            todo_j.append(order[b, j])
        todo_b, todo_j = np.concatenate(todo_b), np.concatenate(todo_j)
        if len(todo_b) == 0:
            continue
        step = "starts" if lo else ""
        keep_best(todo_b, phase1(todo_b, cand[todo_b, todo_j], max_iter), step)
    # a quick solve gives up early: once more from the best point (fresh multipliers)
    again = np.nonzero(need & (best_g <= 0) & ~thorough)[0]
    if len(again) and "again" in fallbacks:
        keep_best(again, phase1(again, best[again], max_iter), "again")
    # the interior-point phase 1 can stall short of a thin window: linear programmes next
    stalled = np.nonzero(need & (best_g <= 0) & thorough)[0]
    if len(stalled) and lp and "lp" in fallbacks:
        work.add(programmes=1)
        y_lp, t_lp = phase1_lp(rows.take(stalled), best[stalled])
        up = t_lp > best_g[stalled]
        best[stalled[up]], best_g[stalled[up]] = y_lp[up], t_lp[up]
        found[stalled[up & (t_lp > 0)]] = "lp"
    # the give-up rule is only a hint here: the rest continue from their best point, longer
    rest = np.nonzero(need & (best_g <= 0) & thorough)[0]
    if len(rest) and "long" in fallbacks:
        y_long = phase1(rest, best[rest], 3 * max_iter, give_up=False)
        keep_best(rest, y_long, "long")
    feasible = need & (best_g > 0)
    solve = np.nonzero(feasible)[0]
    y = np.zeros((B, n))
    converged = np.ones(B, dtype=bool)
    if len(solve):
        y[solve], converged[solve] = interior_point(
            rows.take(solve), np.full(n, 2.0), np.zeros((len(solve), n)), best[solve],
            max_iter=max_iter, tol=PROJECTION_TOL,
        )  # fmt: skip
    result = []
    X = T + L[:, None] * y  # the solved points (rows of feasible problems)
    for b, p in enumerate(problems):
        if at_target[b]:
            result.append(ApexSolution(True, T[b].copy(), [], True, "target"))
        elif feasible[b]:
            x, how = X[b], f"{found[b]}+ipm" if found[b] else "ipm"
            if not converged[b] and not kkt_point(p, T[b], x):
                # rare: finish with SLSQP from the feasible point
                x_s = project_slsqp(p, T[b], x)
                if np.sum((x_s - T[b]) ** 2) < np.sum((x - T[b]) ** 2):
                    x, how = x_s, how + "+slsqp"
            result.append(ApexSolution(True, x, [], False, how))
        else:
            x = T[b] + L[b] * best[b]
            vals = p.values(x)
            rows_failing = p.describe(np.nonzero(vals < 0)[0])
            result.append(ApexSolution(False, x, rows_failing, False, "ipm"))
    return result
