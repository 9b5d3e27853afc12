"""The pictures of sharp vertices in ``docs/`` (issue 15): the bunny and the torus folded, with
holes (``--sharp none``) and closed (the default), patches coloured (cones orange, cylinders
blue, conical fillets teal, face pieces green).

Run from the repository root:

    .venv/bin/python benchmarks/pictures.py [--out docs]

Writes ``bunny-1k-holes-front.png``, ``bunny-1k-closed-front.png``, ``bunny-1k-closed-back.png``
(``examples/bunny-lowres.obj`` Loop-subdivided twice: 1,602 vertices),
``bunny-lowres-closed-front.png``, ``bunny-lowres-closed-back.png``, ``torus-holes-front.png``
and ``torus-closed-front.png``, and prints for each design its vertices by treatment and the
certificate's ``holes`` line, after the machine.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections import Counter
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from examples import machine
from pipeline import case_mesh

import filletfold
from filletfold.export.png import preview_png

ROOT = Path(__file__).resolve().parent.parent
#: (input, name, sharp, views): front is azimuth -60 degrees, back 120 (elevation 25; the bunny
#: with +y up).
PICTURES = [
    ("bunny-loop2", "bunny-1k", "none", ("front",)),
    ("bunny-loop2", "bunny-1k", "auto", ("front", "back")),
    ("bunny", "bunny-lowres", "auto", ("front", "back")),
    ("torus", "torus", "none", ("front",)),
    ("torus", "torus", "auto", ("front",)),
]
AZIMUTH = {"front": -60.0, "back": 120.0}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs"))
    args = ap.parse_args(argv)
    print(machine())
    out = Path(args.out)
    for source, name, sharp, views in PICTURES:
        mesh = case_mesh(source) if source.startswith("bunny") else source
        d = filletfold.round_mesh(mesh, tabs=False, sharp=sharp)
        state = "holes" if sharp == "none" else "closed"
        print(
            f"{name} {state}: {dict(Counter(d.vertices.treatment))}; "
            f"{d.certificate['holes'].detail}; certificate {'ok' if d.certificate.ok else 'FAILS'}"
        )
        for view in views:
            up = "y" if source.startswith("bunny") else "z"  # the bunny's up is +y
            png = preview_png(d.pattern, width_px=900, azim=AZIMUTH[view], up=up)
            (out / f"{name}-{state}-{view}.png").write_bytes(png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
