"""Issue 29's table: filletfold beside Blender's Export Paper Model on three public meshes.

    .venv/bin/python benchmarks/paper_model.py [--repeat N] [--timeout S] [--json FILE]
                                               [--addon DIR] [--bpy-venv DIR] [--setup]
                                               [--size SIZE] [--keep DIR] [cases...]
    .venv/bin/python benchmarks/paper_model.py --setup     # first run: makes the bpy venv

Per mesh, both tools make a paper model printed on A4 at the same physical size, each run as a
fresh process, ``--repeat`` times (default 3, about 5 minutes in all on 2 cores: the 3k-vertex
scan takes about half a minute in each tool). Seconds are medians over the runs; the counts
are those of the run with the median (low) piece count: Paper Model's islands can differ from
one run to the next (its cut order breaks ties by the order of Python sets of its objects,
which follows memory addresses), filletfold's do not; the table marks a count that differed and
the notes give its range.

* filletfold, as a user runs it: ``filletfold round MESH --sheet A4 -o DIR`` (default layout,
  nets; the default size, the least buildable one, unless ``--size``). From ``DIR/report.json``:
  pieces (``pattern.pieces``), seams (``fabrication.cut_borders``: cut borders to glue), A4
  sheets (``fabrication.sheets``); seconds: the whole command's wall clock. Valid: ``filletfold
  check DIR`` exits 0, and every piece lies on one sheet: the bounding box of each piece's
  vertices (``design.fold``) inside one of the sheet rectangles of ``annotations.json``, every
  tab and label inside a sheet, and the count of pieces per sheet that of the report.
* Export Paper Model (Adam Dominec's add-on, GPL; bundled with Blender up to 4.1, an extension
  since 4.2, not in the ``bpy`` wheel), run headless by ``bpy`` from PyPI in its own virtualenv
  (``--bpy-venv``, default ``out/bpy-venv``; ``--setup`` makes it: ``python -m venv DIR`` and
  ``DIR/bin/python -m pip install bpy==BPY_VERSION``), the add-on's source taken from ``--addon``
  (default ``out/export_paper_model``: the add-on's folder, holding its ``__init__.py``, e.g. a
  copy of the repository ``addam/Export-Paper-Model-from-Blender``; it is not part of this
  repository). This file is also the Blender side (``--worker``, run by the venv's Python). In
  an empty scene it imports the mesh (Blender's PLY/OBJ/STL importer, defaults), and runs
  ``bpy.ops.export_mesh.paper_model`` as File > Export > Paper Model does: PDF, page A4, tabs and
  numbers on, no texture, every other option its default, except two a user printing at a given
  size sets: the model scale (Automatic Scale off, ``scale`` = 1000 / filletfold's mm per mesh
  unit, so the mesh's largest side is as long as in filletfold's design: ``parameters.scale`` of
  its report) and Limit Island Size on (else an island bigger than A4 stops the export). The
  limit is the A4 page's printable area less a tab's width on each side and the island's title
  (the add-on's own margin, tab width and title height: 190 x 271 mm); with the add-on's plain
  A4 limit (200 x 290 mm) its tabs and title can still push an island off the page, which stops
  the export with "An island is too big"; then the limit is shrunk by 10 % and the export run
  again (the attempts are shown). Figures from the add-on's own objects, by wrapping its PDF
  writer (``Pdf.write(mesh, path)``, called once the net is laid out): pieces = its islands,
  seams = mesh edges cut between two faces (each gets one tab), sheets = its pages (checked
  against the ``/Type /Page`` objects of the PDF it wrote); seconds: the operator's call (unfold,
  tabs, page layout, PDF; not Blender's start-up nor the import, shown apart as ``proc s``;
  the notes give the page layout's share).
  Valid: the export finished, and every island's box (faces, tabs, title) lies inside its page's
  printable area, no two boxes of a page overlapping (islands do not overlap themselves: the
  add-on joins faces only where they do not).

Printed: the machine (CPU, cores, Python, bpy), the command, one row per tool and mesh (mesh,
vertices in the file, tool, pieces, seams, A4 sheets, seconds, valid), then per mesh the ratios
ours / theirs of pieces and sheets against issue 29's goal (at most 1.5). Cases: the default
three, from the public corpus (``benchmarks/corpus_manifest.json``, fetched into
``out/corpus-meshes`` by ``benchmarks/fetch_corpus.py``; licences there, and printed): the
Stanford bunny ``bun_zipper_res4.ply`` (453 vertices, a scan), ``spot.ply`` (2,930 vertices,
a scan-like character) and ``pyvista/nut.ply`` (a hex nut, a CAD part: 523 vertices, 1,046
triangles), or ``collection/name``, file stems or mesh files. Caveats: Paper Model's page layout
is a branch and bound with a 15 s time limit, so its page count can change with the machine's
speed; filletfold's cut borders are the borders of its rounded pieces (straight and curved
segments), not mesh edges.
"""

from __future__ import annotations

import argparse
import atexit
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

DEFAULT_CASES = ("meshio/bun_zipper_res4.ply", "geometry-central/spot.ply", "pyvista/nut.ply")
BPY_VERSION = "4.5.15"
ADDON_MODULE = "export_paper_model"
RESULT = "PAPER_MODEL_RESULT "
A4 = (0.210, 0.297)  # m
UNIT_M = {"mm": 1e-3, "cm": 1e-2, "m": 1.0, "in": 0.0254}
GOAL = 1.5

# --------------------------------------------------------------------------------------------
# The Blender side: run by the bpy venv's Python as ``paper_model.py --worker ARGS_JSON``.
# Only the standard library and bpy here.


def _enable_addon(addon_dir: Path):
    """Enable the add-on from its folder, whatever the folder's name."""
    import addon_utils
    import bpy

    link_dir = Path(tempfile.mkdtemp(prefix="paper-model-addon-"))
    atexit.register(shutil.rmtree, link_dir, True)
    (link_dir / ADDON_MODULE).symlink_to(addon_dir.resolve(), target_is_directory=True)
    sys.path.insert(0, str(link_dir))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    mod = addon_utils.enable(ADDON_MODULE, default_set=True, handle_error=None)
    if mod is None or not hasattr(bpy.ops.export_mesh, "paper_model"):
        raise SystemExit(f"the add-on in {addon_dir} did not register export_mesh.paper_model")
    return mod


def _import_mesh(path: str):
    import bpy

    ext = Path(path).suffix.lower()
    importers = {".ply": "ply_import", ".obj": "obj_import", ".stl": "stl_import"}
    if ext not in importers:
        raise SystemExit(f"{path}: Blender imports {', '.join(importers)} here, not {ext}")
    before = set(bpy.data.objects)
    getattr(bpy.ops.wm, importers[ext])(filepath=path)
    new = [ob for ob in bpy.data.objects if ob not in before and ob.type == "MESH"]
    if len(new) != 1:
        raise SystemExit(f"{path}: imported {len(new)} mesh objects, expected 1")
    ob = new[0]
    for other in bpy.context.view_layer.objects:
        other.select_set(other is ob)
    bpy.context.view_layer.objects.active = ob
    return ob


def _largest_side(ob) -> float:
    coords = [ob.matrix_world @ v.co for v in ob.data.vertices]
    return max(max(c[i] for c in coords) - min(c[i] for c in coords) for i in range(3))


def _net_figures(mesh, printable) -> dict:
    """Counts and placement checks from the add-on's Mesh, once its islands are on pages."""
    from importlib import import_module

    unfolder = import_module(f"{ADDON_MODULE}.unfolder")
    seams = sum(1 for e in mesh.edges.values() if e.is_main_cut and len(e.uvedges) >= 2)
    tabs = sum(isinstance(m, unfolder.Sticker) for island in mesh.islands for m in island.markers)
    tol = 1e-6  # m: Blender packs the boxes in single precision
    off, overlaps = [], 0
    for p, page in enumerate(mesh.pages):
        boxes = []
        for island in page.islands:
            x0, y0 = island.pos.x, island.pos.y
            x1, y1 = x0 + island.bounding_box.x, y0 + island.bounding_box.y
            if x0 < -tol or y0 < -tol or x1 > printable[0] + tol or y1 > printable[1] + tol:
                off.append(f"{island.label} on page {p + 1}")
            boxes.append((x0, y0, x1, y1))
        for i, a in enumerate(boxes):
            for b in boxes[i + 1 :]:
                if (
                    min(a[2], b[2]) - max(a[0], b[0]) > tol
                    and min(a[3], b[3]) - max(a[1], b[1]) > tol
                ):
                    overlaps += 1
    placed = sum(len(page.islands) for page in mesh.pages)
    return {
        "islands": len(mesh.islands),
        "pages": len(mesh.pages),
        "seams": seams,
        "tabs": tabs,
        "faces": sum(len(island.faces) for island in mesh.islands),
        "islands_per_page": [len(page.islands) for page in mesh.pages],
        "placed": placed,
        "off_page": off,
        "box_overlaps": overlaps,
        "largest_box_mm": [
            round(1e3 * max(i.bounding_box.x for i in mesh.islands), 1),
            round(1e3 * max(i.bounding_box.y for i in mesh.islands), 1),
        ],
    }


def worker(args: dict) -> dict:
    """Import ``args['mesh']`` into an empty scene and export its paper model on A4."""
    import bpy

    mod = _enable_addon(Path(args["addon"]))
    ops = sys.modules[f"{ADDON_MODULE}.unfold_operator"]
    unfolder = sys.modules[f"{ADDON_MODULE}.unfolder"]
    ob = _import_mesh(args["mesh"])
    out = {
        "bpy": bpy.app.version_string,
        "addon_version": ".".join(map(str, mod.bl_info["version"])),
        "vertices": len(ob.data.vertices),
        "faces": len(ob.data.polygons),
        "largest_side_mm": 1e3 * _largest_side(ob) / args["scale"],
        "scale": args["scale"],
    }
    seen = {}
    write = ops.Pdf.write

    def recording_write(self, mesh, filename):
        seen.update(_net_figures(mesh, self.page_size - 2 * self.margin))
        return write(self, mesh, filename)

    ops.Pdf.write = recording_write
    paginate = unfolder.paginate_islands  # the page layout (a 15 s branch and bound at most)

    def timed_paginate(*a, **k):
        t = time.perf_counter()
        pages = paginate(*a, **k)
        seen["nest_seconds"] = time.perf_counter() - t
        return pages

    unfolder.paginate_islands = timed_paginate
    settings = bpy.context.scene.paper_model
    settings.use_auto_scale = False
    settings.scale = args["scale"]
    settings.limit_by_page = True
    settings.page_size_preset = "USER"
    margin, tab = 0.005, 0.005  # the operator's defaults: output_margin, sticker_width
    limit = [A4[0] - 2 * margin - 2 * tab, A4[1] - 2 * margin - 2 * tab - 1.2 * tab]
    attempts = []
    pdf = Path(args["out"]) / "paper_model.pdf"
    for _ in range(8):
        settings.output_size_x, settings.output_size_y = limit
        seen.clear()
        t = time.perf_counter()
        try:
            r = bpy.ops.export_mesh.paper_model(
                filepath=str(pdf), page_size_preset="A4", scale=args["scale"]
            )
            error = None if r == {"FINISHED"} else f"operator returned {sorted(r)}"
        except RuntimeError as e:
            error = str(e).strip().splitlines()[0]
        attempts.append(
            {"limit_mm": [round(1e3 * x, 1) for x in limit], "seconds": time.perf_counter() - t}
        )
        if error is None:
            break
        attempts[-1]["error"] = error
        if "too big" not in error:
            break
        limit = [0.9 * x for x in limit]
    out.update(seen)
    out["attempts"] = attempts
    out["seconds"] = attempts[-1]["seconds"]
    out["error"] = attempts[-1].get("error")
    if out["error"] is None:
        out["pdf_pages"] = len(re.findall(rb"/Type /Page\n", pdf.read_bytes()))
    return out


# --------------------------------------------------------------------------------------------
# The benchmark side: run by filletfold's Python.


def bpy_python(venv: Path, setup: bool) -> Path:
    py = venv / "bin" / "python"
    make = [
        [sys.executable, "-m", "venv", str(venv)],
        [str(py), "-m", "pip", "install", f"bpy=={BPY_VERSION}"],
    ]
    if not py.is_file() or subprocess.run([py, "-c", "import bpy"], capture_output=True).returncode:
        if not setup:
            cmds = " && ".join(" ".join(c) for c in make)
            raise SystemExit(f"no bpy in {venv}: rerun with --setup, or make it with:\n  {cmds}")
        for cmd in make[0 if not py.is_file() else 1 :]:
            print(f"# setup: {' '.join(cmd)}", flush=True)
            subprocess.run(cmd, check=True)
    return py


def corpus(names) -> tuple[list[tuple[str, Path]], dict[str, dict]]:
    """The cases ``names`` (corpus meshes or files) as ``(name, file)``, and the corpus
    collections (with their licences) by name."""
    sys.path.insert(0, str(HERE))  # not at the top: the Blender worker has no filletfold
    from real_meshes import corpus_cases

    manifest = json.loads((HERE / "corpus_manifest.json").read_text())
    cases = [(name, path.resolve()) for name, path in corpus_cases(names)]
    return cases, {c["collection"]: c for c in manifest["collections"]}


def file_vertices(path: Path) -> int | None:
    """The vertex count a PLY header declares (or the OBJ's ``v`` lines); None otherwise."""
    if path.suffix.lower() == ".ply":
        with open(path, "rb") as f:
            for line in f:
                if line.startswith(b"element vertex"):
                    return int(line.split()[2])
                if line.startswith(b"end_header"):
                    break
    if path.suffix.lower() == ".obj":
        with open(path, "rb") as f:
            return sum(1 for line in f if line.startswith(b"v "))
    return None


def pieces_on_sheets(out: Path, report: dict) -> list[str]:
    """Problems with the placement of filletfold's pieces on its sheets (none: all on one)."""
    design = json.loads((out / "design.fold").read_text())
    notes = json.loads((out / "annotations.json").read_text())
    sheets = notes.get("sheets") or []
    fab = report["fabrication"]
    if len(sheets) != fab.get("sheets"):
        return [f"{len(sheets)} sheet rectangles for {fab.get('sheets')} sheets"]
    coords = design["vertices_coords"]
    boxes: dict[int, list[float]] = {}
    faces = zip(design["faces_vertices"], design["filletfold:faces_piece"], strict=True)
    for face, piece in faces:
        box = boxes.setdefault(piece, [float("inf"), float("inf"), -float("inf"), -float("inf")])
        for v in face:
            x, y = coords[v][:2]
            box[0], box[1] = min(box[0], x), min(box[1], y)
            box[2], box[3] = max(box[2], x), max(box[3], y)
    tol = 1e-9 * max(s[2] - s[0] for s in sheets)

    def sheet_of(x0, y0, x1, y1) -> int | None:
        for i, (a, b, c, d) in enumerate(sheets):
            if x0 >= a - tol and y0 >= b - tol and x1 <= c + tol and y1 <= d + tol:
                return i
        return None

    problems, counts = [], [0] * len(sheets)
    for piece, box in sorted(boxes.items()):
        i = sheet_of(*box)
        if i is None:
            problems.append(f"piece {piece} on no sheet")
        else:
            counts[i] += 1
    for t, tab in enumerate(notes.get("tabs") or []):
        xs, ys = [p[0] for p in tab], [p[1] for p in tab]
        if sheet_of(min(xs), min(ys), max(xs), max(ys)) is None:
            problems.append(f"tab {t} on no sheet")
    for k, (x, y) in enumerate((notes.get("labels") or {}).get("position") or []):
        if sheet_of(x, y, x, y) is None:
            problems.append(f"label {k} on no sheet")
    if len(boxes) != report["pattern"]["pieces"]:
        problems.append(
            f"{len(boxes)} pieces in design.fold, {report['pattern']['pieces']} reported"
        )
    if counts != list(fab.get("pieces_per_sheet") or []):
        problems.append(f"pieces per sheet {counts}, reported {fab.get('pieces_per_sheet')}")
    return problems


def run_filletfold(mesh: Path, out: Path, size: str | None, timeout: float) -> dict:
    from pipeline import filletfold_cli, run_process

    cmd = [*filletfold_cli(), "round", str(mesh), "--sheet", "A4", "-o", str(out)]
    cmd += ["--size", size] if size else []
    r = run_process(cmd, timeout)
    row = {"seconds": r["wall"], "peak_mb": r["peak_mb"]}
    if r["rc"] != 0 or r["timeout"]:
        lines = [x for x in r["stderr"].splitlines() if x.strip()]
        row["error"] = "timeout" if r["timeout"] else (lines[-1] if lines else f"exit {r['rc']}")
        return row
    report = json.loads((out / "report.json").read_text())
    fab, par = report["fabrication"], report["parameters"]
    check = subprocess.run([*filletfold_cli(), "check", str(out)], capture_output=True, text=True)
    placement = pieces_on_sheets(out, report)
    row.update(
        pieces=report["pattern"]["pieces"],
        seams=fab["cut_borders"],
        sheets=fab.get("sheets"),
        tabs=fab.get("tabs"),
        pieces_per_sheet=fab.get("pieces_per_sheet"),
        size=par.get("size"),
        units=par.get("units"),
        mm_per_unit=par["scale"] * UNIT_M[par["units"]] * 1e3,
        mesh_vertices=report["mesh_counts"]["vertices"],
        check_rc=check.returncode,
        check_last=(check.stdout.strip().splitlines() or [""])[-1],
        placement=placement,
        valid=check.returncode == 0 and not placement,
    )
    return row


def run_paper_model(py: Path, addon: Path, mesh: Path, out: Path, scale: float, timeout: float):
    from pipeline import run_process

    args = {"addon": str(addon), "mesh": str(mesh), "out": str(out), "scale": scale}
    out.mkdir(parents=True, exist_ok=True)
    r = run_process([str(py), str(Path(__file__).resolve()), "--worker", json.dumps(args)], timeout)
    lines = [x for x in r["stdout"].splitlines() if x.startswith(RESULT)]
    if r["timeout"] or not lines:
        tail = [x for x in (r["stderr"] + r["stdout"]).splitlines() if x.strip()]
        return {"error": "timeout" if r["timeout"] else (tail[-1] if tail else f"exit {r['rc']}")}
    row = json.loads(lines[-1][len(RESULT) :])
    row["proc_seconds"] = r["wall"]
    row["peak_mb"] = r["peak_mb"]
    if row.get("error") is None:
        row["valid"] = (
            not row["off_page"]
            and not row["box_overlaps"]
            and row["placed"] == row["islands"]
            and row["pdf_pages"] == row["pages"]
        )
    return row


def summary(runs: list[dict], counts: tuple[str, ...]) -> dict:
    """The runs of one tool on one mesh: the counts and details of the run with the median
    (low) piece count, the median seconds; ``spread``: the counts that differed, (least, most)."""
    good = [r for r in runs if r.get("error") is None]
    if not good:
        return {"error": runs[-1].get("error", "failed"), "runs": 0, "failed": len(runs)}
    pieces = [r.get("pieces", r.get("islands")) for r in good]
    out = dict(good[pieces.index(statistics.median_low(pieces))])
    for k in ("seconds", "proc_seconds", "nest_seconds"):
        if k in out:
            out[k] = statistics.median(r[k] for r in good)
    out["spread"] = {}
    for k in counts:
        values = [r[k] for r in good if k in r]
        if values and min(values) != max(values):
            out["spread"][k] = (min(values), max(values))
    out["valid"] = all(r.get("valid") for r in good) and len(good) == len(runs)
    out["runs"], out["failed"] = len(good), len(runs) - len(good)
    return out


def table_row(name: str, n_v, tool: str, r: dict) -> str:
    v = f"{n_v:6d}" if n_v else f"{'?':>6s}"
    if "pieces" not in r and "islands" not in r:
        return f"{name:18s} {v} {tool:12s} error: {r.get('error')}"
    spread = r.get("spread", {})

    def count(*keys) -> str:
        key = next(k for k in keys if k in r)
        return f"{r[key]:6d}{'*' if key in spread else ' '}"

    proc = f"{r['proc_seconds']:7.1f}" if "proc_seconds" in r else f"{'':7s}"
    return (
        f"{name:18s} {v} {tool:12s} {count('pieces', 'islands')}{count('seams')}"
        f"{count('sheets', 'pages')}{r['seconds']:8.1f} {proc} "
        f"{'yes' if r.get('valid') else 'NO':>5s}"
    )


def main(argv=None) -> int:
    if argv is None and len(sys.argv) > 2 and sys.argv[1] == "--worker":
        print(RESULT + json.dumps(worker(json.loads(sys.argv[2]))), flush=True)
        return 0
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases", nargs="*", help="corpus meshes (collection/name or stem) or files")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=1800.0)
    ap.add_argument("--json", help="write the results to this file")
    ap.add_argument("--addon", default=str(ROOT / "out" / ADDON_MODULE),
                    help="the Export Paper Model add-on's folder (its __init__.py)")  # fmt: skip
    ap.add_argument("--bpy-venv", default=str(ROOT / "out" / "bpy-venv"),
                    help="virtualenv with bpy (never filletfold's own)")  # fmt: skip
    ap.add_argument("--setup", action="store_true", help=f"make --bpy-venv (bpy=={BPY_VERSION})")
    ap.add_argument("--size", help="filletfold's --size (default: its least buildable size)")
    ap.add_argument("--keep", help="keep both tools' outputs in this folder")
    args = ap.parse_args(argv)

    addon = Path(args.addon)
    if not (addon / "__init__.py").is_file() or not (addon / "unfold_operator.py").is_file():
        ap.error(
            f"--addon {addon}: no Export Paper Model add-on there (a folder with __init__.py and "
            "unfold_operator.py, e.g. a copy of the repository "
            "addam/Export-Paper-Model-from-Blender; GPL, kept out of this repository)"
        )
    py = bpy_python(Path(args.bpy_venv), args.setup)
    bpy_version = subprocess.run(
        [py, "-c", "import bpy; print(bpy.app.version_string)"], capture_output=True, text=True
    ).stdout.strip()
    cases, collections = corpus(args.cases or DEFAULT_CASES)

    sys.path.insert(0, str(HERE))
    from examples import machine

    commit = addon / "COMMIT"
    addon_from = f" (commit {commit.read_text().strip()[:12]})" if commit.is_file() else ""
    print(f"# machine: {machine()}; bpy {bpy_version} in {args.bpy_venv}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# add-on: Export Paper Model from {addon}{addon_from}")
    print(f"# load average at start: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    size = f" --size {args.size}" if args.size else ""
    print(
        f"# filletfold: filletfold round MESH --sheet A4 -o DIR{size} (seconds: the command's "
        "wall; valid: 'filletfold check' exits 0 and every piece, tab and label on a sheet)"
    )
    print(
        "# paper model: export_mesh.paper_model, PDF on A4, scale matched to filletfold's size, "
        "Limit Island Size on (seconds: the operator; proc s: Blender's process with start-up "
        "and import; valid: exported, every island box on its page's printable area, none "
        "overlapping)"
    )
    print(
        f"# runs per tool and mesh: {args.repeat} (seconds: median; counts: the run with the "
        "median piece count; *: this count differed between runs, its range in the notes)"
    )
    head = (
        f"{'mesh':18s} {'V':>6s} {'tool':12s} {'pieces':>6s}  {'seams':>6s}  {'A4':>6s} "
        f"{'seconds':>8s} {'proc s':>7s} {'valid':>5s}"
    )
    print(head, flush=True)
    results = {}
    keys = ("pieces", "islands", "seams", "sheets", "pages", "tabs")
    with tempfile.TemporaryDirectory(prefix="filletfold-paper-model-") as tmp:
        base = Path(args.keep) if args.keep else Path(tmp)
        for name, path in cases:
            stem = path.stem
            n_v = file_vertices(path)
            ours, theirs = [], []
            for i in range(args.repeat):
                ours.append(
                    run_filletfold(path, base / f"{stem}-filletfold-{i}", args.size, args.timeout)
                )
                if "error" in ours[-1]:
                    break
                scale = 1e3 / ours[-1]["mm_per_unit"]  # Paper Model divides Blender's metres by it
                pm_out = base / f"{stem}-paper-model-{i}"
                theirs.append(run_paper_model(py, addon, path, pm_out, scale, args.timeout))
            a = summary(ours, keys)
            b = summary(theirs, keys) if theirs else {"error": "not run (filletfold failed)"}
            label = Path(name).stem[:18]
            print(table_row(label, n_v, "filletfold", a))
            print(table_row(label, n_v, "paper model", b), flush=True)
            results[name] = {"path": str(path), "vertices": n_v, "filletfold": a, "paper_model": b}
        print()
        print(
            f"{'mesh':18s} {'size':>7s} {'PM side':>8s} {'pieces ours/theirs':>19s} "
            f"{'sheets ours/theirs':>19s}  goal <= {GOAL} | notes"
        )
        ok_all = True
        for name, r in results.items():
            a, b = r["filletfold"], r["paper_model"]
            if "pieces" not in a or "islands" not in b:
                print(f"{Path(name).stem[:18]:18s} no ratio: {a.get('error') or b.get('error')}")
                ok_all = False
                continue
            rp, rs = a["pieces"] / b["islands"], a["sheets"] / b["pages"]
            ok = rp <= GOAL and rs <= GOAL and a["valid"] and b["valid"]
            ok_all &= ok
            nest = f", page layout {b['nest_seconds']:.1f} s" if "nest_seconds" in b else ""
            notes = [
                f"filletfold mesh {a['mesh_vertices']} V, {a['tabs']} tabs, pieces/sheet "
                f"{a['pieces_per_sheet']}",
                f"PM {b['vertices']} V {b['faces']} F, {b['tabs']} tabs, islands/page "
                f"{b['islands_per_page']}, limit {b['attempts'][-1]['limit_mm']} mm"
                + nest
                + (f" after {len(b['attempts'])} tries" if len(b["attempts"]) > 1 else ""),
            ]
            for tool, x in (("filletfold", a), ("PM", b)):
                if x["spread"] or x["failed"]:
                    ranges = ", ".join(f"{k} {lo}-{hi}" for k, (lo, hi) in x["spread"].items())
                    failed = f", {x['failed']} failed" if x["failed"] else ""
                    notes.append(f"{tool} over {x['runs']} runs: {ranges}{failed}")
            if a["placement"]:
                notes.append("placement: " + "; ".join(a["placement"][:3]))
            if b["box_overlaps"]:
                notes.append(f"PM: {b['box_overlaps']} pairs of island boxes overlap")
            if b["off_page"]:
                notes.append("PM off page: " + "; ".join(b["off_page"][:3]))
            print(
                f"{Path(name).stem[:18]:18s} {a['size']:>7s} {b['largest_side_mm']:6.0f}mm "
                f"{a['pieces']:>7d}/{b['islands']:<4d}={rp:5.2f} {a['sheets']:>7d}/{b['pages']:<4d}"
                f"={rs:5.2f}  {'met' if ok else 'NOT met':>8s} | " + "; ".join(notes)
            )
        print(f"# issue 29's goal on every mesh: {'met' if ok_all else 'NOT met'}")
        licences = []
        for r in results.values():
            coll = next((c for c in collections if f"/{c}/" in r["path"]), None)
            if coll:
                c = collections[coll]
                licences.append(f"{Path(r['path']).name}: {c['license']} ({c['package']})")
        if licences:
            print("# meshes: " + "; ".join(licences))
    print(f"# load average at end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    if args.json:
        doc = {"machine": machine(), "bpy": bpy_version, "cases": results}
        Path(args.json).write_text(json.dumps(doc, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
