"""Same bytes out: the default command of two source trees on the same cases, file by file.

Run from the repository root:

    .venv/bin/python benchmarks/same_bytes.py --base REV [--corpus] [--max-faces F]
                                              [--format FMT] [--keep-parameters]
                                              [--match TEXT ...]

A refactor (issue 28: "behaviour unchanged, same bytes out") is checked against the tree it
started from: ``REV`` (a commit, tag or branch) is checked out into a temporary ``git
worktree``, and every case runs ``filletfold round ARGS -o DIR`` twice in fresh processes of
this environment, once with ``PYTHONPATH`` on the worktree's ``src`` and once on this
checkout's. Then per case: the same exit status, the same file names, and every file the same
bytes, except ``timings.json`` (seconds) and, unless ``--keep-parameters``, the ``parameters``
object of ``report.json`` (which a change may extend; the rest of the report must be the
same). A case whose two runs both fail counts as the same when their last stderr line is.
``--format FMT`` is passed to every run (``--format all`` compares every writer's file).

Cases: every built-in example with the defaults, the option sets of :data:`OPTION_SETS`
(material loss, nets, sheets, strict, per-vertex depth, clamp, sharp kinds), and with
``--corpus`` every mesh of the corpus's default tier (``benchmarks/fetch_corpus.py``) of at
most ``--max-faces`` faces (default 3000). Prints the machine, the command and one row per
case; exits 1 when any case differs.
"""

from __future__ import annotations

import argparse
import filecmp
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

ROOT = Path(__file__).resolve().parent.parent

#: (name, arguments of ``filletfold round``) beyond the examples at their defaults.
OPTION_SETS = [
    ("miura material loss", ["miura", "--material-loss"]),
    ("yoshimura sheet", ["yoshimura", "--material-loss", "--layout", "sheet"]),
    ("conical-dome material loss", ["conical-dome", "--material-loss"]),
    ("blob on A4", ["blob", "--sheet", "A4"]),
    ("shell net", ["shell", "--layout", "net"]),
    ("open-box strict", ["open-box", "--strict", "--sharp", "none"]),
    ("geodesic depth", ["geodesic-sphere", "-d", "40%", "-r", "25%", "--no-fit-vertices"]),
    ("saddle-patch no sharp", ["saddle-patch", "--sharp", "none"]),
    ("chicken-wire on A3", ["chicken-wire", "--sheet", "A3", "--units", "mm", "--scale", "100"]),
    ("dimpled-cube clamp", ["dimpled-cube", "--clamp", "-n", "12"]),
]


def examples() -> list[str]:
    """The built-in examples' names (in this checkout)."""
    from filletfold.mesh.examples import example_names

    return example_names()


def corpus_meshes(max_faces: int) -> list[tuple[str, list[str]]]:
    """The corpus's default-tier meshes of at most ``max_faces`` faces, as cases."""
    from fetch_corpus import fetch

    cache = ROOT / "out" / "corpus-meshes"
    out = []
    for e in fetch(cache, quiet=True):
        if e["tier"] == "default" and (e.get("faces") or 0) <= max_faces:
            path = cache / e["collection"] / e["name"]
            out.append((f"{e['collection']}/{e['name']}", [str(path)]))
    return out


def run(src: Path, args: list[str], out: Path) -> tuple[int, str]:
    """``filletfold round ARGS -o OUT`` in a fresh process on the sources ``src``: the exit
    status and the last line of stderr."""
    env = dict(os.environ, PYTHONPATH=str(src), FILLETFOLD_THREADS="1")
    code = "import sys; from filletfold.cli import main; sys.exit(main(sys.argv[1:]))"
    done = subprocess.run(
        [sys.executable, "-c", code, "round", *args, "-q", "-o", str(out)],
        env=env,
        capture_output=True,
        text=True,
        timeout=1800,
    )
    lines = done.stderr.strip().splitlines()
    return done.returncode, lines[-1] if lines else ""


def differences(old: Path, new: Path, keep_parameters: bool) -> list[str]:
    """The files of two output folders that differ (names, then bytes)."""
    a = sorted(p.name for p in old.iterdir()) if old.is_dir() else []
    b = sorted(p.name for p in new.iterdir()) if new.is_dir() else []
    if a != b:
        return [f"files: {sorted(set(a) ^ set(b))}"]
    out = []
    for name in a:
        if name == "timings.json":
            continue
        if name == "report.json" and not keep_parameters:
            x, y = (json.loads((d / name).read_text()) for d in (old, new))
            x.pop("parameters", None)
            y.pop("parameters", None)
            if x != y:
                out.append(name + " (" + ", ".join(k for k in x if x.get(k) != y.get(k)) + ")")
        elif not filecmp.cmp(old / name, new / name, shallow=False):
            out.append(name)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", required=True, help="the commit, tag or branch to compare with")
    ap.add_argument("--corpus", action="store_true", help="add the corpus's default tier")
    ap.add_argument("--max-faces", type=int, default=3000)
    ap.add_argument("--keep-parameters", action="store_true")
    ap.add_argument("--format", help="passed to every run (e.g. all)")
    ap.add_argument("--match", nargs="*", default=[], help="only cases whose name has TEXT")
    args = ap.parse_args(argv)
    # a kill (SIGTERM) still removes the worktree and the temporary folder
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))

    cases = [(name, [name]) for name in examples()] + OPTION_SETS
    if args.corpus:
        cases += corpus_meshes(args.max_faces)
    if args.match:
        cases = [c for c in cases if any(m in c[0] for m in args.match)]
    if args.format:
        cases = [(name, [*case, "--format", args.format]) for name, case in cases]
    rev = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", args.base],
        capture_output=True, text=True, check=True,
    ).stdout.strip()  # fmt: skip
    print(f"# {machine()}")
    print(f"# {' '.join([Path(sys.argv[0]).name, *sys.argv[1:]])}: {len(cases)} cases, "
          f"{rev} against this checkout")  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="same-bytes-") as tmp:
        tmp = Path(tmp)
        base = tmp / "base"
        subprocess.run(
            ["git", "-C", str(ROOT), "worktree", "add", "--detach", "-f", str(base), rev],
            capture_output=True, check=True,
        )  # fmt: skip
        try:
            print("| case | exit (base, this) | seconds (base, this) | same bytes |")
            print("|---|---|---|---|")
            failed = 0
            for k, (name, case) in enumerate(cases):
                outs, codes, secs = [], [], []
                for src in (base / "src", ROOT / "src"):
                    out = tmp / f"{k}-{len(outs)}"
                    t = time.perf_counter()
                    codes.append(run(src, case, out))
                    secs.append(time.perf_counter() - t)
                    outs.append(out)
                if codes[0][0] != codes[1][0] or (codes[0][0] != 0 and codes[0] != codes[1]):
                    verdict = f"no: exit {codes[0]} vs {codes[1]}"
                else:
                    diff = differences(*outs, args.keep_parameters)
                    verdict = "yes" if not diff else "no: " + ", ".join(diff)
                failed += verdict != "yes"
                print(
                    f"| {name} | {codes[0][0]}, {codes[1][0]} | {secs[0]:.1f}, {secs[1]:.1f} "
                    f"| {verdict} |",
                    flush=True,
                )
        finally:
            subprocess.run(
                ["git", "-C", str(ROOT), "worktree", "remove", "--force", str(base)],
                capture_output=True,
            )  # fmt: skip
    print(f"# {len(cases) - failed} of {len(cases)} cases give the same bytes")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
