"""Start-up time of what users run first: ``import filletfold`` and ``filletfold --help``.

    .venv/bin/python benchmarks/startup.py [--repeat N] [--python EXE] [--filletfold EXE]
                                           [--also CODE ...]

Issue 14's budgets: ``python -c "import filletfold"`` within 0.2 s and ``filletfold --help``
within 0.3 s. Each command runs ``--repeat`` times (default 7) in a fresh child process, the
commands taking turns (so a burst of load on a shared machine hits all of them alike), after
one untimed warm-up run each (the file cache). Printed per command: the median wall time from
start to exit, the fastest run, the ratio of the median to the baseline's (``python -c pass``:
the interpreter's own start-up), the median less the baseline (what filletfold adds), the
median CPU time (user + system: on a shared machine less swayed by other jobs); then the heavy
libraries the command loaded (none is the aim: they are imported where they are used).
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
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

#: Libraries that must not be loaded by ``import filletfold`` or ``filletfold --help``.
HEAVY = ("scipy", "shapely", "trimesh", "meshio", "numba", "matplotlib", "ezdxf", "viser")

#: Budgets of issue 14 (seconds, median wall time).
BUDGETS = {"import filletfold": 0.2, "filletfold --help": 0.3}

# printed by a child after the command's own work: the heavy top-level modules it loaded
_PROBE = (
    "import sys; print('heavy:' + ','.join(sorted({m.split('.')[0] for m in sys.modules}"
    " & set(%r))))"
)


def default_filletfold(python: str) -> list[str]:
    """The ``filletfold`` script beside ``python``, else ``python -m filletfold.cli``."""
    script = os.path.join(os.path.dirname(python), "filletfold")
    return [script] if os.path.isfile(script) else [python, "-m", "filletfold.cli"]


def heavy_loaded(python: str, code: str | None, argv: list[str] | None, env: dict) -> str:
    """The heavy libraries loaded after ``python -c code`` (or the CLI run with ``argv``)."""
    probe = _PROBE % (HEAVY,)
    if code is not None:
        prog = f"{code}\n{probe}"
    else:  # the entry point's own code, then the probe
        prog = (
            "import sys\nfrom filletfold.cli import main\n"
            f"sys.argv = ['filletfold', *{argv!r}]\ntry:\n    main()\nfinally:\n"
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
    ap.add_argument(
        "--bytecode",
        action="store_true",
        help="unset PYTHONDONTWRITEBYTECODE in the children (time with .pyc files)",
    )
    args = ap.parse_args(argv)
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
    cases = {
        "python -c pass": ([py, "-c", "pass"], "pass"),
        "import filletfold": ([py, "-c", "import filletfold"], "import filletfold"),
        **{f"python -c {c!r}": ([py, "-c", c], c) for c in args.also},
        "filletfold --help": ([*ff, "--help"], None),
    }

    sys.path.insert(0, HERE)
    from examples import machine

    print(f"# machine: {machine()}")
    print(f"# command: {shlex.join([os.path.basename(sys.executable), *sys.argv])}")
    print(f"# timed: {py} and {shlex.join(ff)}; bytecode {bytecode}")
    print(
        f"# wall time from start to exit of a fresh process, {args.repeat} runs each (taking "
        "turns) after a warm-up; baseline = python -c pass; cpu = user + system; heavy = which of "
        f"{', '.join(HEAVY)} were loaded"
    )
    for cmd, _ in cases.values():
        run_once(cmd, env)
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in cases}
    for _ in range(args.repeat):
        for name, (cmd, _) in cases.items():
            times[name].append(run_once(cmd, env))
    base = statistics.median(w for w, _ in times["python -c pass"])
    print(
        f"{'command':28s} {'median s':>9s} {'min s':>7s} {'ratio':>6s} {'added s':>8s} "
        f"{'cpu s':>6s} {'budget':>7s}  heavy"
    )
    for name, (_, code) in cases.items():
        walls = [w for w, _ in times[name]]
        med = statistics.median(walls)
        cpu = statistics.median(c for _, c in times[name])
        budget = BUDGETS.get(name)
        mark = "" if budget is None else f"{budget:.1f} {'ok' if med <= budget else 'over'}"
        heavy = heavy_loaded(py, code, None if code is not None else ["--help"], env)
        print(
            f"{name:28s} {med:9.3f} {min(walls):7.3f} {med / base:6.1f} "
            f"{med - base:8.3f} {cpu:6.3f} {mark:>7s}  {heavy}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
