"""Round the developable tessellations and the conical dome with consistent material loss.

    .venv/bin/python benchmarks/material_loss.py [--repeat N] [names...]

Prints, per example: the LP bound b, the smallest and largest radius, vertices ok / interior,
pieces and cut edges of the pattern (one uncut sheet: 1 and 0), and the run time (median of
``--repeat`` runs of ``round_mesh``, no export), after the machine and the command.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import filletfold

sys.path.insert(0, os.path.dirname(__file__))
from examples import machine

DEFAULT = [
    "miura",
    "chicken-wire",
    "yoshimura",
    "resch",
    "resch:4x4",
    "miura:8x8,fold=0.7",
    "conical-dome",
]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# round_mesh(name, material_loss=True), median of {args.repeat} runs")
    print(
        f"{'example':22s} {'method':8s} {'b':>9s} {'r min':>9s} {'r max':>9s} "
        f"{'ok/int':>7s} {'pieces':>6s} {'cuts':>5s} {'time s':>7s}"
    )
    for name in args.names or DEFAULT:
        times = []
        for _ in range(args.repeat):
            t = time.perf_counter()
            d = filletfold.round_mesh(name, material_loss=True)
            times.append(time.perf_counter() - t)
        ml = d.material_loss
        r = d.rounding.radius[d.rounding.radius > 0]
        interior = int((~d.mesh.is_boundary_vertex).sum())
        method = "offset" if ml.message.startswith("conical") else "LP"
        print(
            f"{name:22s} {method:8s} {ml.bound:9.3g} {r.min():9.3g} {r.max():9.3g} "
            f"{d.status_counts()['ok']:3d}/{interior:<3d} {d.pattern.n_pieces:6d} "
            f"{int(d.pattern.cut_mask().sum()):5d} {statistics.median(times):7.2f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
