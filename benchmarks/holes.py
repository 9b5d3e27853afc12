"""Holes before and after sharp vertices (issue 15): every example and corpus mesh, rounded
with ``--sharp none`` (holes at vertices without a cone) and with the default (kept sharp).

Run from the repository root:

    .venv/bin/python benchmarks/holes.py [NAME_OR_PATH ...] [--json FILE]

Default: every built-in example and every mesh of ``tests/data/corpus``. For each, through
``filletfold.round_mesh`` with the defaults (``tabs=False``: tabs do not change the surface),
prints: vertices by treatment (cone / sharp / hole), edges by treatment (cylinder / conical
fillet / sharp crease), the certificate's ``holes`` (holes and notches of the folded
surface, and the deepest notch of its border / size) with ``--sharp none`` and with the
default, whether every certificate check holds, the ``on fillets`` figure, and the seconds
of each run. Prints the machine and the command first.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from examples import machine

import filletfold
from filletfold.mesh import example_names
from filletfold.vertex.sharpen import edge_treatments

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / "tests" / "data" / "corpus"


def inputs(names: list[str]) -> list[str]:
    if names:
        return names
    corpus = sorted(
        str(p) for p in CORPUS.iterdir() if p.suffix.lower() in (".obj", ".ply", ".stl", ".off")
    )
    return list(example_names()) + corpus


def notch(detail: str) -> float | None:
    m = re.search(r"deepest notch of the border / size ([0-9.e+-]+)", detail)
    return float(m.group(1)) if m else None


def measure(source: str, sharp: str) -> dict:
    t = time.perf_counter()
    d = filletfold.round_mesh(source, sharp=sharp, tabs=False)
    seconds = time.perf_counter() - t
    cert = d.certificate
    holes = cert["holes"]
    return {
        "seconds": round(seconds, 2),
        "vertices": dict(Counter(d.vertices.treatment)),
        "edges": dict(Counter(edge_treatments(d.mesh, d.rounding, d.vertices.treatment))),
        "holes": int(holes.value),
        "notches": int(re.search(r"and (\d+) notches", holes.detail).group(1)),
        "notch": notch(holes.detail),
        "certificate": bool(cert.ok),
        "failed": [c.name for c in cert.failed],
        "on_fillets": None
        if cert["on fillets"].value != cert["on fillets"].value
        else cert["on fillets"].value,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("inputs", nargs="*")
    ap.add_argument("--json", help="also write the rows to this file")
    args = ap.parse_args(argv)
    print(machine())
    print("command:", " ".join([Path(sys.argv[0]).name, *(argv or sys.argv[1:])]))
    rows = []
    head = (
        f"{'mesh':28s} {'cone/sharp/hole':>15s} {'cyl/fillet/crease':>17s} "
        f"{'holes none->auto':>16s} {'notches':>9s} {'depth none->auto':>18s} "
        f"{'cert':>9s} {'fillet err':>10s} "
        f"{'s':>11s}"
    )
    print(head)
    for source in inputs(args.inputs):
        name = Path(source).name if os.sep in source else source
        try:
            before, after = measure(source, "none"), measure(source, "auto")
        except filletfold.FilletfoldError as exc:
            print(f"{name:28s} error: {exc}")
            rows.append({"mesh": name, "error": str(exc)})
            continue
        v, e = after["vertices"], after["edges"]

        def fmt(x):
            return "-" if x is None else f"{x:.2g}"

        print(
            f"{name:28s} {v.get('cone', 0):>5d}/{v.get('sharp', 0)}/{v.get('hole', 0):<5d} "
            f"{e.get('cylinder', 0):>7d}/{e.get('cone', 0)}/{e.get('sharp', 0):<5d} "
            f"{before['holes']:>8d} -> {after['holes']:<4d} "
            f"{before['notches']:>4d}->{after['notches']:<3d} "
            f"{fmt(before['notch']):>8s} -> {fmt(after['notch']):<6s} "
            f"{'ok' if before['certificate'] else 'FAIL'}/"
            f"{'ok' if after['certificate'] else 'FAIL'} "
            f"{fmt(after['on_fillets']):>10s} {before['seconds']:>5.1f}/{after['seconds']:<5.1f}"
        )
        rows.append({"mesh": name, "none": before, "auto": after})
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
