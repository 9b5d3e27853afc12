"""Issue 27's table: the default command on public real meshes, against an earlier commit.

    .venv/bin/python benchmarks/real_meshes.py --against REV [--repeat N] [--timeout S]
                                               [--json FILE] [cases...]
    .venv/bin/python benchmarks/real_meshes.py --against 0e9ac81 spot fox bunny /tmp/cow.obj

Each case is run as a user runs it, ``filletfold round MESH -o DIR`` in a fresh process, by
this checkout and by the commit ``REV`` (a ``git worktree`` of it, run with the same Python and
packages: its ``src`` first on the path), one after the other, ``--repeat`` times (default 3).
Per case it prints the medians of both: wall (from outside), the pipeline's stages (from
``timings.json``), the peak resident set (``os.wait4`` of the child), the bytes written, the
bytes per input vertex (goal of issue 27: 5 KB) and the ratio of the walls (REV / this: above
1 is faster now), with the machine and the command. A run over ``--timeout`` seconds is killed
and shown as such.

Cases: meshes of the public corpus (``benchmarks/corpus_manifest.json``, fetched into
``out/corpus-meshes`` by ``benchmarks/fetch_corpus.py``; licences there), as
``collection/name`` or by file stem, or mesh files. The default cases are real meshes of the
kinds and sizes issue 27 names: the 2,904-vertex animal scan ``pymeshlab/cow.obj``, the
2,930-vertex character ``spot``, a 5,051-vertex scan ``bunny10k_textured``, the 7,017-vertex
CAD-like ``airplane.obj``, the 7,526-vertex ``cube_noisy``, the 28,088-vertex scan
``pymeshlab/bunny.obj`` (56,172 triangles) and ``StanfordBunny`` (99,785 triangles).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from pipeline import folder_mb, machine, run_process  # noqa: E402

DEFAULT_CASES = (
    "pymeshlab/cow.obj",
    "geometry-central/spot.ply",
    "pymeshlab/bunny10k_textured.obj",
    "pymeshlab/airplane.obj",
    "openmesh/cube_noisy.off",
    "pymeshlab/bunny.obj",
    "pymeshfix/StanfordBunny.ply",
)
STAGES = ("read", "rounding", "normals", "apices", "surface", "tabs", "certificate", "export")


def corpus_files() -> dict[str, Path]:
    """Corpus meshes by file stem (and by file name), where fetched."""
    manifest = json.loads((HERE / "corpus_manifest.json").read_text())
    out = {}
    for item in manifest["meshes"]:
        local = ROOT / "out" / "corpus-meshes" / item["collection"] / item["name"]
        if local.is_file():
            out[f"{item['collection']}/{item['name']}"] = local
            out.setdefault(Path(item["name"]).stem, local)
    return out


def command(src: Path | None) -> list[str]:
    """The CLI of this checkout, or of the worktree whose ``src`` is given."""
    if src is None:
        script = Path(sys.executable).with_name("filletfold")
        return [str(script)] if script.is_file() else [sys.executable, "-m", "filletfold.cli"]
    boot = f"import sys; sys.path.insert(0, {str(src)!r}); from filletfold.cli import main; "
    return [sys.executable, "-c", boot + "sys.exit(main())"]


def one(cmd: list[str], mesh: str, out: Path, timeout: float) -> dict:
    r = run_process([*cmd, "round", mesh, "-o", str(out)], timeout)
    row = {"wall": r["wall"], "peak_mb": r["peak_mb"], "rc": r["rc"], "timeout": r["timeout"]}
    if r["rc"] != 0 or r["timeout"]:
        lines = [x for x in r["stderr"].splitlines() if x.strip()]
        row["error"] = "timeout" if r["timeout"] else (lines[-1] if lines else f"exit {r['rc']}")
    if (out / "timings.json").is_file():
        row["timings"] = json.loads((out / "timings.json").read_text())
    if (out / "report.json").is_file():
        rep = json.loads((out / "report.json").read_text())
        row["status"] = {k: v for k, v in rep.get("status_counts", {}).items() if v}
    if out.is_dir():
        row["out_mb"] = folder_mb(out)
        shutil.rmtree(out, ignore_errors=True)
    return row


def medians(runs: list[dict]) -> dict:
    good = [r for r in runs if "error" not in r]
    if not good:
        return {"error": runs[-1].get("error", "failed")}
    stages = {
        k: statistics.median(r["timings"].get(k, 0.0) for r in good)
        for k in STAGES
        if any(k in r.get("timings", {}) for r in good)
    }
    return {
        "wall": statistics.median(r["wall"] for r in good),
        "peak_mb": max(r["peak_mb"] for r in good),
        "out_mb": statistics.median(r.get("out_mb", 0.0) for r in good),
        "stages": stages,
        "status": good[-1].get("status"),
        "runs": len(good),
    }


def input_vertices(path: str) -> int | None:
    try:
        from filletfold.mesh import load_mesh

        return int(load_mesh(path)[0].n_vertices)
    except Exception:
        return None


def corpus_cases(names) -> list[tuple[str, Path]]:
    """``(name, file)`` of each of ``names``: a corpus mesh (``collection/name`` or file stem)
    or a mesh file; one not found is said so and left out."""
    known = corpus_files()
    cases = []
    for name in names:
        path = known.get(name) or (Path(name) if Path(name).is_file() else None)
        if path is None:
            print(f"# {name}: not found (run benchmarks/fetch_corpus.py, or give a file)")
            continue
        cases.append((name, path))
    return cases


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--against", required=True, help="the commit to compare with (git rev)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=1800.0)
    ap.add_argument("--json", help="write the results to this file")
    ap.add_argument("cases", nargs="*")
    args = ap.parse_args(argv)
    cases = [(name, str(path)) for name, path in corpus_cases(args.cases or DEFAULT_CASES)]
    rev = subprocess.run(
        ["git", "rev-parse", "--short", args.against], cwd=ROOT, capture_output=True, text=True
    ).stdout.strip()
    head = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True
    ).stdout.strip()
    if not rev:
        ap.error(f"{args.against}: not a commit of this repository")
    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# load average at start: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(
        f"# each run: filletfold round MESH -o DIR (defaults), a fresh process; this checkout "
        f"({head}, with its working tree) and {rev} one after the other; median of "
        f"{args.repeat} (peak: largest); KB/V: bytes written per input vertex"
    )
    results = {}
    with tempfile.TemporaryDirectory(prefix="filletfold-real-") as tmp:
        tmp = Path(tmp)
        worktree = tmp / "rev"
        subprocess.run(
            ["git", "worktree", "add", "--detach", str(worktree), rev],
            cwd=ROOT, check=True, capture_output=True,
        )  # fmt: skip
        try:
            head_line = (
                f"{'case':14s} {'V':>6s} | {'wall':>7s} {'peak MB':>7s} {'out MB':>7s} "
                f"{'KB/V':>6s} | {rev + ' wall':>12s} {'peak':>6s} {'out':>7s} | {'ratio':>5s}"
                f" | stages now (s): " + " ".join(STAGES)
            )
            print(head_line, flush=True)
            for name, path in cases:
                n_v = input_vertices(path)
                now, old = [], []
                for i in range(args.repeat):
                    old.append(one(command(worktree / "src"), path, tmp / f"o{i}", args.timeout))
                    now.append(one(command(None), path, tmp / f"n{i}", args.timeout))
                a, b = medians(now), medians(old)
                results[name] = {"vertices": n_v, "now": a, "rev": b, "path": path}
                print(row(name, n_v, a, b), flush=True)
        finally:
            subprocess.run(
                ["git", "worktree", "remove", "--force", str(worktree)],
                cwd=ROOT, capture_output=True,
            )  # fmt: skip
    print(f"# load average at end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    if args.json:
        doc = {"machine": machine(), "against": rev, "head": head, "cases": results}
        Path(args.json).write_text(json.dumps(doc, indent=1) + "\n")
    return 0


def row(name: str, n_v, a: dict, b: dict) -> str:
    def side(r, wide):
        if "error" in r:
            return f"{r['error'][:wide]:>{wide}s}"
        return None

    v = f"{n_v:6d}" if n_v else f"{'?':>6s}"
    left = side(a, 32) or (
        f"{a['wall']:7.1f} {a['peak_mb']:7.0f} {a['out_mb']:7.1f} "
        + (f"{1e3 * a['out_mb'] / n_v:6.1f}" if n_v else f"{'?':>6s}")
    )
    right = side(b, 27) or f"{b['wall']:12.1f} {b['peak_mb']:6.0f} {b['out_mb']:7.1f}"
    ratio = f"{b['wall'] / a['wall']:5.2f}" if "wall" in a and "wall" in b else f"{'-':>5s}"
    stages = " ".join(f"{a['stages'].get(s, 0):.1f}" for s in STAGES) if "stages" in a else ""
    return f"{name.split('/')[-1][:14]:14s} {v} | {left} | {right} | {ratio} | {stages}"


if __name__ == "__main__":
    sys.exit(main())
