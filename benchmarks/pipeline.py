"""Stage timings and peak memory of the pipeline on meshes of growing size (issue 6's table).

    .venv/bin/python benchmarks/pipeline.py [--repeat N] [--max-faces F] [--timeout S]
                                            [--arc-step DEG] [cases...]
    .venv/bin/python benchmarks/pipeline.py --max-faces 100000 --repeat 1   # the big run

Cases, each skipped when it has more than ``--max-faces`` faces (default 1280, quick):

* the Platonic solids;
* ``geodesic-sphere`` at levels 3..6 (1280, 5120, 20480, 81920 triangles; convex, so every
  vertex gets a cone): the ~1k, ~10k and ~100k face cases;
* a real object: ``examples/bunny-lowres.obj`` (200 triangles, radii clamped) and, since the
  project has no real mesh of a few thousand faces, that bunny Loop-subdivided once and twice
  (800 and 3200 triangles, smoothed, so not coplanar; radii clamped);
* large tessellations with material loss: ``miura:20x20`` and ``miura:40x40`` (400 and 1600
  parallelograms) with ``material_loss=True`` and layout ``auto`` (one uncut sheet).

As the command line runs it (``keep_stages=False``: no state kept for reuse). Radius 10 %,
depth 30 %, no tabs, 24 samples per arc at most and the library's arc step
(``--arc-step 0``: every arc gets 24 points, as before adaptive sampling); layout ``modules``
except for the tessellations. Every case
runs in its own child process (so peak memory, ``ru_maxrss``, is the case's alone and includes
the interpreter and imports, ``base MB``), killed after ``--timeout`` seconds (then skipped
with a note). Per case: the median over ``--repeat`` runs of every stage of ``round_mesh``
(``design.timings``) and of the export (fold, json, obj, svg), the median total, ms per
vertex and µs per face. Last, the scaling ratio: time per face of the largest case run over
time per face of ``geodesic-3`` (1280 faces); linear scaling is 1.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BUNNY = os.path.join(ROOT, "examples", "bunny-lowres.obj")
STAGES = ["read", "rounding", "normals", "apices", "creases", "surface"]
REF_CASE = "geodesic-3"

# name -> (faces, mesh spec, round_mesh keyword arguments); faces known without building
CASES = {
    **{
        name: (faces, name, {})
        for name, faces in (
            ("tetrahedron", 4),
            ("cube", 6),
            ("octahedron", 8),
            ("dodecahedron", 12),
            ("icosahedron", 20),
        )
    },
    **{f"geodesic-{lv}": (20 * 4**lv, f"geodesic-sphere:level={lv}", {}) for lv in (3, 4, 5, 6)},
    "bunny": (200, "bunny", {"clamp": True}),
    "bunny-loop1": (800, "bunny-loop1", {"clamp": True}),
    "bunny-loop2": (3200, "bunny-loop2", {"clamp": True}),
    "miura:20x20 loss": (400, "miura:20x20", {"material_loss": True, "layout": "auto"}),
    "miura:40x40 loss": (1600, "miura:40x40", {"material_loss": True, "layout": "auto"}),
}


def case_mesh(spec: str):
    """The mesh argument of ``round_mesh`` for a case (built in the child, outside timings)."""
    if spec == "bunny":
        return BUNNY
    if spec.startswith("bunny-loop"):
        import numpy as np
        from trimesh.remesh import subdivide_loop

        from filletfold.mesh import read_mesh

        v, f = read_mesh(BUNNY)
        v, f = subdivide_loop(np.asarray(v, float), np.asarray(f), int(spec[-1]))
        return v, f
    from filletfold.mesh import example_mesh

    return example_mesh(spec)


def rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KB on Linux


def child(name: str, repeat: int, arc_step: float | None = None) -> dict:
    """Run one case ``repeat`` times in this process; medians, sizes and peak memory."""
    import filletfold

    _, spec, kwargs = CASES[name]
    mesh = case_mesh(spec)
    base = rss_mb()
    kwargs = {"layout": "modules", "tabs": False, "keep_stages": False, **kwargs}  # as the CLI
    if arc_step is not None:
        kwargs["arc_step"] = arc_step
    runs = []
    d = None
    for _ in range(repeat):
        t = time.perf_counter()
        d = filletfold.round_mesh(mesh, **kwargs)
        with tempfile.TemporaryDirectory() as tmp:
            t_exp = time.perf_counter()
            d.export(tmp)
            export = time.perf_counter() - t_exp
        total = time.perf_counter() - t
        runs.append(
            {
                **{k: v for k, v in d.timings.items() if k != "total"},
                "export": export,
                "total": total,
            }
        )
    keys = sorted({k for r in runs for k in r})
    med = {k: statistics.median(r.get(k, 0.0) for r in runs) for k in keys}
    return {
        "V": int(d.mesh.n_vertices),
        "F": int(d.mesh.n_faces),
        "status": d.status_counts(),
        "layout": d.layout,
        "pattern_faces": len(d.pattern.faces),
        "median": med,
        "base_mb": base,
        "peak_mb": rss_mb(),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument(
        "--max-faces",
        type=int,
        default=1280,
        help="skip cases with more faces (100000 for the big run)",
    )
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per case")
    ap.add_argument(
        "--arc-step",
        type=float,
        default=None,
        help="round_mesh's arc_step in degrees (default: the library's; 0: uniform samples)",
    )
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("cases", nargs="*", help=f"case names (default all: {', '.join(CASES)})")
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child, args.repeat, args.arc_step)))
        return 0
    for c in args.cases:
        if c not in CASES:
            ap.error(f"unknown case {c!r}; choose from {', '.join(CASES)}")

    sys.path.insert(0, HERE)
    from examples import machine

    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(
        f"# medians of {args.repeat} runs (s); radius 10%, depth 30%, no tabs, arc step "
        f"{'default' if args.arc_step is None else f'{args.arc_step:g}'}; one child "
        f"process per case (timeout {args.timeout:g} s); peak = child's max RSS"
    )
    names = args.cases or list(CASES)
    cols = [*STAGES, "export"]
    head = (
        f"{'case':17s} {'V':>6s} {'F':>6s} "
        + " ".join(f"{s:>8s}" for s in cols)
        + f" {'total':>8s} {'ms/vert':>8s} {'µs/face':>8s} {'peak MB':>8s} {'base MB':>8s}"
        + f" {'faces out':>9s}  statuses"
    )
    print(head)
    done = {}
    skipped = []
    for name in names:
        faces = CASES[name][0]
        if faces > args.max_faces:
            skipped.append(f"{name} ({faces} faces)")
            continue
        cmd = [
            sys.executable,
            os.path.abspath(__file__),
            "--child",
            name,
            "--repeat",
            str(args.repeat),
            *([] if args.arc_step is None else ["--arc-step", str(args.arc_step)]),
        ]
        try:
            out = subprocess.run(
                cmd, capture_output=True, text=True, timeout=args.timeout, cwd=ROOT
            )
        except subprocess.TimeoutExpired:
            print(f"{name:17s} skipped: over the {args.timeout:g} s timeout")
            continue
        if out.returncode != 0:
            err = (out.stderr.strip().splitlines() or ["?"])[-1]
            print(f"{name:17s} failed: {err}")
            continue
        r = json.loads(out.stdout.strip().splitlines()[-1])
        done[name] = r
        med = r["median"]
        extra = sorted(set(med) - {*cols, "total"})
        counts = ", ".join(f"{k} {v}" for k, v in r["status"].items() if v)
        print(
            f"{name:17s} {r['V']:6d} {r['F']:6d} "
            + " ".join(f"{med[s]:8.3f}" if s in med else f"{'-':>8s}" for s in cols)
            + f" {med['total']:8.2f} {1e3 * med['total'] / r['V']:8.2f}"
            + f" {1e6 * med['total'] / r['F']:8.0f} {r['peak_mb']:8.0f} {r['base_mb']:8.0f}"
            + f" {r['pattern_faces']:9d}"
            + f"  {counts}"
            + (f"; {r['layout']}" if r["layout"] != "modules" else "")
            + (f"; other stages: {', '.join(f'{k} {med[k]:.3f}' for k in extra)}" if extra else "")
        )
    if skipped:
        print(f"# not run (over --max-faces {args.max_faces}): {', '.join(skipped)}")
    if REF_CASE in done:
        big = max(done, key=lambda k: done[k]["F"])
        per_face = {k: done[k]["median"]["total"] / done[k]["F"] for k in (REF_CASE, big)}
        print(
            f"# scaling: time per face of {big} ({done[big]['F']} faces) / {REF_CASE} "
            f"({done[REF_CASE]['F']} faces) = {per_face[big] / per_face[REF_CASE]:.2f} "
            "(linear = 1; issue 6 asks <= 1.5 up to 100k faces)"
        )
    else:
        print(f"# scaling: not computed ({REF_CASE} did not run)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
