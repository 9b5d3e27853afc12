"""Round every built-in example and print statuses, mismatch and run time.

Run from the repository root:

    .venv/bin/python benchmarks/examples.py [--repeat N] [--radius R] [--depth D] [names...]

Prints the machine and the command first; times are medians of ``--repeat`` runs of
``filletfold.round_mesh`` (no export), in one process.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from importlib import metadata

import numpy as np

import filletfold
from filletfold.export.outputs import edge_mismatch, relative_mismatch
from filletfold.mesh import example_names


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        numba = f"numba {metadata.version('numba')}"
    except metadata.PackageNotFoundError:
        numba = "no numba"
    return (
        f"{platform.system()} {platform.machine()}, {os.cpu_count()} cores, {cpu}; "
        f"Python {platform.python_version()}, numpy {np.__version__}, {numba}, "
        f"filletfold {filletfold.__version__}"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", help="examples (default: all built-ins)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--radius", default="10%")
    ap.add_argument("--depth", default="30%")
    ap.add_argument("--clamp", action="store_true")
    args = ap.parse_args(argv)
    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# radius {args.radius}, depth {args.depth}, median of {args.repeat} runs")
    head = (
        f"{'example':22s} {'V':>4s} {'ok':>4s} {'sad':>4s} {'inf':>4s} {'bnd':>4s} "
        f"{'dev':>4s} {'pieces':>6s} {'mismatch':>9s} {'relative':>9s} {'time s':>7s}"
    )
    print(head)
    for name in args.names or example_names():
        times = []
        for _ in range(args.repeat):
            t = time.perf_counter()
            d = filletfold.round_mesh(name, radius=args.radius, depth=args.depth, clamp=args.clamp)
            times.append(time.perf_counter() - t)
        c = d.status_counts()
        p = d.pattern
        print(
            f"{name:22s} {d.mesh.n_vertices:4d} {c['ok']:4d} {c['saddle']:4d} "
            f"{c['infeasible']:4d} {c['boundary']:4d} {c['developable']:4d} "
            f"{p.n_pieces:6d} {edge_mismatch(p).max():9.2e} "
            f"{relative_mismatch(p).max():9.2e} {statistics.median(times):7.3f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
