"""The pictures of a built example in ``docs/`` (issue 29): the pages of one design on A4 and
its assembly guide.

Run from the repository root:

    .venv/bin/python benchmarks/guide_pictures.py [--out docs] [--dpi 80]

Makes the design a user gets with ``filletfold round examples/bunny-lowres.obj --sheet A4
--format all`` (the default size, nets, glue tabs) and writes the first sheet of its
``pattern.pdf`` (``guide-sheet.png``), the overview page of its ``assembly.pdf``
(``guide-overview.png``) and its first page of steps (``guide-steps.png``), after the machine
and the design's figures (size, pieces, sheets, numbered borders, steps).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from examples import machine

import filletfold
from filletfold.export.assembly import STEPS_PER_PAGE, assembly_pages
from filletfold.export.pdf import pattern_pages

ROOT = Path(__file__).resolve().parent.parent
MESH = ROOT / "examples" / "bunny-lowres.obj"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs"), help="folder of the pictures")
    ap.add_argument("--dpi", type=float, default=80.0, help="pixels per inch of the pages")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(machine())
    print(f"# command: python benchmarks/guide_pictures.py {' '.join(argv or sys.argv[1:])}")
    t = time.perf_counter()
    design = filletfold.round_mesh(str(MESH), sheet="A4")
    p, fab = design.params, design.fabrication
    seams = fab["seams"]
    print(
        f"design: {MESH.relative_to(ROOT)} at {p.size} ({fab['default_size']['binding']} set it), "
        f"up +{design.up}: {design.pattern.n_pieces} pieces on {fab['sheets']} sheets of A4, "
        f"{len(seams)} numbered borders, {design.pattern.n_pieces} steps on "
        f"{-(-design.pattern.n_pieces // STEPS_PER_PAGE)} pages; "
        f"{time.perf_counter() - t:.1f} s"
    )
    sheet = next(iter(pattern_pages(design.pattern, page="A4", units=p.units, scale=p.scale)))
    # the guide's pictures sit on its pages pixel for pixel: drawn for the dpi wanted (the
    # overview's two pictures are 0.8 of the page's width, twice a step's)
    width_px = round(args.dpi * 0.8 * 210.0 / 25.4 / 2)
    pages = assembly_pages(design.pattern, seams, up=design.up, page="A4", width_px=width_px)
    figures = {"guide-sheet.png": sheet, "guide-overview.png": next(pages)}
    figures["guide-steps.png"] = next(pages)
    for name, fig in figures.items():
        dpi = args.dpi if name == "guide-sheet.png" else fig.dpi
        fig.savefig(out / name, dpi=dpi, metadata={"Software": None})
        print(f"wrote {out / name} ({(out / name).stat().st_size / 1024:.0f} KB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
