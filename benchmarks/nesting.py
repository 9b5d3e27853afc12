"""Sheets and material use with the shelf packer and with sparrow, on the same designs.

    .venv/bin/python benchmarks/nesting.py [--seconds S] [CASE ...]

Per case (a mesh, a sheet and a scale in mm per unit): the net pieces, then for the shelf
packer and for sparrow (``nest="sparrow"``, or ``"sparrow:S"`` with ``--seconds S``) the
sheets, the material use (the pieces' area over the sheets' area), the strip use (over the
strip the sheets make, to the last sheet's rightmost piece) and the seconds the placement
took (``timings["nest"]``). Both packers place the same pieces: the second design reuses the
first one's stages. CASE filters the cases by a part of their label. Needs the ``nest`` extra.
"""

from __future__ import annotations

import argparse
import os
import sys

import filletfold
from filletfold.layout.nest import have_sparrow

sys.path.insert(0, os.path.dirname(__file__))
from examples import machine

#: (mesh, sheet, mm per mesh unit, round_mesh options)
CASES = [
    ("cube", "A4", 60.0, {}),
    ("cube", "A3", 60.0, {}),
    ("icosahedron", "A4", 60.0, {}),
    ("icosahedron", "A3", 60.0, {}),
    ("dodecahedron", "A4", 60.0, {}),
    ("dodecahedron", "A3", 60.0, {}),
    ("torus", "A4", 30.0, {}),
    ("torus", "A3", 30.0, {}),
    ("examples/bunny-lowres.obj", "A4", 6.0, {"clamp": True}),
    ("examples/bunny-lowres.obj", "A3", 8.0, {"clamp": True}),
    ("tests/data/corpus/compas-tubemesh.obj", "A4", 30.0, {}),
    ("tests/data/corpus/compas-tubemesh.obj", "A3", 30.0, {}),
]


def _row(design) -> tuple:
    f = design.fabrication
    n = f["nesting"]
    return f["sheets"], n["material_use"], n["strip_use"], design.timings["nest"]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=int, default=0, help="sparrow's search per run")
    parser.add_argument("cases", nargs="*", help="parts of case labels to run")
    args = parser.parse_args(argv)
    if not have_sparrow():
        print("needs spyrrow: pip install 'filletfold[nest]'", file=sys.stderr)
        return 2
    nester = f"sparrow:{args.seconds}" if args.seconds else "sparrow"
    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# nester: {nester}; each case: filletfold round MESH --sheet S --units mm --scale K")
    print(
        "| design | sheet | mm/unit | pieces | shelf sheets | shelf use | shelf strip | shelf s "
        "| sparrow sheets | sparrow use | sparrow strip | sparrow s | runs |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for mesh, sheet, scale, kw in CASES:
        label = f"{os.path.basename(mesh)} {sheet}"
        if args.cases and not any(c in label for c in args.cases):
            continue
        common = {"sheet": sheet, "units": "mm", "scale": scale, **kw}
        shelf = filletfold.round_mesh(mesh, nest="shelf", certify=False, **common)
        nested = filletfold.round_mesh(mesh, nest=nester, certify=False, reuse=shelf, **common)
        assert nested.pattern.n_pieces == shelf.pattern.n_pieces
        a, b = _row(shelf), _row(nested)
        print(
            f"| {os.path.basename(mesh)} | {sheet} | {scale:g} | {shelf.pattern.n_pieces} "
            f"| {a[0]} | {a[1]:.1%} | {a[2]:.1%} | {a[3]:.2f} "
            f"| {b[0]} | {b[1]:.1%} | {b[2]:.1%} | {b[3]:.2f} "
            f"| {nested.fabrication['nesting']['runs']} |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
