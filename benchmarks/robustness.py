"""Robustness: how ``round_mesh`` ends on fuzzed meshes and files (:mod:`filletfold.testing`).

Run from the repository root, one process, ``FILLETFOLD_THREADS`` as you want it:

    .venv/bin/python benchmarks/robustness.py [--cases 2000] [--seed 0] [--show N]
                                              [--timeout S] [--json PATH]
    .venv/bin/python benchmarks/robustness.py --case 'hull-37/scale-1e-6#0012'

Runs the first ``--cases`` cases of ``--seed`` one by one, in this process, with the defaults
of ``round_mesh``, and certifies every design with ``filletfold.check.certify_design`` when
that exists. Prints the machine and the command, then a table of outcomes per mutation kind (a
case of two kinds counts in both rows; the total counts it once) and per base mesh, the median
and largest time per case, the ``--show`` slowest cases, every traceback (grouped by exception
type and where it was raised, then one line each), every design failing its certificate, every
garbage file not refused or refused without naming it, and the ``--show``
most frequent refusal messages (numbers and paths replaced by ``#`` and ``<file>``).

``--case NAME`` reruns one case and prints its outcome and full traceback; a file case's file
is kept in a temporary folder whose path is printed.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import re
import statistics
import sys
import tempfile
import time
from dataclasses import asdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from examples import machine

from filletfold.testing import KINDS, case_by_name, fuzz_case, run_case
from filletfold.testing.fuzz import certifier

COLUMNS = (
    "cases",
    "design",
    "certified",
    "cert-fail",
    "error",
    "multiline",
    "traceback",
    "timeout",
)


def counts(outcomes) -> dict[str, int]:
    """Outcome counts of a group of cases (the table's columns)."""
    c = collections.Counter(o.outcome for o in outcomes)
    return {
        "cases": len(outcomes),
        "design": c["design"],
        "certified": sum(o.certified is True for o in outcomes),
        "cert-fail": sum(o.certified is False for o in outcomes),
        "error": c["error"],
        "multiline": c["error-multiline"],
        "traceback": c["traceback"],
        "timeout": c["timeout"],
    }


def table(title: str, rows: dict[str, list], order) -> list[str]:
    width = max([len(title), *map(len, rows)])
    lines = [f"{title:{width}s} " + " ".join(f"{h:>9s}" for h in COLUMNS)]
    for key in order:
        if key in rows:
            c = counts(rows[key])
            lines.append(f"{key:{width}s} " + " ".join(f"{c[h]:9d}" for h in COLUMNS))
    return lines


def family(base: str) -> str:
    """The base mesh's family: hull, grid-quad, grid-tri, torus or example."""
    for name in ("hull", "grid-quad", "grid-tri", "torus"):
        if re.fullmatch(rf"{name}-[\dx]+", base):
            return name
    return "example"


def normalise(message: str, path: str | None) -> str:
    """A refusal message with its file, numbers and lists of numbers made generic."""
    if path:
        message = message.replace(path, "<file>")
    message = re.sub(r"/tmp/\S+?\.(obj|off|ply|stl)\b", "<file>", message, flags=re.I)
    message = re.sub(r"\[[-+\d.eE, naif]*\]", "[...]", message)
    return re.sub(r"(?<![\w<])[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?", "#", message)


def rerun(name: str, timeout: float) -> int:
    case = case_by_name(name)
    folder = tempfile.mkdtemp(prefix="filletfold-case-")
    o = run_case(case, folder, timeout=timeout)
    print(f"# case: {case.name} (kind {case.kind}, base {case.base}, garbage {case.garbage})")
    if case.file is not None:
        print(f"# file: {o.file} ({len(case.file[1])} bytes, kept)")
    else:
        print(f"# mesh: {len(case.vertices)} vertices, {len(case.faces)} faces")
    print(f"outcome: {o.outcome}  ({o.seconds:.3f} s, certificate {o.certify_seconds:.3f} s)")
    if o.outcome == "design":
        print(f"faces after cleaning: {o.n_faces}; certified: {o.certified}")
        if o.failed_checks:
            print("failing checks: " + ", ".join(o.failed_checks))
    elif o.outcome in ("error", "error-multiline"):
        print(f"{o.error_type}: {o.message}")
        if o.names_file is not None:
            print(f"names the file: {o.names_file}")
    for w in o.warnings:
        print(f"warning: {w}")
    if o.traceback:
        print(o.traceback.rstrip())
    return 0 if not o.defect else 1


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=2000, help="number of cases (default 2000)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--case", help="rerun one case by name and print its full traceback")
    ap.add_argument("--show", type=int, default=15, help="slowest cases and refusal groups shown")
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds allowed per case")
    ap.add_argument("--json", help="also write every outcome to this JSON file")
    args = ap.parse_args(argv)
    print(f"# machine: {machine()}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    threads = os.environ.get("FILLETFOLD_THREADS", "(unset)")
    certify = certifier()
    cert = "filletfold.check.certify_design" if certify else "none (no filletfold.check yet)"
    print(f"# FILLETFOLD_THREADS={threads}; os.cpu_count() {os.cpu_count()}; certificate: {cert}")
    if args.case:
        return rerun(args.case, args.timeout)

    outcomes, bases = [], []
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="filletfold-fuzz-") as folder:
        for i in range(args.cases):
            case = fuzz_case(i, args.seed)
            outcomes.append(run_case(case, folder, timeout=args.timeout))
            bases.append(case.base)
            if case.file is not None:
                os.unlink(outcomes[-1].file)
            if (i + 1) % 100 == 0:
                print(
                    f"[{i + 1:5d}/{args.cases}] {time.perf_counter() - t0:7.1f} s", file=sys.stderr
                )
    wall = time.perf_counter() - t0
    times = [o.seconds + o.certify_seconds for o in outcomes]
    slow = max(range(len(outcomes)), key=times.__getitem__)
    print(
        f"# {len(outcomes)} cases of seed {args.seed} in {wall:.1f} s; per case median "
        f"{statistics.median(times):.3f} s, mean {statistics.fmean(times):.3f} s, max "
        f"{times[slow]:.2f} s ({outcomes[slow].name})"
    )
    print()
    by_kind = collections.defaultdict(list)
    for o in outcomes:
        for k in o.kinds:
            by_kind[k].append(o)
    by_kind["total"] = outcomes
    print("\n".join(table("kind", by_kind, [*KINDS, "total"])))
    print()
    by_base = collections.defaultdict(list)
    for o, b in zip(outcomes, bases, strict=True):
        by_base[family(b)].append(o)
    print("\n".join(table("base", by_base, ["hull", "example", "grid-quad", "grid-tri", "torus"])))

    print(f"\n## {args.show} slowest cases (round_mesh + certificate)")
    for i in sorted(range(len(outcomes)), key=lambda i: -times[i])[: args.show]:
        o = outcomes[i]
        faces = f", {o.n_faces} faces" if o.n_faces is not None else ""
        print(f"{times[i]:7.2f} s  {o.name}  {o.outcome}{faces}")

    bad = [o for o in outcomes if o.outcome in ("traceback", "timeout")]
    print(f"\n## tracebacks and time-outs: {len(bad)}")
    groups = collections.defaultdict(list)
    for o in bad:
        groups[(o.error_type, o.where, o.stage)].append(o)
    for (etype, where, stage), os_ in sorted(groups.items(), key=lambda g: -len(g[1])):
        at = " (while certifying)" if stage == "certify" else ""
        print(f"{len(os_):5d} x {etype} at {where}{at}; e.g. {os_[0].name}")
    if bad:
        print()
    for o in bad:
        print(f"{o.name}: {o.message}")

    sections = [
        ("designs failing the certificate", [o for o in outcomes if o.certified is False]),
        ("multi-line errors", [o for o in outcomes if o.outcome == "error-multiline"]),
        ("garbage files not refused", [o for o in outcomes if o.garbage and o.outcome == "design"]),
        (
            "garbage file errors not naming the file",
            [o for o in outcomes if o.garbage and o.names_file is False],
        ),
    ]
    for title, items in sections:
        print(f"\n## {title}: {len(items)}")
        for o in items:
            if o.certified is False:
                print(f"{o.name}: failing {', '.join(o.failed_checks) or '(no check named)'}")
            else:
                first = (o.message.splitlines() or [""])[0]
                print(f"{o.name}: {o.error_type or o.outcome}: {first}")

    refusals = [o for o in outcomes if o.outcome in ("error", "error-multiline")]
    groups = collections.defaultdict(list)
    for o in refusals:
        groups[(o.error_type, normalise((o.message.splitlines() or [""])[0], o.file))].append(o)
    ranked = sorted(groups.items(), key=lambda g: -len(g[1]))
    print(f"\n## refusals: {len(refusals)} in {len(groups)} groups; the {args.show} largest")
    for (etype, text), os_ in ranked[: args.show]:
        print(f"{len(os_):5d} x {etype}: {text[:160]}  (e.g. {os_[0].name})")

    unnamed = [o for o in outcomes if not o.garbage and o.names_file is False]
    files = [o for o in outcomes if o.file is not None and not o.garbage]
    print(
        f"\n## valid files of mutated meshes refused without naming the file: {len(unnamed)} "
        f"of {sum(o.outcome != 'design' for o in files)} refused (of {len(files)})"
    )

    warned = [o for o in outcomes if o.warnings]
    print(f"\n## cases with warnings: {len(warned)}")
    wgroups = collections.Counter(w for o in warned for w in o.warnings)
    for w, n in wgroups.most_common(args.show):
        print(f"{n:5d} x {w[:160]}")

    if args.json:
        with open(args.json, "w") as f:
            json.dump([asdict(o) for o in outcomes], f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
