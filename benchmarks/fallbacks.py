"""What each fallback of the apex solver pays for, on real meshes (issue 27: "no fallback that
does not pay for itself").

Run from the repository root:

    .venv/bin/python benchmarks/fallbacks.py [--max-faces F] [--match TEXT ...] [--json FILE]
                                             [cases ...]

When the interior-point feasibility phase from a vertex's best start ends short of a feasible
point, :func:`filletfold.vertex.batch.solve_apex_batch` tries the fallbacks of
:data:`filletfold.vertex.settings.FALLBACKS` in turn (of ``starts``, ``again``, ``lp``,
``long``: :data:`~filletfold.vertex.settings.KNOWN_FALLBACKS`). Per mesh this runs the default
design (``round_mesh`` with the defaults, in this process) with the default fallbacks, then
once with each known fallback toggled (``-lp``: the default ones less ``lp``; ``+starts``:
plus ``starts``, in its place in the order), and prints one row per run: the cones
(vertices with status ``ok``), the vertices rescued by smaller radii, those left sharp and
infeasible, the apex problems solved
(``fitting.apex_work``: the design counts them) and the phase-1 problems (the feasibility
runs, every start counted), the apex stage's seconds, the certificate, and with the default
fallbacks the cones each one found (``fitting.cones_by_fallback``). Then a summary per
fallback over all meshes: the cones it found (as a default one), and what it pays for: the
cones more and the vertices rescued fewer (radii halved) with it than without, and the
phase-1 problems and apex seconds it costs.

Cases: meshes of the public corpus (``benchmarks/corpus_manifest.json``, fetched into
``out/corpus-meshes`` by ``benchmarks/fetch_corpus.py``), as ``collection/name`` or by file
stem, or mesh files; default: every mesh of the corpus's default tier of at most
``--max-faces`` faces (default 3000) whose name has one of the ``--match`` texts.
"""

from __future__ import annotations

import argparse
import collections
import json
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from examples import machine  # noqa: E402
from real_meshes import corpus_files  # noqa: E402

import filletfold  # noqa: E402
import filletfold.vertex.batch as batch  # noqa: E402
import filletfold.vertex.settings as settings  # noqa: E402

DEFAULT = tuple(settings.FALLBACKS)
KNOWN = tuple(settings.KNOWN_FALLBACKS)


def toggled(name: str) -> tuple:
    """The default fallbacks with ``name`` turned off (a default one) or on (another one)."""
    on = set(DEFAULT) ^ {name}
    return tuple(f for f in KNOWN if f in on)


def default_cases(max_faces: int, match: list[str]) -> list[Path]:
    """The corpus meshes of the default tier with at most ``max_faces`` faces."""
    manifest = json.loads((HERE / "corpus_manifest.json").read_text())
    files = corpus_files()
    out = []
    for item in manifest["meshes"]:
        if item.get("tier", "default") != "default" or (item.get("faces") or 0) > max_faces:
            continue
        path = files.get(f"{item['collection']}/{item['name']}")
        if path is None or (match and not any(m in str(path) for m in match)):
            continue
        out.append(path)
    return out


def run(path: Path, fallbacks: tuple) -> dict:
    """One default design of ``path`` with only ``fallbacks`` on: counts and seconds (the
    solver's work as the design counts it, ``fitting.apex_work``)."""
    settings.FALLBACKS = fallbacks
    try:
        design = filletfold.round_mesh(str(path))
    finally:
        settings.FALLBACKS = DEFAULT
    work = design.fitting["apex_work"]
    counts = design.status_counts()
    return {
        "cones": counts["ok"],
        "rescued": len(design.fitting["rescued"]),
        "sharp": counts["sharp"],
        "infeasible": counts["infeasible"],
        "problems": work["problems"],
        "phase1": work["phase1_runs"],
        "apices_s": design.timings.get("apices", float("nan")),
        "valid": bool(design.certificate is not None and design.certificate.ok),
        "by_fallback": dict(design.fitting.get("cones_by_fallback", {})),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases", nargs="*")
    ap.add_argument("--max-faces", type=int, default=3000)
    ap.add_argument("--match", nargs="*", default=[])
    ap.add_argument("--json", help="write the rows here too")
    args = ap.parse_args(argv)
    files = corpus_files()
    paths = [files.get(c, Path(c)) for c in args.cases] or default_cases(args.max_faces, args.match)
    batch.warm_kernel()  # its loading is not any fallback's cost
    print(f"# {' '.join(['benchmarks/fallbacks.py', *(argv or sys.argv[1:])])}")
    print(f"# {machine()}")
    print("| mesh | fallbacks | cones | rescued | sharp | infeasible | problems | phase 1 "
          "| apices s | valid | cones found by |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    total = collections.defaultdict(collections.Counter)
    for path in paths:
        mesh = f"{path.parent.name}/{path.name}"
        base = None
        for name in ("", *KNOWN):
            label = "default" if not name else ("-" if name in DEFAULT else "+") + name
            t0 = time.perf_counter()
            try:
                r = run(path, toggled(name) if name else DEFAULT)
            except Exception as exc:  # a refused mesh: say so, go on
                print(f"| {mesh} | {label} | {type(exc).__name__}: {exc} |")
                break
            r.update(mesh=mesh, fallbacks=label, wall_s=time.perf_counter() - t0)
            rows.append(r)
            found = ", ".join(f"{k} {v}" for k, v in r["by_fallback"].items() if v)
            print(
                f"| {mesh} | {label} | {r['cones']} | {r['rescued']} | {r['sharp']} "
                f"| {r['infeasible']} | {r['problems']} | {r['phase1']} | {r['apices_s']:.2f} "
                f"| {'yes' if r['valid'] else 'NO'} | {found if not name else ''} |",
                flush=True,
            )
            if not name:
                base = r
                for k, v in r["by_fallback"].items():
                    total[k]["found"] += v
                continue
            with_it, without = (base, r) if name in DEFAULT else (r, base)
            t = total[name]
            t["cones more"] += with_it["cones"] - without["cones"]
            t["rescued fewer"] += without["rescued"] - with_it["rescued"]
            t["phase1 cost"] += with_it["phase1"] - without["phase1"]
            t["apex ms cost"] += round(1000 * (with_it["apices_s"] - without["apices_s"]))
            t["invalid"] += not r["valid"]
    print()
    print("| fallback | default | cones found | cones more with it | rescued fewer with it "
          "| phase-1 problems it costs | apex s it costs | invalid when toggled |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for f in KNOWN:
        t = total[f]
        cost = t["apex ms cost"] / 1000
        head = f"| {f} | {'yes' if f in DEFAULT else 'no'} | {t['found']} | {t['cones more']} "
        print(f"{head}| {t['rescued fewer']} | {t['phase1 cost']} | {cost:.1f} | {t['invalid']} |")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
