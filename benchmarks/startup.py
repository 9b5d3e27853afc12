"""Start-up time of what users run first: ``import filletfold``, ``filletfold --help`` and a
built-in example's design.

    .venv/bin/python benchmarks/startup.py [--repeat N] [--python EXE] [--filletfold EXE]
                                           [--also CODE ...] [--example NAME] [--base REV]
                                           [--bytecode]

Budgets: issue 14's ``python -c "import filletfold"`` within 0.2 s and ``filletfold --help``
within 0.3 s; issue 27's ``filletfold round EXAMPLE -o DIR`` (the default command, default
formats and tabs; ``--example``, default icosahedron) within 0.5 s. Each command runs
``--repeat`` times (default 7) in a fresh child process, the commands taking turns (so a
burst of load on a shared machine hits all of them alike), after one untimed warm-up run
each (the file cache). Printed per command: the median wall time from start to exit, the
fastest run, the ratio of the median to the baseline's (``python -c pass``: the
interpreter's own start-up), the median less the baseline (what filletfold adds), the
median CPU time (user + system: on a shared machine less swayed by other jobs); then the heavy
libraries the command loaded (none is the aim for the first two: they are imported where
they are used; numba only where the solver's kernel solves a batch).
``--base REV`` also times every command on the sources of ``REV`` (a commit, tag or branch,
checked out into a temporary ``git worktree`` and put first on ``PYTHONPATH``; both trees'
modules compiled to ``.pyc`` first), in the same turns, and prints its median and this
checkout's median over it (below 1: faster now).
``--also CODE`` adds a ``python -c CODE`` row (``--also "import numpy"``, say).
``--python`` and ``--filletfold`` time another install (default: this interpreter and the
``filletfold`` script beside it). The children inherit the environment; with
``PYTHONDONTWRITEBYTECODE`` set no ``__pycache__`` is written, so filletfold's own modules
(an editable install) are compiled on every start: ``--bytecode`` unsets it for the children
(the warm-up writes the ``.pyc`` files, as an installed package has them). Prints the machine,
the command and the bytecode state first.
"""

from __future__ import annotations

import argparse
import os
import resource
import shlex
import signal
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

#: Libraries that must not be loaded by ``import filletfold`` or ``filletfold --help``.
HEAVY = ("scipy", "shapely", "trimesh", "meshio", "numba", "matplotlib", "ezdxf", "viser")

#: Budgets of issues 14 and 27 (seconds, median wall time).
BUDGETS = {"import filletfold": 0.2, "filletfold --help": 0.3, "filletfold round": 0.5}

# printed by a child after the command's own work: the heavy top-level modules it loaded
_PROBE = (
    "import sys; print('heavy:' + ','.join(sorted({m.split('.')[0] for m in sys.modules}"
    " & set(%r))))"
)


def default_filletfold(python: str) -> list[str]:
    """The ``filletfold`` script beside ``python``, else ``python -m filletfold.cli``."""
    script = os.path.join(os.path.dirname(python), "filletfold")
    return [script] if os.path.isfile(script) else [python, "-m", "filletfold.cli"]


def heavy_loaded(python: str, what: str | list[str], env: dict) -> str:
    """The heavy libraries loaded after ``python -c what`` (a str) or the command line run
    with the arguments ``what`` (a list)."""
    probe = _PROBE % (HEAVY,)
    if isinstance(what, str):
        prog = f"{what}\n{probe}"
    else:  # the entry point's own code, then the probe
        prog = (
            "import sys\nfrom filletfold.cli import main\n"
            f"sys.argv = ['filletfold', *{what!r}]\ntry:\n    main()\nfinally:\n"
            f"    {probe}"
        )
    out = subprocess.run([python, "-c", prog], capture_output=True, text=True, cwd=ROOT, env=env)
    found = [line[6:] for line in out.stdout.splitlines() if line.startswith("heavy:")]
    return (found[-1] or "none") if found else f"? (exit {out.returncode})"


def run_once(cmd: list[str], env: dict) -> tuple[float, float]:
    """Wall time and CPU time (user + system) of one run of ``cmd``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True, cwd=ROOT, env=env
    )
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def worktree(rev: str, where: str, python: str) -> str:
    """``rev`` checked out (detached) at ``where``; its ``src`` folder. The modules of both
    trees are compiled (``.pyc``) first: under ``PYTHONDONTWRITEBYTECODE`` a fresh tree, or a
    module changed since its ``.pyc``, would be compiled on every start, in one tree only."""
    src = os.path.join(where, "src")
    subprocess.run(
        ["git", "-C", ROOT, "worktree", "add", "--detach", "-f", where, rev],
        capture_output=True, check=True,
    )  # fmt: skip
    for tree in (src, os.path.join(ROOT, "src")):
        subprocess.run([python, "-m", "compileall", "-q", tree], capture_output=True, check=True)
    return src


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7, help="timed runs per command (default 7)")
    ap.add_argument("--python", default=sys.executable, help="interpreter to time")
    ap.add_argument(
        "--filletfold", help="filletfold executable (default: the script beside --python)"
    )
    ap.add_argument(
        "--also", action="append", default=[], metavar="CODE", help="also time python -c CODE"
    )
    ap.add_argument("--example", default="icosahedron", help="the example filletfold rounds")
    ap.add_argument("--base", metavar="REV", help="also time the sources of REV (git worktree)")
    ap.add_argument(
        "--bytecode",
        action="store_true",
        help="unset PYTHONDONTWRITEBYTECODE in the children (time with .pyc files)",
    )
    args = ap.parse_args(argv)
    # a kill (SIGTERM) still removes the worktree and the temporary folder
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    with tempfile.TemporaryDirectory(prefix="startup-") as tmp:
        try:
            return timed(args, tmp)
        finally:
            if args.base:
                subprocess.run(
                    ["git", "-C", ROOT, "worktree", "remove", "--force", f"{tmp}/base"],
                    capture_output=True,
                )  # fmt: skip


def timed(args, tmp: str) -> int:
    """Time the commands (and those of ``--base``) with outputs under ``tmp``; print them."""
    env = dict(os.environ)
    if args.bytecode:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
    bytecode = (
        "not written (PYTHONDONTWRITEBYTECODE set: modules without .pyc compiled every start)"
        if env.get("PYTHONDONTWRITEBYTECODE")
        else "written and reused (.pyc)"
    )
    py = args.python
    ff = [args.filletfold] if args.filletfold else default_filletfold(py)
    out = os.path.join(tmp, "design")
    round_argv = ["round", args.example, "-o", out, "--force"]
    cases = {
        "python -c pass": ([py, "-c", "pass"], "pass"),
        "import filletfold": ([py, "-c", "import filletfold"], "import filletfold"),
        **{f"python -c {c!r}": ([py, "-c", c], c) for c in args.also},
        "filletfold --help": ([*ff, "--help"], ["--help"]),
        "filletfold round": ([*ff, *round_argv], round_argv),
    }
    envs = {"": env}
    if args.base:
        rev = subprocess.run(
            ["git", "-C", ROOT, "rev-parse", "--short", args.base],
            capture_output=True, text=True, check=True,
        ).stdout.strip()  # fmt: skip
        src = worktree(rev, os.path.join(tmp, "base"), py)
        envs["base"] = {
            **env,
            "PYTHONPATH": os.pathsep.join(filter(None, [src, env.get("PYTHONPATH")])),
        }

    sys.path.insert(0, HERE)
    from examples import machine

    print(f"# machine: {machine()}")
    print(f"# command: {shlex.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# timed: {py} and {shlex.join(ff)}; bytecode {bytecode}")
    if args.base:
        print(f"# base: {args.base} = {rev}, its src first on PYTHONPATH, in the same turns")
    print(
        f"# wall time from start to exit of a fresh process, {args.repeat} runs each (taking "
        "turns) after a warm-up; baseline = python -c pass; cpu = user + system; heavy = which of "
        f"{', '.join(HEAVY)} were loaded; filletfold round = {shlex.join(round_argv[:2])}"
    )
    runs = [
        (name, tree) for name in cases for tree in envs if tree == "" or name != "python -c pass"
    ]
    for name, tree in runs:
        run_once(cases[name][0], envs[tree])
    times: dict = {run: [] for run in runs}
    for _ in range(args.repeat):
        for name, tree in runs:
            times[name, tree].append(run_once(cases[name][0], envs[tree]))
    base = statistics.median(w for w, _ in times["python -c pass", ""])
    print(
        f"{'command':28s} {'median s':>9s} {'min s':>7s} {'ratio':>6s} {'added s':>8s} "
        f"{'cpu s':>6s} {'budget':>7s}  heavy"
        + (f"  | {'base s':>7s} {'/ base':>6s}  base heavy" if args.base else "")
    )
    for name, (_, code) in cases.items():
        walls = [w for w, _ in times[name, ""]]
        med = statistics.median(walls)
        cpu = statistics.median(c for _, c in times[name, ""])
        budget = BUDGETS.get(name)
        mark = "" if budget is None else f"{budget:.1f} {'ok' if med <= budget else 'over'}"
        line = (
            f"{name:28s} {med:9.3f} {min(walls):7.3f} {med / base:6.1f} "
            f"{med - base:8.3f} {cpu:6.3f} {mark:>7s}  {heavy_loaded(py, code, env):9s}"
        )
        if args.base and (name, "base") in times:
            was = statistics.median(w for w, _ in times[name, "base"])
            line += f"  | {was:7.3f} {med / was:6.2f}  {heavy_loaded(py, code, envs['base'])}"
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
