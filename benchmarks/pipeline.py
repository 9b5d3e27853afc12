"""What a user waits for: ``filletfold round MESH -o DIR``, from outside and stage by stage.

    .venv/bin/python benchmarks/pipeline.py [--repeat N] [--max-faces F] [--timeout S]
                                            [--no-tabs] [--format FMT] [--arc-step DEG]
                                            [--api] [--json FILE] [cases...] [-- CLI OPTIONS]
    .venv/bin/python benchmarks/pipeline.py --max-faces 100000 --repeat 1   # the big run
    .venv/bin/python benchmarks/pipeline.py --no-tabs --format fold,json    # as before issue 14

Every run of a case is a fresh process running the command line as a user does:
``filletfold round MESH -o DIR`` with no other option (the CLI's defaults: glue tabs, the
default formats, layout ``auto``), plus ``--no-tabs``, ``--format FMT``, ``--arc-step DEG`` and
whatever follows ``--`` when given. Per run:

* ``wall``: the process's wall clock, measured from outside (start-up and imports, the
  pipeline, the summary, writing the files);
* the stages, from the ``timings.json`` the CLI writes into ``DIR`` (read, rounding,
  normals, apices, surface, certificate, their ``total``, and ``export``: the files written
  before ``timings.json``; a ``tabs`` stage and its share of ``total`` when the CLI reports
  one; only when ``json`` is among the formats, as by default);
* ``rest``: ``wall - total - export`` (start-up, summary, the last writes);
* ``peak``: the largest resident set of the process (``ru_maxrss`` of ``os.wait4``, taken by
  a small launcher process so that it is this child's alone, interpreter and imports included,
  not the benchmark's).

A case's figures are the medians over ``--repeat`` runs (peak: the largest); a run over
``--timeout`` seconds is killed and the case noted; a run that fails is shown with the CLI's
one-line message. ``ms/V`` is the pipeline ``total`` per vertex of the design's mesh (as
cleaned, from ``report.json``); ``x cube`` is the case's wall over the wall of the baseline
``filletfold round cube -o DIR`` (same options) run first, beside ``python -c "import
filletfold"`` (start-up alone).

Cases, each skipped when its input has more than ``--max-faces`` faces (default 600: a few
minutes on 2 cores):

* ``geodesic-3`` .. ``geodesic-6``: ``geodesic-sphere:level=3..6`` (1280, 5120, 20480, 81920
  triangles, convex, every vertex a cone);
* ``hull-1k``, ``hull-10k``, ``hull-50k``: convex hulls (``trimesh.convex.convex_hull``) of
  1000, 10000, 50000 points uniform on the unit sphere (seed ``SEED``; 1996, 19996, 99996
  irregular triangles);
* ``bunny``: ``examples/bunny-lowres.obj`` (200 triangles) and ``bunny-loop1``, ``bunny-loop2``:
  it Loop-subdivided once and twice (``trimesh.remesh.subdivide_loop``; 800, 3200 triangles);
* the corpus of real meshes, ``tests/data/corpus`` (see its ``SOURCES.md``), by file stem,
  and each readable one Loop-subdivided once and twice (``-loop1``, ``-loop2``; polygons
  fanned into triangles, a triangle soup's corners joined first).

Generated meshes are written as OBJ files into ``benchmarks/.cache`` (git-ignored) once and
reused. A case may also be any mesh file or built-in example spec (``miura:20x20``).
``--api``: the measurement before issue 14 instead, ``round_mesh`` + ``export_design`` timed
inside a child process (no start-up), with the CLI's defaults.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
BUNNY = ROOT / "examples" / "bunny-lowres.obj"
CORPUS = ROOT / "tests" / "data" / "corpus"
CACHE = HERE / ".cache"
SEED = 14  # the points of the hulls (issue 14)
GENERATOR = "1"  # bump when the generated meshes change, so cached files are rebuilt
STAGES = ["read", "rounding", "normals", "apices", "surface", "certificate", "tabs"]
HEADS = {"rounding": "round", "normals": "normal", "certificate": "cert"}
KNOWN = {*STAGES, "total", "export"}
BASELINE = "cube"


# --------------------------------------------------------------------------- meshes
def loop_subdivided(path, iterations: int):
    """(vertices, triangles) of the mesh file ``path`` Loop-subdivided ``iterations`` times.

    Polygons are fanned into triangles; corners at the same point are joined first (an STL
    file is a soup of separate triangles), and triangles that collapse are dropped.
    """
    import numpy as np
    from trimesh.remesh import subdivide_loop

    from filletfold.mesh import read_mesh

    v, faces = read_mesh(path)
    v = np.asarray(v, float)
    tris = np.array(
        [[f[0], f[i], f[i + 1]] for f in faces for i in range(1, len(f) - 1)], dtype=np.int64
    ).reshape(-1, 3)
    unique, inverse = np.unique(v, axis=0, return_inverse=True)
    if len(unique) < len(v):
        v, tris = unique, inverse.reshape(-1)[tris]
        tris = tris[
            (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 2] != tris[:, 0])
        ]
    return subdivide_loop(v, tris, iterations)


def sphere_hull(n_points: int, seed: int = SEED):
    """(vertices, triangles) of the convex hull of ``n_points`` uniform on the unit sphere."""
    import numpy as np
    import trimesh

    p = np.random.default_rng(seed).normal(size=(n_points, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    hull = trimesh.convex.convex_hull(p)
    return np.asarray(hull.vertices, float), np.asarray(hull.faces, np.int64)


def case_mesh(spec: str):
    """The mesh argument of ``round_mesh`` for ``spec`` (``bunny``, ``bunny-loopK`` or a
    built-in example spec), built in memory (``benchmarks/ipm_kernel.py`` uses it)."""
    if spec == "bunny":
        return str(BUNNY)
    if spec.startswith("bunny-loop"):
        return loop_subdivided(BUNNY, int(spec.removeprefix("bunny-loop")))
    from filletfold.mesh import example_mesh

    return example_mesh(spec)


def write_obj(path: Path, vertices, faces) -> None:
    """Write an OBJ file with every coordinate exact (``repr`` of the float), atomically."""
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in vertices.tolist()]
    lines += ["f " + " ".join(str(i + 1) for i in f) for f in faces.tolist()]
    tmp = path.with_suffix(".tmp")
    tmp.write_text("\n".join(lines) + "\n")
    os.replace(tmp, path)


def cached(name: str, key: str, build) -> str:
    """The path of the cached OBJ file of a generated mesh, built by ``build()`` if missing.

    ``key`` identifies the content (generator version, parameters, source bytes, trimesh
    version), so a changed source or generator gives a new file.
    """
    import trimesh

    digest = hashlib.sha1(f"{GENERATOR} {trimesh.__version__} {key}".encode()).hexdigest()
    path = CACHE / f"{name}-{digest[:10]}.obj"
    if not path.is_file():
        CACHE.mkdir(exist_ok=True)
        write_obj(path, *build())
    return str(path)


@dataclass
class Case:
    name: str
    faces: int | None  # faces of the input, known before it is built (None: unreadable)
    mesh: object  # () -> the MESH argument of the CLI (a path or a built-in spec)


def file_counts(path: Path) -> tuple[int | None, int | None]:
    """(faces, triangles once fanned) of a mesh file as filletfold reads it; (None, None)
    when it cannot be read (the case then shows the CLI's error)."""
    from filletfold.mesh import read_mesh

    try:
        _, faces = read_mesh(path)
    except Exception:
        return None, None
    return len(faces), sum(len(f) - 2 for f in faces)


def subdivisions(stem: str, path: Path, triangles: int) -> list[Case]:
    source = hashlib.sha1(path.read_bytes()).hexdigest()
    return [
        Case(
            f"{stem}-loop{k}",
            triangles * 4**k,
            lambda k=k: cached(
                f"{stem}-loop{k}", f"loop {k} {source}", lambda: loop_subdivided(path, k)
            ),
        )
        for k in (1, 2)
    ]


def all_cases() -> list[Case]:
    cases = [
        Case(f"geodesic-{lv}", 20 * 4**lv, lambda lv=lv: f"geodesic-sphere:level={lv}")
        for lv in (3, 4, 5, 6)
    ]
    for n, label in ((1000, "1k"), (10000, "10k"), (50000, "50k")):
        name = f"hull-{label}"
        cases.append(
            Case(
                name,
                2 * n - 4,  # every point is on the hull: a triangulated sphere
                lambda n=n, name=name: cached(
                    name, f"hull {n} seed {SEED}", lambda: sphere_hull(n)
                ),
            )
        )
    from filletfold.mesh import SUPPORTED_EXTENSIONS

    faces, tris = file_counts(BUNNY)
    cases.append(Case("bunny", faces, lambda: str(BUNNY)))
    cases += subdivisions("bunny", BUNNY, tris)
    for path in sorted(CORPUS.iterdir()):
        if path.suffix.lower() not in SUPPORTED_EXTENSIONS:
            continue
        faces, tris = file_counts(path)
        cases.append(Case(path.stem, faces, lambda path=path: str(path)))
        if faces:
            cases += subdivisions(path.stem, path, tris)
    return cases


def extra_case(spec: str) -> Case:
    """A case for a mesh file or built-in example spec named on the command line."""
    path = Path(spec)
    if path.is_file():
        return Case(path.name, file_counts(path)[0], lambda: str(path.resolve()))
    from filletfold.mesh import example_mesh

    try:
        faces = len(example_mesh(spec)[1])
    except Exception as exc:
        raise ValueError(str(exc).splitlines()[0]) from None
    return Case(spec, faces, lambda: spec)


# --------------------------------------------------------------------------- running
# Runs the command in a child of its own and reports on it: a tiny process started for every
# run, so that the child's ru_maxrss is its own. (A child forked from the benchmark itself counts
# the benchmark's resident set at the fork, or with vfork, as subprocess does, the benchmark's
# peak: the meshes it generated.) argv: result file, timeout in seconds, the command.
LAUNCHER = """
import json, os, signal, sys, time
result, timeout, cmd = sys.argv[1], float(sys.argv[2]), sys.argv[3:]
t = time.perf_counter()
pid = os.fork()
if pid == 0:
    try:
        os.execvp(cmd[0], cmd)
    finally:
        os._exit(127)
killed = []
def kill(*_):
    killed.append(1)
    os.kill(pid, signal.SIGKILL)
signal.signal(signal.SIGALRM, kill)
signal.setitimer(signal.ITIMER_REAL, timeout)
os.waitid(os.P_PID, pid, os.WEXITED | os.WNOWAIT)  # exited, not reaped: still pid's
wall = time.perf_counter() - t
signal.setitimer(signal.ITIMER_REAL, 0)
_, status, ru = os.wait4(pid, 0)
with open(result, "w") as f:
    json.dump({"wall": wall, "rc": os.waitstatus_to_exitcode(status), "timeout": bool(killed),
               "maxrss": ru.ru_maxrss, "cpu": ru.ru_utime + ru.ru_stime}, f)
"""


def run_process(cmd: list[str], timeout: float) -> dict:
    """Run ``cmd``; its wall clock, exit code, rusage figures and output.

    The figures come from ``os.wait4`` in :data:`LAUNCHER`, so they are the child's alone
    (peak resident set, CPU seconds). Killed after ``timeout`` seconds.
    """
    with (
        tempfile.TemporaryDirectory() as tmp,
        tempfile.TemporaryFile() as out,
        tempfile.TemporaryFile() as err,
    ):
        result = Path(tmp) / "result.json"
        launch = [sys.executable, "-I", "-S", "-c", LAUNCHER, str(result), str(timeout), *cmd]
        subprocess.run(launch, stdout=out, stderr=err, cwd=ROOT, check=True)
        r = json.loads(result.read_text())
        out.seek(0)
        err.seek(0)
        stdout = out.read().decode(errors="replace")
        stderr = err.read().decode(errors="replace")
    unit = 1024 * 1024 if sys.platform == "darwin" else 1024  # bytes on macOS, KB on Linux
    return {
        "wall": r["wall"],
        "rc": r["rc"],
        "timeout": r["timeout"],
        "peak_mb": r["maxrss"] / unit,
        "cpu": r["cpu"],
        "stdout": stdout,
        "stderr": stderr,
    }


def filletfold_cli() -> list[str]:
    """The ``filletfold`` command a user runs: the console script beside this Python."""
    script = Path(sys.executable).with_name("filletfold")
    return [str(script)] if script.is_file() else [sys.executable, "-m", "filletfold.cli"]


def folder_mb(folder: Path) -> float:
    return sum(f.stat().st_size for f in folder.rglob("*") if f.is_file()) / 1e6


def failure(r: dict) -> str:
    """The one-line message of a failed run (the CLI's last line on stderr)."""
    lines = [line.strip() for line in r["stderr"].splitlines() if line.strip()]
    last = lines[-1].removeprefix("error: ") if lines else f"exit {r['rc']}"
    if "Traceback (most recent call last)" in r["stderr"]:
        return f"traceback: {last}"
    return last


def one_run(mesh: str, out: Path, args, extra: list[str]) -> dict:
    """One fresh process on ``mesh`` writing into ``out`` (removed afterwards)."""
    options = [
        *(["--no-tabs"] if args.no_tabs else []),
        *(["--format", args.format] if args.format else []),
        *(["--arc-step", str(args.arc_step)] if args.arc_step is not None else []),
    ]
    if args.api:
        cmd = [sys.executable, str(Path(__file__).resolve()), "--api-child", mesh, str(out)]
        r = run_process([*cmd, *options], args.timeout)
    else:
        r = run_process(
            [*filletfold_cli(), "round", mesh, "-o", str(out), *options, *extra], args.timeout
        )
    row = {k: r[k] for k in ("wall", "rc", "timeout", "peak_mb", "cpu")}
    if r["timeout"]:
        row["error"] = f"killed after the {args.timeout:g} s timeout"
    elif r["rc"] != 0:
        row["error"] = failure(r)
    if args.api and r["rc"] == 0:
        child = json.loads(r["stdout"].strip().splitlines()[-1])
        row["process_wall"] = row["wall"]
        row["wall"] = child["wall"]  # round_mesh + export_design, no start-up
        row.update(timings=child["timings"], vertices=child["vertices"], base_mb=child["base_mb"])
    else:
        timings, report = out / "timings.json", out / "report.json"
        if timings.is_file():
            row["timings"] = json.loads(timings.read_text())
        if report.is_file():
            rep = json.loads(report.read_text())
            counts = rep.get("mesh_counts")  # reports before it: the mesh itself
            row["vertices"] = counts["vertices"] if counts else len(rep["mesh"]["vertices"])
            row["layout"] = rep.get("layout", {}).get("kind")
            row["status"] = {k: v for k, v in rep.get("status_counts", {}).items() if v}
    if out.is_dir():
        row["out_mb"] = folder_mb(out)
        shutil.rmtree(out, ignore_errors=True)
    return row


def run_case(mesh: str, tmp: Path, args, extra: list[str]) -> dict:
    """``--repeat`` runs of one case; medians (peak: the largest), or the failure."""
    runs = []
    for i in range(args.repeat):
        row = one_run(mesh, tmp / f"run{i}", args, extra)
        runs.append(row)
        if row.get("timeout") or ("error" in row and "timings" not in row):
            break  # a time-out or a failure: no point in repeating it
    good = [r for r in runs if "timings" in r or "error" not in r]
    result = {"runs": runs}
    last = runs[-1]
    if "error" in last:
        result["error"] = last["error"]
        result["timeout"] = last["timeout"]
    if not good or last.get("timeout"):
        return result
    keys = sorted({k for r in good for k in r.get("timings", {})})
    result.update(
        wall=statistics.median(r["wall"] for r in good),
        cpu=statistics.median(r["cpu"] for r in good),
        peak_mb=max(r["peak_mb"] for r in good),
        timings={
            k: statistics.median(r["timings"][k] for r in good if k in r.get("timings", {}))
            for k in keys
        },
        vertices=good[-1].get("vertices"),
        out_mb=good[-1].get("out_mb"),
        layout=good[-1].get("layout"),
        status=good[-1].get("status"),
    )
    return result


def api_child(mesh: str, folder: str, args) -> int:
    """``--api``: round_mesh and export_design as the CLI calls them, timed in this process."""
    import resource

    import filletfold
    from filletfold.export.cutfiles import DEFAULT_FORMATS, parse_formats
    from filletfold.export.outputs import export_design

    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    kwargs = {"tabs": not args.no_tabs, "keep_stages": False, "units": "mm", "scale": 1.0}
    if args.arc_step is not None:
        kwargs["arc_step"] = args.arc_step
    try:
        t = time.perf_counter()
        d = filletfold.round_mesh(mesh, **kwargs)
        formats = parse_formats(args.format or DEFAULT_FORMATS)
        export_design(d, folder, formats=formats, units="", scale=None, page="A4")
        wall = time.perf_counter() - t
    except Exception as exc:  # one line, as the CLI
        from filletfold.errors import one_line

        print(f"error: {one_line(exc)}", file=sys.stderr)
        return 2
    out = {"wall": wall, "timings": d.timings, "vertices": int(d.mesh.n_vertices), "base_mb": base}
    print(json.dumps(out))
    return 0


# --------------------------------------------------------------------------- printing
def machine() -> str:
    sys.path.insert(0, str(HERE))
    from examples import machine as base

    return f"{base()}, trimesh {metadata.version('trimesh')} (generated meshes)"


def secs(x: float | None, width: int = 7) -> str:
    if x is None:
        return f"{'-':>{width}s}"
    return f"{x:{width}.3f}" if x < 100 else f"{x:{width}.1f}"


def header() -> str:
    stages = " ".join(f"{HEADS.get(s, s):>7s}" for s in STAGES)
    return (
        f"{'case':28s} {'F':>6s} {'V':>6s} {'wall':>7s} {'total':>7s} {stages} {'tabs%':>5s} "
        f"{'export':>7s} {'rest':>7s} {'peak MB':>7s} {'ms/V':>6s} {'x cube':>6s}  note"
    )


def row_text(name: str, faces, res: dict, ref_wall: float | None) -> str:
    fs = f"{faces:6d}" if faces is not None else f"{'?':>6s}"
    if "wall" not in res:
        kind = "timeout" if res.get("timeout") else "error"
        return f"{name[:28]:28s} {fs} {kind}: {res['error']}"
    t = res["timings"]
    v = res.get("vertices")
    total, export = t.get("total"), t.get("export")
    rest = res["wall"] - total - (export or 0.0) if total is not None else None
    tabs = f"{100 * t['tabs'] / total:5.1f}" if "tabs" in t and total else f"{'-':>5s}"
    per_v = f"{1e3 * total / v:6.2f}" if total is not None and v else f"{'-':>6s}"
    ratio = f"{res['wall'] / ref_wall:6.1f}" if ref_wall else f"{'-':>6s}"
    notes = []
    if res.get("error"):
        notes.append(f"exit {res['runs'][-1]['rc']}: {res['error']}")
    if res.get("layout") not in (None, "modules"):
        notes.append(f"layout {res['layout']}")
    other = {k: s for k, s in t.items() if k not in KNOWN}
    if other:
        notes.append("other stages: " + ", ".join(f"{k} {s:.3f}" for k, s in other.items()))
    if not t:
        notes.append("no timings.json (json not among the formats)")
    return (
        f"{name[:28]:28s} {fs} {v if v is not None else '?':>6} {secs(res['wall'])} {secs(total)} "
        + " ".join(secs(t.get(s)) for s in STAGES)
        + f" {tabs} {secs(export)} {secs(rest)} {res['peak_mb']:7.0f} {per_v} {ratio}"
        + (f"  {'; '.join(notes)}" if notes else "")
    )


def scaling(done: dict, prefix: str) -> str | None:
    """Pipeline time per face of the largest ``prefix`` case over its smallest (linear = 1)."""
    runs = {
        k: r for k, r in done.items() if k.startswith(prefix) and "total" in r[1].get("timings", {})
    }
    if len(runs) < 2:
        return None
    small = min(runs, key=lambda k: runs[k][0])
    big = max(runs, key=lambda k: runs[k][0])
    per = {k: runs[k][1]["timings"]["total"] / runs[k][0] for k in (small, big)}
    walls = {k: runs[k][1]["wall"] / runs[k][0] for k in (small, big)}
    return (
        f"# scaling: time per face of {big} ({runs[big][0]} faces) / {small} ({runs[small][0]}): "
        f"pipeline {per[big] / per[small]:.2f}, wall {walls[big] / walls[small]:.2f} (linear = 1)"
    )


# --------------------------------------------------------------------------- main
def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    extra = argv[argv.index("--") + 1 :] if "--" in argv else []
    argv = argv[: argv.index("--")] if "--" in argv else argv
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="runs per case (medians)")
    ap.add_argument(
        "--max-faces",
        type=int,
        default=600,
        help="skip cases whose input has more faces (100000 for the big run)",
    )
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per run")
    ap.add_argument("--no-tabs", action="store_true", help="pass the CLI's --no-tabs")
    ap.add_argument("--format", help="pass the CLI's --format (default: its default formats)")
    ap.add_argument("--arc-step", type=float, default=None, help="pass the CLI's --arc-step")
    ap.add_argument(
        "--api",
        action="store_true",
        help="time round_mesh + export_design inside the child instead (no start-up)",
    )
    ap.add_argument("--json", help="write the results to this file")
    ap.add_argument("--api-child", nargs=2, help=argparse.SUPPRESS)
    ap.add_argument("cases", nargs="*", help="case names, mesh files or built-in specs")
    args = ap.parse_args(argv)
    if args.api_child:
        return api_child(*args.api_child, args)
    if args.repeat < 1:
        ap.error("--repeat must be at least 1")
    if args.api and extra:
        ap.error("options after -- go to the command line; --api does not run it")

    known = {c.name: c for c in all_cases()}
    cases = []
    for name in args.cases:
        if name in known:
            cases.append(known[name])
            continue
        try:
            cases.append(extra_case(name))
        except ValueError as exc:
            ap.error(
                f"unknown case {name!r} ({exc}); choose a mesh file, a built-in spec or "
                f"one of {', '.join(known)}"
            )
    cases = cases or list(known.values())

    options = " ".join(
        [
            *(["--no-tabs"] if args.no_tabs else []),
            *([f"--format {args.format}"] if args.format else []),
            *([f"--arc-step {args.arc_step:g}"] if args.arc_step is not None else []),
            *extra,
        ]
    )
    what = (
        f"round_mesh + export_design in a child process (--api), the CLI's defaults {options}"
        if args.api
        else f"filletfold round MESH -o DIR {options}"
    ).rstrip()
    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# load average at start: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(
        f"# each run: {what}, a fresh process; median of {args.repeat} run(s) (peak: largest); "
        f"timeout {args.timeout:g} s per run"
    )
    print(
        "# wall: "
        + (
            "round_mesh + export_design timed inside the child"
            if args.api
            else "the process, from outside"
        )
        + "; stages, total, export: timings.json (s); rest = wall - total - export; "
        "peak: the child's max RSS; ms/V: total per vertex; F: faces of the input; "
        "V: vertices of the design's mesh (report.json)"
    )
    results = {}
    with tempfile.TemporaryDirectory(prefix="filletfold-bench-") as tmp:
        tmp = Path(tmp)
        imports = [
            run_process([sys.executable, "-c", "import filletfold"], args.timeout)
            for _ in range(args.repeat)
        ]
        startup = {
            "wall": statistics.median(r["wall"] for r in imports),
            "peak_mb": max(r["peak_mb"] for r in imports),
            "cpu": statistics.median(r["cpu"] for r in imports),
        }
        base = run_case(BASELINE, tmp, args, extra)
        ref_wall = base.get("wall")
        base_total = base.get("timings", {}).get("total")
        print(
            f"# baselines: python -c 'import filletfold' {startup['wall']:.2f} s, "
            f"{startup['peak_mb']:.0f} MB; {BASELINE} ({what.replace('MESH', BASELINE)}) "
            + (
                f"{ref_wall:.2f} s (pipeline {secs(base_total, 0).strip()} s), "
                f"{base['peak_mb']:.0f} MB; x cube = wall / this wall"
                if ref_wall
                else f"failed: {base.get('error')}"
            )
        )
        print(header(), flush=True)
        skipped = []
        done = {}
        for case in cases:
            if case.faces is not None and case.faces > args.max_faces:
                skipped.append(f"{case.name} ({case.faces})")
                continue
            try:
                mesh = case.mesh()
            except Exception as exc:
                res = {"error": f"not built: {str(exc).splitlines()[0]}", "timeout": False}
            else:
                res = run_case(mesh, tmp, args, extra)
            results[case.name] = {"faces": case.faces, **res}
            if "wall" in res:
                done[case.name] = (case.faces, res)
            print(row_text(case.name, case.faces, res, ref_wall), flush=True)
    if skipped:
        print(f"# not run (over --max-faces {args.max_faces} faces): {', '.join(skipped)}")
    failed = [k for k, r in results.items() if "error" in r]
    if failed:
        print(f"# {len(failed)} of {len(results)} cases failed or timed out: {', '.join(failed)}")
    for prefix in ("geodesic-", "hull-"):
        line = scaling(done, prefix)
        if line:
            print(line)
    print(f"# load average at end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    if args.json:
        out = {
            "machine": machine(),
            "platform": platform.platform(),
            "command": sys.argv,
            "run": what,
            "repeat": args.repeat,
            "startup": startup,
            "baseline": {"case": BASELINE, **base},
            "cases": results,
            "skipped": skipped,
        }
        Path(args.json).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
