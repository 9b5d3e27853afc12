"""The numba kernel of the batched interior-point method against the numpy one.

    .venv/bin/python benchmarks/ipm_kernel.py [--repeat N] [--no-compile] [--pipeline]
                                              [cases...]

Needs numba (a dependency). Per case, the apex problems of the pipeline's first
attempt (radius 10 %, depth 30 %, 9 samples per arc, the margin; set up as in
``round_mesh`` by :func:`filletfold.vertex.solve.apex_problems`) go through
``solve_apex_batch`` (``thorough`` as in the pipeline's first round: off, so an infeasible
problem is given up without the SLSQP fallback) with ``filletfold.vertex.batch.interior_point``
monkeypatched to :func:`~filletfold.vertex.batch.interior_point_numpy` and to
:func:`~filletfold.vertex.batch_kernel.interior_point_numba`. Reported: the
median over ``--repeat`` runs of the time spent inside ``interior_point`` (all its calls:
phase 1 and phase 2) and of the whole ``solve_apex_batch``, in ms and µs per problem
(vertex), numpy's time over the kernel's, and how the results differ from numpy's (``ok``
flags that differ, largest apex distance over the scale where both are ok). One warm-up run
per variant first (so the compile time is not in these figures).

Then, unless ``--no-compile``, in fresh processes: the import time of numba, the first call
of the kernel with an empty on-disk cache (``NUMBA_CACHE_DIR`` set to a new directory: the
JIT compile) and again with that cache filled, and the installed size of numba + llvmlite.
``--pipeline``: also one ``round_mesh`` per case and variant, with the apex stage's time
(``design.timings["apices"]``, every round) and the interior-point time inside it.

Cases: ``blob``, ``geodesic-sphere:level=3`` (642 vertices) and ``bunny-loop2`` (the bunny
Loop-subdivided twice, 3200 triangles, radii clamped; built as in ``benchmarks/pipeline.py``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)

from examples import machine  # noqa: E402
from pipeline import case_mesh  # noqa: E402

from filletfold.vertex import batch  # noqa: E402

# name -> (mesh spec for pipeline.case_mesh, clamp the radii)
CASES = {
    "blob": ("blob", False),
    "geodesic-3": ("geodesic-sphere:level=3", False),
    "bunny-loop2": ("bunny-loop2", True),
}


def first_attempt_problems(spec: str, clamp: bool):
    """(constraints, targets, starts, thorough) of every cone vertex's first attempt, as
    :func:`filletfold.vertex.solve.solve_apices` sets up its first round."""
    from filletfold.mesh import load_mesh
    from filletfold.rounding.edges import clamp_radii, round_edges
    from filletfold.vertex.solve import apex_problems

    pm, _ = load_mesh(case_mesh(spec))
    ref = pm.mean_edge_length
    r = np.full(pm.n_edges, 0.1 * ref)
    if clamp:
        r = clamp_radii(pm, r)
    probs = apex_problems(pm, round_edges(pm, r), np.full(pm.n_vertices, 0.3 * ref))
    return (
        [p.constraints(*p.attempts[0]) for p in probs],
        [np.asarray(p.target, float) for p in probs],
        [list(p.starts) for p in probs],
        [p.attempts[0][1] < 1.0 for p in probs],
    )


class Timed:
    """``interior_point`` replacement that adds up the time spent in ``fn``."""

    def __init__(self, fn):
        self.fn = fn
        self.total = 0.0
        self.calls = 0

    def __call__(self, *args, **kwargs):
        t = time.perf_counter()
        try:
            return self.fn(*args, **kwargs)
        finally:
            self.total += time.perf_counter() - t
            self.calls += 1


def variants() -> dict:
    from filletfold.vertex.batch_kernel import interior_point_numba

    return {"numpy": batch.interior_point_numpy, "numba": interior_point_numba}


def time_case(problems, repeat: int) -> dict:
    """Per variant: median (ipm seconds, solve_apex_batch seconds), ok count, calls."""
    original = batch.interior_point
    res = {}
    sols = {}
    try:
        for name, fn in variants().items():
            ipm, total = [], []
            for k in range(repeat + 1):  # the first run warms up (compiles)
                timed = Timed(fn)
                batch.interior_point = timed
                t = time.perf_counter()
                sols[name] = batch.solve_apex_batch(*problems[:3], thorough=problems[3])
                if k:
                    total.append(time.perf_counter() - t)
                    ipm.append(timed.total)
            res[name] = (statistics.median(ipm), statistics.median(total), timed.calls)
    finally:
        batch.interior_point = original
    # agreement with numpy: ok flags and apices
    ref = sols["numpy"]
    for name, sol in sols.items():
        flips = sum(a.ok != b.ok for a, b in zip(ref, sol, strict=True))
        gap = max(
            (
                float(np.abs(a.x - b.x).max() / c.scale)
                for a, b, c in zip(ref, sol, problems[0], strict=True)
                if a.ok and b.ok
            ),
            default=0.0,
        )
        res[name] = (*res[name], flips, gap)
    return res


def pipeline_case(spec: str, clamp: bool) -> dict:
    """One round_mesh per variant: (apex stage s, ipm s inside it)."""
    import filletfold

    mesh = case_mesh(spec)
    original = batch.interior_point
    out = {}
    try:
        for name, fn in variants().items():
            timed = Timed(fn)
            batch.interior_point = timed
            d = filletfold.round_mesh(mesh, layout="modules", tabs=False, clamp=clamp)
            out[name] = (d.timings.get("apices", float("nan")), timed.total)
    finally:
        batch.interior_point = original
    return out


FIRST_CALL = """
import time
t0 = time.perf_counter()
import numba
t1 = time.perf_counter()
from filletfold.vertex import rows as r
from filletfold.vertex.batch_kernel import interior_point_numba
rows = r.pack([(__import__('numpy').array([1.0, 2.0]), __import__('numpy').eye(2, 3),
                    __import__('numpy').zeros(2))], 3)
import numpy as np
t2 = time.perf_counter()
interior_point_numba(rows, np.full(3, 2.0), np.ones((1, 3)), np.zeros((1, 3)))
t3 = time.perf_counter()
print(t1 - t0, t3 - t2)
"""


def compile_figures() -> None:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    # import time of numba alone, median of 3 fresh processes
    imports = []
    for _ in range(3):
        out = subprocess.run(
            [sys.executable, "-c", "import time; t = time.perf_counter(); import numba; "
             "print(time.perf_counter() - t)"],
            capture_output=True, text=True, check=True, env=env,
        )  # fmt: skip
        imports.append(float(out.stdout))
    print(f"import numba (fresh process, median of 3): {statistics.median(imports):.2f} s")
    with tempfile.TemporaryDirectory() as cache:
        env_c = {**env, "NUMBA_CACHE_DIR": cache}
        code = FIRST_CALL
        for label in ("empty cache (JIT compile)", "filled cache (load)"):
            t = time.perf_counter()
            out = subprocess.run(
                [sys.executable, "-c", code], capture_output=True, text=True, env=env_c,
                cwd=ROOT, check=True,
            )  # fmt: skip
            wall = time.perf_counter() - t
            imp, first = (float(x) for x in out.stdout.split())
            print(
                f"first kernel call, {label}: {first:.2f} s "
                f"(numba import {imp:.2f} s; whole process {wall:.1f} s)"
            )
        size = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(cache) for f in fs)
        print(f"on-disk cache: {size / 1e6:.1f} MB")
    import llvmlite
    import numba

    total = 0
    for mod in (numba, llvmlite):
        root = os.path.dirname(mod.__file__)
        total += sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(root) for f in fs)
    print(
        f"installed size: numba {numba.__version__} + llvmlite {llvmlite.__version__} = "
        f"{total / 1e6:.0f} MB"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--no-compile", action="store_true", help="skip the compile-time figures")
    ap.add_argument("--pipeline", action="store_true", help="also time round_mesh's apex stage")
    ap.add_argument("cases", nargs="*", help=f"default all: {', '.join(CASES)}")
    args = ap.parse_args(argv)
    for c in args.cases:
        if c not in CASES:
            ap.error(f"unknown case {c!r}; choose from {', '.join(CASES)}")
    import numba

    print(f"# machine: {machine()}; numba {numba.__version__}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(
        f"# first attempt of every cone vertex through solve_apex_batch; medians of "
        f"{args.repeat} runs after a warm-up; ipm = time inside interior_point"
    )
    print(
        f"{'case':12s} {'V':>5s} {'variant':>9s} {'calls':>5s} {'ipm ms':>8s} {'µs/vert':>8s} "
        f"{'batch ms':>9s} {'µs/vert':>8s} {'ipm x':>6s} {'batch x':>7s} {'ok diff':>7s} "
        f"{'max |dx|/L':>10s}"
    )
    for name in args.cases or list(CASES):
        spec, clamp = CASES[name]
        problems = first_attempt_problems(spec, clamp)
        V = len(problems[0])
        res = time_case(problems, args.repeat)
        ipm0, tot0 = res["numpy"][:2]
        for variant, (ipm, tot, calls, flips, gap) in res.items():
            print(
                f"{name:12s} {V:5d} {variant:>9s} {calls:5d} {1e3 * ipm:8.1f} "
                f"{1e6 * ipm / V:8.0f} {1e3 * tot:9.1f} {1e6 * tot / V:8.0f} "
                f"{ipm0 / ipm:6.1f} {tot0 / tot:7.2f} {flips:7d} {gap:10.1e}"
            )
        if args.pipeline:
            for variant, (apices, ipm) in pipeline_case(spec, clamp).items():
                print(
                    f"{name:12s} round_mesh, {variant}: apex stage {apices:.2f} s, "
                    f"of which interior_point {ipm:.2f} s"
                )
    if not args.no_compile:
        compile_figures()
    return 0


if __name__ == "__main__":
    sys.exit(main())
