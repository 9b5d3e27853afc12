"""The apex stage with the compiled (numba) interior-point kernel and with numpy alone.

Run from the repository root:

    .venv/bin/python benchmarks/numba_choice.py [--repeat N] [cases...]

What decided that numba is a dependency: the same designs solved with ``FILLETFOLD_NUMBA=1``
and ``FILLETFOLD_NUMBA=0``, each case in child processes with ``FILLETFOLD_THREADS=1`` (one
thread, so CPU time and wall time tell the same story on a quiet machine). Per case and
solver: the median over ``--repeat`` runs (after one warm-up run, the kernel loaded before)
of the apex stage's CPU seconds (``time.process_time`` around the stage) and its wall
seconds (``design.timings["apices"]``), and the whole ``round_mesh``'s CPU seconds (tabs
off: the tab stage does not depend on the solver); last, numpy's time over numba's.

Cases: ``hull-N``, the convex hull of N seeded random points on the unit sphere (every point
is a vertex; irregular triangles), and ``geodesic-sphere:level=L`` or any other mesh spec
``filletfold round`` takes.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_CASES = ["hull-1000", "geodesic-sphere:level=4"]


def case_mesh(spec: str):
    """The ``round_mesh`` argument of a case: ``hull-N`` built here, anything else as is."""
    if not spec.startswith("hull-"):
        return spec
    import numpy as np
    import trimesh

    rng = np.random.default_rng(int(spec.split("-")[1]))
    p = rng.normal(size=(int(spec.split("-")[1]), 3))
    hull = trimesh.convex.convex_hull(p / np.linalg.norm(p, axis=1)[:, None])
    return np.asarray(hull.vertices), np.asarray(hull.faces)


def child(spec: str, repeat: int) -> dict:
    """Time one case in this process (the environment chooses the solver)."""
    import filletfold.design as design
    import filletfold.pipeline as pipeline
    from filletfold.vertex import batch

    kernel = batch.warm_kernel()
    mesh = case_mesh(spec)
    stage_cpu = []
    solve = pipeline.apex_stage

    def timed(*args, **kwargs):
        t = time.process_time()
        try:
            return solve(*args, **kwargs)
        finally:
            stage_cpu.append(time.process_time() - t)

    pipeline.apex_stage = timed
    design.apex_stage = timed  # the orchestrator's name for it
    runs = []
    for k in range(repeat + 1):
        t = time.process_time()
        d = design.round_mesh(mesh, tabs=False, keep_stages=False)
        if k:  # the first run warms caches
            runs.append((stage_cpu[-1], d.timings["apices"], time.process_time() - t))
    return {
        "kernel": kernel,
        "vertices": int(d.mesh.n_vertices),
        "cone_vertices": int(d.status_counts()["ok"]),
        "apices_cpu": statistics.median(r[0] for r in runs),
        "apices_wall": statistics.median(r[1] for r in runs),
        "round_cpu": statistics.median(r[2] for r in runs),
    }


def run_case(spec: str, numba: bool, repeat: int) -> dict:
    env = {**os.environ, "FILLETFOLD_NUMBA": "1" if numba else "0", "FILLETFOLD_THREADS": "1"}
    cmd = [sys.executable, os.path.abspath(__file__), "--child", spec, "--repeat", str(repeat)]
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False)
    if out.returncode:
        lines = (out.stderr or out.stdout).strip().splitlines()
        return {"error": lines[-1] if lines else f"exit {out.returncode}"}
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases", nargs="*", default=DEFAULT_CASES)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child, args.repeat)))
        return 0
    sys.path.insert(0, HERE)
    from examples import machine

    print(f"# {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# one thread; medians of {args.repeat} runs after a warm-up; seconds")
    head = "case", "V", "cone", "solver", "apices CPU", "apices wall", "round CPU"
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for spec in args.cases:
        res = {name: run_case(spec, name == "numba", args.repeat) for name in ("numba", "numpy")}
        for name, r in res.items():
            if "error" in r:
                print(f"| {spec} | | | {name} | error: {r['error']} | | |")
                continue
            solver = name if name == "numpy" or r["kernel"] else "numba (not loaded)"
            print(
                f"| {spec} | {r['vertices']} | {r['cone_vertices']} | {solver} "
                f"| {r['apices_cpu']:.3f} | {r['apices_wall']:.3f} | {r['round_cpu']:.3f} |"
            )
        if all("error" not in r for r in res.values()):
            ratio = res["numpy"]["apices_cpu"] / res["numba"]["apices_cpu"]
            print(f"| {spec} | | | numpy / numba | {ratio:.2f} | | |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
