"""Stage timings of the pipeline on meshes of growing size (issue 6's first table).

    .venv/bin/python benchmarks/pipeline.py [--repeat N] [--max-faces F]

Cases: the built-in ``geodesic-sphere`` at levels 0, 1, 2, ... (20, 80, 320, 1280, ...
faces), convex so every vertex gets a cone. For each: the median over
``--repeat`` runs of every stage of ``round_mesh`` (read, rounding, normals, apices, surface
with nets/tabs off) and of the export, the peak memory (ru_maxrss growth, MB) and seconds per
vertex. Prints the machine and the command first.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import sys
import tempfile
import time

import filletfold
from filletfold.mesh import example_mesh

sys.path.insert(0, os.path.dirname(__file__))
from examples import machine


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--max-faces", type=int, default=1280)
    args = ap.parse_args(argv)
    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# medians of {args.repeat} runs; radius 10%, depth 30%, layout modules, no tabs")
    stages = ["read", "rounding", "normals", "apices", "surface", "export"]
    print(
        f"{'case':18s} {'V':>6s} {'F':>6s} "
        + " ".join(f"{s:>9s}" for s in stages)
        + f" {'total':>8s} {'ms/vert':>8s} {'peak MB':>8s}"
    )
    level = 0
    while True:
        v, f = example_mesh(f"geodesic-sphere:level={level}")
        if len(f) > args.max_faces:
            break
        times = {s: [] for s in [*stages, "total"]}
        rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        for _ in range(args.repeat):
            t = time.perf_counter()
            d = filletfold.round_mesh((v, f), layout="modules", tabs=False)
            with tempfile.TemporaryDirectory() as tmp:
                d.export(tmp)
            times["total"].append(time.perf_counter() - t)
            for s in stages:
                times[s].append(d.timings.get(s, 0.0))
        peak = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss0) / 1024
        med = {s: statistics.median(x) for s, x in times.items()}
        print(
            f"{'geodesic-' + str(level):18s} {len(v):6d} {len(f):6d} "
            + " ".join(f"{med[s]:9.3f}" for s in stages)
            + f" {med['total']:8.2f} {1e3 * med['total'] / len(v):8.1f} {peak:8.1f}"
        )
        level += 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
