"""The gallery (``docs/gallery.md`` and its pictures in ``docs/gallery/``): the paper's figures
14 (Miura-ori and chicken wire), 17 (the icosahedron at three apex depths), 18 (Ron Resch's
tessellation), 19 (the bunny, front and back) and 20 (a shell structure), each picture the
``preview.png`` of one ``filletfold round`` command, which is written under it.

Run from the repository root:

    .venv/bin/python benchmarks/gallery.py [--out docs] [--only NAME ...]

Runs every command (in this process, through :func:`filletfold.cli.main`, in a temporary
folder), copies its ``preview.png`` to ``docs/gallery/<name>.png``, writes ``docs/gallery.md``
and prints, after the machine, each picture's size and the command's wall time.
"""

from __future__ import annotations

import argparse
import os
import shlex
import shutil
import sys
import tempfile
import time
from contextlib import redirect_stdout
from io import StringIO
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from examples import machine

from filletfold.cli import main as cli_main

ROOT = Path(__file__).resolve().parent.parent
#: (figure, title, paragraph, [(picture name, caption, command)]): each command is run from the
#: repository root with ``-o out/gallery/<name>`` appended; its preview.png is the picture.
FIGURES = [
    (
        "14",
        "Folded tessellations with consistent material loss",
        "A developable tessellation rounded with the material loss of paper sec. 4 "
        "(`--material-loss`): one uncut sheet (1 piece), every interior vertex a cone (9 of "
        "25; the 16 on the border are boundary vertices).",
        [
            (
                "miura",
                "Miura-ori, 4 × 4 cells",
                "filletfold round miura --material-loss --format png",
            ),
            (
                "chicken-wire",
                "Chicken wire, 4 × 4 cells",
                "filletfold round chicken-wire --material-loss --format png",
            ),
        ],
    ),
    (
        "17",
        "The icosahedron at three apex depths",
        "The same radius (10 % of the edge), the apex depth along the vertex normal 15 %, "
        "30 % (the default) and 60 % of the edge.",
        [
            (
                "icosahedron-depth15",
                "depth 15 %",
                "filletfold round icosahedron --depth 15% --format png",
            ),
            (
                "icosahedron-depth30",
                "depth 30 %",
                "filletfold round icosahedron --depth 30% --format png",
            ),
            (
                "icosahedron-depth60",
                "depth 60 %",
                "filletfold round icosahedron --depth 60% --format png",
            ),
        ],
    ),
    (
        "18",
        "Ron Resch's tessellation",
        "A part of Resch's triangle tessellation, partly folded (it curls into a cap), rounded "
        "as one sheet, seen from higher up than the default view.",
        [
            (
                "resch",
                "Resch, 3 × 3 stars",
                "filletfold round resch --material-loss --view=-60,55 --format png",
            ),
        ],
    ),
    (
        "19",
        "The Stanford bunny, front and back",
        "`examples/bunny-lowres.obj` (200 triangles; its up is +y, hence `,y` after the view). "
        "Its saddle vertices get no cone: they keep their corner (the default `--sharp`), and "
        "their edges to cones become conical fillets (teal).",
        [
            (
                "bunny-front",
                "front",
                "filletfold round examples/bunny-lowres.obj --view front,y --format png",
            ),
            (
                "bunny-back",
                "back",
                "filletfold round examples/bunny-lowres.obj --view back,y --format png",
            ),
        ],
    ),
    (
        "20",
        "A shell structure",
        "The built-in `shell`: an open vault of planar quads (a translational surface), every "
        "interior vertex convex; the boundary vertices stay sharp.",
        [
            (
                "shell",
                "shell, 8 × 6 quads",
                "filletfold round shell:8x6 --radius 15% --format png",
            ),
            (
                "shell-below",
                "the same shell seen from below",
                "filletfold round shell:8x6 --radius 15% --view=-60,-30 --format png",
            ),
        ],
    ),
]


def gallery_markdown() -> str:
    """The text of ``docs/gallery.md``."""
    lines = [
        "# Gallery",
        "",
        "The figures of the paper (Maleczek, Mundilova, Tachi, *Curved Crease Edge Rounding of "
        "Polyhedral Surfaces*) made again with filletfold. Every picture is the `preview.png` of "
        "the command under it (with `-o out/gallery/<name>`); "
        "`.venv/bin/python benchmarks/gallery.py` runs them all and writes this page.",
        "",
        "Colours: cones orange, cylinders blue, conical fillets teal, flat face pieces green (the "
        "back of a face darker); creases mountain red, valley blue; the sheet's outline black, "
        "seams between pieces grey. Faces and creases behind the surface are hidden.",
        "",
    ]
    for figure, title, text, pictures in FIGURES:
        lines += [f"## Fig. {figure}: {title}", "", text, ""]
        for name, caption, command in pictures:
            lines += [
                f"![{caption}](gallery/{name}.png)",
                "",
                f"{caption}:",
                "",
                "```",
                f"{command} -o out/gallery/{name}",
                "```",
                "",
            ]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs"))
    ap.add_argument("--only", nargs="*", default=None, help="picture names to make")
    args = ap.parse_args(argv)
    print(machine())
    out = Path(args.out)
    (out / "gallery").mkdir(parents=True, exist_ok=True)
    os.chdir(ROOT)  # the commands name examples/ relative to the root
    with tempfile.TemporaryDirectory() as tmp:
        for _, _, _, pictures in FIGURES:
            for name, _, command in pictures:
                if args.only is not None and name not in args.only:
                    continue
                words = shlex.split(command)
                assert words[0] == "filletfold"
                target = Path(tmp) / name
                t = time.perf_counter()
                with redirect_stdout(StringIO()):
                    code = cli_main([*words[1:], "-q", "-o", str(target)])
                seconds = time.perf_counter() - t
                if code != 0:
                    print(f"{name}: {command} exited {code}")
                    return 1
                picture = out / "gallery" / f"{name}.png"
                shutil.copyfile(target / "preview.png", picture)
                size = picture.stat().st_size
                print(f"{name:22s} {size / 1024:6.0f} KB {seconds:6.1f} s  {command}")
    (out / "gallery.md").write_text(gallery_markdown(), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
