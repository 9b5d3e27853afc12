"""The apex stage against the obvious alternatives (issue 6's baselines, paper sec. 3.2).

    .venv/bin/python benchmarks/apex_solvers.py [--quick] [--repeat N] [--max-problems N]
                                                [--random K] [--methods a,b,...] [--seed S]
                                                [--mesh PATH ...]

Every case is turned into the per-vertex apex problems of the pipeline's first attempt
(``minimise |x - P|^2 / L^2`` subject to the sampled constraints ``g(x) >= 0`` of
:class:`~filletfold.vertex.apex.ApexConstraints`: 9 samples per arc, the safety margin), and
the same problems go to every method:

* ``slsqp-loop``: one plain scipy SLSQP call per vertex from the target ``P`` (no feasibility
  phase; ftol 1e-12, maxiter 200) - the obvious way;
* ``ipopt``: Ipopt through casadi (optional, ``pip install casadi`` or the ``bench`` extra), one
  ``nlpsol`` per vertex from ``P``, Ipopt's default options except ``bound_relax_factor 0`` (so
  ``g >= 0`` is not relaxed by 1e-8); the symbolic functions are built once per distinct
  (row count, variable count) and that setup is reported separately;
* ``reference``: the library's SLSQP solver with a feasibility phase from several starts
  (``filletfold.vertex.reference.solve_apex_slsqp``);
* ``batched``: ``filletfold.vertex.batch.solve_apex_batch``, one call for all problems of a
  case, with the numpy interior-point method;
* ``batched-numba``: the same with the compiled kernel at every batch size (needs numba: the
  ``fast`` extra; skipped without it; its one-time compilation is in the warm-up).

A vertex is *feasible* when at least one method returned a point with every row
``g >= -1e-9 L`` (``L`` = the constraints' scale, the mean incident edge length); a method
*succeeds* on it under the same test. The objective gap is ``(f - f_best) / max(f_best, 1e-12)``
with ``f = |x - P|^2 / L^2`` and ``f_best`` the best objective among the successful methods,
over the vertices the method solved (when ``P`` itself is feasible, ``f_best = 0`` and the
gap is ``f`` / 1e-12: 1e-1 means ``|x - P|`` = 3e-7 L). Times are µs per vertex, medians of
``--repeat`` runs (one warm-up call per method first), and ``ratio`` is a method's time over
the batched solver's.

Cases: the Platonic solids, ``geodesic-sphere:level=3``, ``examples/bunny-lowres.obj``
(radii clamped), and random convex polyhedra (five hulls of 30-200 points on a perturbed sphere,
radius 5-25 % of the mean edge length per polyhedron, clamped; depth 5-100 % per vertex;
seeded by ``--seed``); ``--mesh PATH`` adds a mesh file (an irregular mesh: a random hull, a
corpus mesh), radius 10 % clamped.
Radius 10 % and depth 30 % elsewhere. ``--quick``: one run, at most 40 problems per case
and two small random polyhedra.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import statistics
import sys
import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize
from scipy.spatial import ConvexHull

from filletfold.mesh import load_mesh
from filletfold.parameters import parse_length
from filletfold.rounding.edges import clamp_radii, round_edges
from filletfold.vertex.batch import solve_apex_batch
from filletfold.vertex.reference import solve_apex_slsqp
from filletfold.vertex.solve import apex_problems

sys.path.insert(0, os.path.dirname(__file__))
from examples import machine

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUNNY = os.path.join(ROOT, "examples", "bunny-lowres.obj")
FEAS_TOL = 1e-9  # rows g >= -FEAS_TOL * L count as satisfied
METHODS = ("slsqp-loop", "ipopt", "reference", "batched", "batched-numba")


# --------------------------------------------------------------------------- problems
@dataclass
class Problem:
    cons: object  # ApexConstraints
    target: np.ndarray
    starts: list
    vertex: int


def mesh_problems(mesh, radius, depth, clamp: bool) -> list[Problem]:
    """The first attempt (9 samples, the margin) of every vertex that reaches the apex stage,
    set up as in ``round_mesh`` (:func:`filletfold.vertex.solve.apex_problems`).

    ``radius``: a value for :func:`parse_length`; ``depth``: a value or an array per vertex.
    """
    pm, _ = load_mesh(mesh)
    ref = pm.mean_edge_length
    r = parse_length(radius, ref, "radius", count=pm.n_edges)
    if clamp:
        r = clamp_radii(pm, r)
    depths = np.broadcast_to(np.asarray(parse_length(depth, ref, "depth"), float), pm.n_vertices)
    return [
        Problem(p.constraints(*p.attempts[0]), np.asarray(p.target, float), list(p.starts),
                p.frame.vertex)
        for p in apex_problems(pm, round_edges(pm, r), depths)
    ]  # fmt: skip


def random_convex(rng, n_points: int):
    """Convex hull of ``n_points`` on a perturbed, stretched sphere: (vertices, faces).

    Radial noise of 5 % keeps most points on the hull; a random stretch per axis.
    """
    p = rng.normal(size=(n_points, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    p *= rng.uniform(0.95, 1.05, size=(n_points, 1)) * rng.uniform(0.7, 1.3, size=3)
    hull = ConvexHull(p)
    used = np.unique(hull.simplices)
    index = np.full(n_points, -1)
    index[used] = np.arange(len(used))
    faces = []
    for s, eq in zip(hull.simplices, hull.equations, strict=True):
        a, b, c = p[s]
        faces.append(index[s] if np.cross(b - a, c - a) @ eq[:3] > 0 else index[s[::-1]])
    return p[used], faces


def random_problems(rng, count: int, n_range: tuple[int, int]):
    probs, notes = [], []
    for _ in range(count):
        n = int(rng.integers(n_range[0], n_range[1] + 1))
        v, f = random_convex(rng, n)
        r_frac = rng.uniform(0.05, 0.25)
        d_frac = rng.uniform(0.05, 1.0, size=len(v))
        pm, _ = load_mesh((v, f))
        depth = d_frac * pm.mean_edge_length
        probs += mesh_problems((v, f), f"{100 * r_frac:.2f}%", depth, True)
        notes.append(f"{len(v)}v r{100 * r_frac:.0f}%")
    return probs, ", ".join(notes)


# --------------------------------------------------------------------------- methods
def feasible(cons, x) -> bool:
    return (
        x is not None
        and bool(np.all(np.isfinite(x)))
        and (cons.values(np.asarray(x, float)).min() >= -FEAS_TOL * cons.scale)
    )


def slsqp_one(p: Problem) -> np.ndarray:
    cons, P, L = p.cons, p.target, p.cons.scale
    r = minimize(
        lambda x: ((x - P) @ (x - P)) / L**2,
        P.copy(),
        jac=lambda x: 2 * (x - P) / L**2,
        constraints=[{"type": "ineq", "fun": cons.values, "jac": cons.jacobian}],
        method="SLSQP",
        options={"ftol": 1e-12, "maxiter": 200},
    )
    return r.x


def run_slsqp_loop(probs):
    return [slsqp_one(p) for p in probs]


class Ipopt:
    """Ipopt through casadi: one ``nlpsol`` per (row count, variable count), reused."""

    OPTS = {  # noqa: RUF012
        "ipopt.print_level": 0,
        # no relaxation of g >= 0 (Ipopt's default 1e-8 leaves rows at about -1e-8, which
        # would fail the -1e-9 L test on most vertices); tolerances otherwise Ipopt's defaults
        "ipopt.bound_relax_factor": 0.0,
        "ipopt.sb": "yes",
        "print_time": False,
        "error_on_fail": False,
    }

    def __init__(self, ca):
        self.ca = ca
        self.solvers = {}
        self.setup = 0.0

    @staticmethod
    def n_rows(cons) -> int:
        return len(cons.quad_s) + len(cons.lin_b)

    @staticmethod
    def rows(cons):
        """``g(x) = b + A x + alpha (|v|^2 - |V|^2)``: (b, A, alpha) of ``cons``."""
        n = cons.n_vars
        x0 = np.zeros(n)
        b = cons.values(x0)
        A = cons.jacobian(x0)
        alpha = np.zeros(len(b))
        alpha[: len(cons.quad_sign)] = cons.quad_sign / cons.scale
        return b, A, alpha

    def solver(self, m: int, n: int):
        key = (m, n)
        if key not in self.solvers:
            t = time.perf_counter()
            ca = self.ca
            x = ca.SX.sym("x", n)
            b = ca.SX.sym("b", m)
            A = ca.SX.sym("A", m, n)
            alpha = ca.SX.sym("alpha", m)
            P = ca.SX.sym("P", n)
            inv_l2 = ca.SX.sym("inv_l2")
            q = ca.sumsqr(x[3:]) - ca.sumsqr(x[:3]) if n > 3 else -ca.sumsqr(x[:3])
            g = b + ca.mtimes(A, x) + alpha * q
            f = inv_l2 * ca.sumsqr(x - P)
            p = ca.vertcat(b, ca.vec(A), alpha, P, inv_l2)
            self.solvers[key] = ca.nlpsol(
                f"apex_{m}_{n}", "ipopt", {"x": x, "p": p, "f": f, "g": g}, self.OPTS
            )
            self.setup += time.perf_counter() - t
        return self.solvers[key]

    def params(self, p: Problem):
        b, A, alpha = self.rows(p.cons)
        return np.concatenate([b, A.ravel(order="F"), alpha, p.target, [1.0 / p.cons.scale**2]])

    def check(self, probs, rng, n_points: int = 5) -> float:
        """Largest relative difference of the casadi rows against ``cons.values``."""
        worst = 0.0
        for p in probs:
            b, A, alpha = self.rows(p.cons)
            n = p.cons.n_vars
            for _ in range(n_points):
                x = p.target + p.cons.scale * rng.normal(size=n)
                q = -x[:3] @ x[:3] + (x[3:] @ x[3:] if n > 3 else 0.0)
                mine = b + A @ x + alpha * q
                ref = p.cons.values(x)
                worst = max(worst, float(np.abs(mine - ref).max() / (1 + np.abs(ref).max())))
        return worst

    def prepare(self, probs):
        """Build every solver needed and the parameter vectors (setup, not timed)."""
        for p in probs:
            self.solver(self.n_rows(p.cons), p.cons.n_vars)
        return [self.params(p) for p in probs]

    def run(self, probs, params):
        out = []
        for p, par in zip(probs, params, strict=True):
            S = self.solver(self.n_rows(p.cons), p.cons.n_vars)
            r = S(x0=p.target, p=par, lbg=0.0, ubg=np.inf)
            out.append(np.asarray(r["x"]).ravel())
        return out


# --------------------------------------------------------------------------- measuring
def timed(fn, repeat: int):
    """(result of the last run, median seconds) of ``repeat`` runs of ``fn()``."""
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return out, statistics.median(times)


def objective(p: Problem, x) -> float:
    d = np.asarray(x, float) - p.target
    return float(d @ d) / p.cons.scale**2


def score(probs, xs_by_method):
    """Per method: success mask, objective array (NaN where failed); feasible mask."""
    ok = {
        m: np.array([feasible(p.cons, x) for p, x in zip(probs, xs, strict=True)], bool)
        for m, xs in xs_by_method.items()
    }
    f = {
        m: np.array(
            [objective(p, x) if o else np.nan for p, x, o in zip(probs, xs, ok[m], strict=True)]
        )
        for m, xs in xs_by_method.items()
    }
    any_ok = np.zeros(len(probs), bool)
    for o in ok.values():
        any_ok |= o
    stack = np.vstack(list(f.values()))
    best = np.full(len(probs), np.nan)
    best[any_ok] = np.nanmin(stack[:, any_ok], axis=0)
    gaps = {m: (f[m] - best) / np.maximum(best, 1e-12) for m in f}
    return ok, gaps, any_ok


def fmt_gap(g) -> str:
    return f"{g:9.1e}" if np.isfinite(g) else f"{'-':>9s}"


def run_method(m: str, probs, repeat: int, solvers: dict, rng):
    """(points, median seconds) of method ``m`` on ``probs``, after one warm-up call."""
    if m == "slsqp-loop":
        run_slsqp_loop(probs[:1])
        return timed(lambda: run_slsqp_loop(probs), repeat)
    if m == "ipopt":
        ipopt = solvers["ipopt"]
        s0, k0 = ipopt.setup, len(ipopt.solvers)
        params = ipopt.prepare(probs)
        err = ipopt.check(probs[:20], rng)
        ipopt.run(probs[:1], params[:1])
        out = timed(lambda: ipopt.run(probs, params), repeat)
        print(
            f"  (ipopt: casadi setup {ipopt.setup - s0:.2f} s for "
            f"{len(ipopt.solvers) - k0} new functions, not timed; casadi rows vs cons.values: "
            f"max rel. diff {err:.1e})"
        )
        return out
    if m == "reference":
        ref = solvers["reference"]
        ref(probs[0].cons, probs[0].target, probs[0].starts)
        return timed(lambda: [ref(p.cons, p.target, p.starts).x for p in probs], repeat)
    if m in ("batched", "batched-numba"):
        from filletfold.vertex import batch as module

        kernel = m == "batched-numba"
        saved = module.USE_KERNEL, module.KERNEL_MIN_PROBLEMS
        module.USE_KERNEL, module.KERNEL_MIN_PROBLEMS = kernel, 0
        try:
            batch = solvers["batched"]
            cons, targets, starts = zip(*((p.cons, p.target, p.starts) for p in probs), strict=True)
            batch(list(cons[:1]), list(targets[:1]), list(starts[:1]))
            sols, secs = timed(lambda: batch(list(cons), list(targets), list(starts)), repeat)
        finally:
            module.USE_KERNEL, module.KERNEL_MIN_PROBLEMS = saved
        return [s.x for s in sols], secs
    raise ValueError(m)


HEAD = (
    f"  {'method':11s} {'n':>5s} {'feas':>5s} {'success':>8s} {'gap med':>9s} {'gap max':>9s} "
    f"{'µs/vertex':>10s} {'ratio':>7s}"
)


def row(name, n, n_feas, ok, feas, gaps, us, us_batched) -> str:
    succ = ok[feas].mean() * 100 if n_feas else float("nan")
    g = gaps[ok & feas] if n_feas else np.array([])
    gmed = float(np.median(g)) if len(g) else float("nan")
    gmax = float(np.max(g)) if len(g) else float("nan")
    ratio = f"{us / us_batched:7.1f}" if us_batched else f"{'-':>7s}"
    return (
        f"  {name:11s} {n:5d} {n_feas:5d} {succ:7.2f}% {fmt_gap(gmed)} {fmt_gap(gmax)} "
        f"{us:10.1f} {ratio}"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="1 run, <= 40 problems per case")
    ap.add_argument("--repeat", type=int, default=None, help="runs per method (default 3)")
    ap.add_argument("--max-problems", type=int, default=None, help="cap per case")
    ap.add_argument("--random", type=int, default=None, help="random polyhedra (default 5)")
    ap.add_argument("--seed", type=int, default=6)
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--mesh", action="append", default=[], help="add a mesh file (repeatable)")
    args = ap.parse_args(argv)
    repeat = args.repeat or (1 if args.quick else 3)
    cap = args.max_problems or (40 if args.quick else None)
    n_random = args.random if args.random is not None else (2 if args.quick else 5)
    n_range = (30, 60) if args.quick else (30, 200)
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    for m in methods:
        if m not in METHODS:
            ap.error(f"unknown method {m!r}; choose from {', '.join(METHODS)}")

    if "batched-numba" in methods and importlib.util.find_spec("numba") is None:
        print("# batched-numba skipped: numba is missing (a dependency: pip install -e .)")
        methods.remove("batched-numba")
    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(
        "# problems: filletfold.vertex.solve.apex_problems; reference: "
        "filletfold.vertex.reference.solve_apex_slsqp"
    )
    print(
        f"# µs per vertex: median of {repeat} run(s) after one warm-up; feasible: some method "
        f"meets every row within {FEAS_TOL:g} L; gap = (f - f_best) / max(f_best, 1e-12)"
    )
    ipopt = None
    if "ipopt" in methods:
        try:
            import casadi

            ipopt = Ipopt(casadi)
            print(f"# ipopt: casadi {casadi.__version__}")
        except ImportError:
            print("# ipopt: skipped (casadi is not installed: pip install casadi)")
            methods.remove("ipopt")

    solvers = {"ipopt": ipopt, "reference": solve_apex_slsqp, "batched": solve_apex_batch}
    rng = np.random.default_rng(args.seed)
    cases = [
        (name, name, "10%", "30%", False)
        for name in ("tetrahedron", "cube", "octahedron", "dodecahedron", "icosahedron")
    ]
    cases += [
        ("geodesic-3", "geodesic-sphere:level=3", "10%", "30%", False),
        ("bunny (clamp)", BUNNY, "10%", "30%", True),
    ]
    cases += [(os.path.basename(m), m, "10%", "30%", True) for m in args.mesh]
    totals = {m: {"n": 0, "t": 0.0, "ok": [], "feas": [], "gap": []} for m in methods}
    t_start = time.perf_counter()
    for case in [*cases, ("random", None, None, None, None)]:
        name, mesh, radius, depth, clamp = case
        if mesh is None:
            probs, note = random_problems(rng, n_random, n_range)
            note = f"{n_random} random convex polyhedra ({note}), depth 5-100 %"
        else:
            probs = mesh_problems(mesh, radius, depth, clamp)
            note = f"radius {radius}{' clamped' if clamp else ''}, depth {depth}"
        if cap is not None and len(probs) > cap:
            pick = np.sort(rng.choice(len(probs), cap, replace=False))
            note += f"; {cap} of {len(probs)} problems"
            probs = [probs[i] for i in pick]
        n = len(probs)
        print(f"\n## {name}: {n} apex problems; {note}")
        if not n:
            continue
        xs, secs = {}, {}
        for m in methods:
            xs[m], secs[m] = run_method(m, probs, repeat, solvers, rng)
        ok, gaps, feas = score(probs, xs)
        n_feas = int(feas.sum())
        us = {m: 1e6 * secs[m] / n for m in methods}
        us_b = us.get("batched")
        print(HEAD)
        for m in methods:
            print(row(m, n, n_feas, ok[m], feas, gaps[m], us[m], us_b))
            tm = totals[m]
            tm["n"] += n
            tm["t"] += secs[m]
            tm["ok"].append(ok[m])
            tm["feas"].append(feas)
            tm["gap"].append(gaps[m])
    print(f"\n## summary over all cases ({time.perf_counter() - t_start:.0f} s wall)")
    print(HEAD)
    us_all = {m: 1e6 * totals[m]["t"] / max(totals[m]["n"], 1) for m in methods}
    for m in methods:
        tm = totals[m]
        if not tm["ok"]:
            continue
        ok, feas, gap = (np.concatenate(tm[k]) for k in ("ok", "feas", "gap"))
        print(row(m, tm["n"], int(feas.sum()), ok, feas, gap, us_all[m], us_all.get("batched")))
    if ipopt is not None:
        print(
            f"  (ipopt: casadi setup {ipopt.setup:.2f} s in total, {len(ipopt.solvers)} "
            "functions, not in µs/vertex)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
