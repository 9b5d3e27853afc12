"""The default command on a corpus of real meshes: what a new user gets.

Run from the repository root:

    .venv/bin/python benchmarks/corpus.py [PATH ...] [--timeout S] [--out DIR] [--json FILE]
                                          [-- extra 'filletfold round' options]

``PATH`` is a mesh file or a folder of them (default: ``tests/data/corpus``, the corpus that
ships with the tests; see its ``SOURCES.md``). Every mesh goes through ``filletfold round MESH
-o DIR`` in its own process, exactly as a user types it (nothing else unless given after
``--``), with a time limit. Prints the machine and the command, then one row per mesh: the
outcome (a design, or the one-line error), the cleaned mesh's vertices, the repairs made, the
edges whose radius was fitted and those left sharp, the vertices by status (ok, saddle,
infeasible, boundary, sharp) and rescued, whether the design's certificate holds, and the wall
time of the whole command. A traceback, a time-out or a multi-line error is a defect and is
listed at the end.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from examples import machine

from filletfold.mesh import SUPPORTED_EXTENSIONS

ROOT = Path(__file__).resolve().parent.parent
DEFAULT = ROOT / "tests" / "data" / "corpus"


def meshes(paths: list[str]) -> list[Path]:
    """The mesh files of ``paths`` (folders searched, sorted by name)."""
    out = []
    for p in map(Path, paths):
        if p.is_dir():
            out += sorted(
                f for f in p.iterdir() if f.is_file() and f.suffix.lower() in SUPPORTED_EXTENSIONS
            )
        else:
            out.append(p)
    return out


def run(mesh: Path, out: Path, timeout: float, extra: list[str]) -> dict:
    """Run ``filletfold round`` on one mesh; what happened, read from its report.json."""
    cmd = [sys.executable, "-m", "filletfold.cli", "round", str(mesh), "-o", str(out), "-q"]
    t = time.perf_counter()
    try:
        proc = subprocess.run(cmd + extra, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"mesh": mesh.name, "outcome": "timeout", "time": timeout}
    row = {"mesh": mesh.name, "time": time.perf_counter() - t, "rc": proc.returncode}
    err = [line for line in proc.stderr.splitlines() if line.strip()]
    report = out / "report.json"
    if "Traceback (most recent call last)" in proc.stderr:
        row["outcome"] = "traceback"
        row["message"] = err[-1] if err else ""
        return row
    if not report.is_file():
        row["outcome"] = "multiline" if len(err) > 1 else "error"
        row["message"] = err[-1].removeprefix("error: ") if err else f"exit {proc.returncode}"
        return row
    r = json.loads(report.read_text())
    counts = r["status_counts"]
    fit = r.get("fitting") or {}
    kinds: dict = {}
    for rep in r.get("repairs", []):
        kinds[rep["what"]] = kinds.get(rep["what"], 0) + 1
    cert = r.get("certificate")
    row.update(
        outcome="design",
        vertices=len(r["mesh"]["vertices"]),
        repairs=kinds,
        fitted=fit.get("radii_reduced", 0),
        sharp_edges=len(fit.get("sharp", [])),
        rescued=fit.get("vertices_rescued", 0),
        status=counts,
        certificate=None if cert is None else cert["ok"],
        failed=[] if cert is None else [k for k, v in cert["checks"].items() if not v["ok"]],
    )
    return row


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    extra = argv[argv.index("--") + 1 :] if "--" in argv else []
    argv = argv[: argv.index("--")] if "--" in argv else argv
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("paths", nargs="*", default=[str(DEFAULT)])
    ap.add_argument("--timeout", type=float, default=300.0)
    ap.add_argument("--out", help="folder for the designs (default: a temporary one)")
    ap.add_argument("--json", help="write the rows to this file")
    args = ap.parse_args(argv)
    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# each mesh: filletfold round MESH -o DIR {' '.join(extra)}".rstrip())
    head = (
        f"{'mesh':34s} {'V':>6s} {'repairs':>7s} {'fit':>5s} {'sharp':>5s} {'ok':>5s} "
        f"{'sad':>4s} {'inf':>4s} {'bnd':>4s} {'shp':>4s} {'resc':>4s} {'cert':>5s} {'s':>6s}"
    )
    print(head)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(args.out or tmp)
        for mesh in meshes(args.paths):
            row = run(mesh, base / mesh.stem, args.timeout, extra)
            rows.append(row)
            if row["outcome"] == "design":
                s = row["status"]
                cert = {None: "-", True: "ok", False: "FAIL"}[row["certificate"]]
                print(
                    f"{mesh.name[:34]:34s} {row['vertices']:6d} {sum(row['repairs'].values()):7d} "
                    f"{row['fitted']:5d} {row['sharp_edges']:5d} {s['ok']:5d} {s['saddle']:4d} "
                    f"{s['infeasible']:4d} {s['boundary']:4d} {s.get('sharp', 0):4d} "
                    f"{row['rescued']:4d} {cert:>5s} {row['time']:6.1f}",
                    flush=True,
                )
            else:
                print(
                    f"{mesh.name[:34]:34s} {row['outcome']}: {row.get('message', '')[:160]}",
                    flush=True,
                )
    designs = [r for r in rows if r["outcome"] == "design"]
    bad = [r for r in rows if r["outcome"] in ("traceback", "timeout", "multiline")]
    failing = [r for r in designs if r["certificate"] is False]
    print(
        f"# {len(rows)} meshes: {len(designs)} designs ({len(failing)} failing their "
        f"certificate), {sum(r['outcome'] == 'error' for r in rows)} one-line errors, "
        f"{len(bad)} defects (traceback, time-out or multi-line error)"
    )
    for r in failing:
        print(f"#   certificate fails: {r['mesh']}: {', '.join(r['failed'])}")
    for r in bad:
        print(f"#   {r['outcome']}: {r['mesh']}: {r.get('message', '')}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
