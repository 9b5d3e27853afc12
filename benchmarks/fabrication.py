"""Nets, glue tabs and sheets for a few meshes.

    .venv/bin/python benchmarks/fabrication.py

Per case: vertex modules, net pieces, sheets (with --sheet), cut borders, tabs placed, borders
left with labels only, and the run time of ``round_mesh`` (one run), after machine and command.
"""

from __future__ import annotations

import os
import sys
import time

import filletfold

sys.path.insert(0, os.path.dirname(__file__))
from examples import machine

CASES = [
    ("icosahedron", {}),
    ("cube", {}),
    ("dodecahedron", {}),
    ("dodecahedron", {"sheet": "A4", "units": "mm", "scale": 60.0}),
    ("torus", {}),
    ("examples/bunny-lowres.obj", {"clamp": True}),
    ("examples/bunny-lowres.obj", {"clamp": True, "sheet": "A3", "units": "mm", "scale": 8.0}),
]


def main() -> int:
    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(
        f"{'case':48s} {'modules':>7s} {'pieces':>6s} {'sheets':>6s} {'borders':>7s} "
        f"{'tabs':>5s} {'no tab':>6s} {'time s':>7s}"
    )
    for name, kw in CASES:
        t = time.perf_counter()
        modules = filletfold.round_mesh(
            name, layout="modules", tabs=False, clamp=kw.get("clamp", False)
        ).pattern.n_pieces
        d = filletfold.round_mesh(name, layout="net", **kw)
        dt = time.perf_counter() - t
        f = d.fabrication
        label = name + (f" --sheet {kw['sheet']} --scale {kw['scale']:g}" if "sheet" in kw else "")
        print(
            f"{label:48s} {modules:7d} {d.pattern.n_pieces:6d} {f.get('sheets', 0):6d} "
            f"{f['cut_borders']:7d} {f['tabs']:5d} {f['untabbed']:6d} {dt:7.2f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
