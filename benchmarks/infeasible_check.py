"""Cross-check 'infeasible' vertices by brute force: random apices around each vertex.

    .venv/bin/python benchmarks/infeasible_check.py MESH [--clamp] [--points N]

For every vertex the solver reports infeasible, draws ``N`` random apices (Gaussian clouds of
0.2, 0.5, 1 and 2 mean incident edge lengths around the vertex), keeps the one with the largest
smallest sampled constraint slack, and validates it densely. A solver miss would show as a
vertex for which the random search finds a valid apex.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

import filletfold
from filletfold.surface.centres import face_piece_centres
from filletfold.vertex.apex import build_constraints, validate_apex
from filletfold.vertex.frame import vertex_frame


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mesh")
    ap.add_argument("--clamp", action="store_true")
    ap.add_argument("--points", type=int, default=20000)
    args = ap.parse_args(argv)
    d = filletfold.round_mesh(args.mesh, clamp=args.clamp)
    rng = np.random.default_rng(0)
    centres = face_piece_centres(d.mesh, d.rounding)
    bad = [u for u, s in enumerate(d.vertices.status) if s == "infeasible"]
    found = 0
    for u in bad:
        fr = vertex_frame(d.mesh, d.rounding, u)
        v = fr.developed_apex()
        if v is None:
            continue
        sigma = int(d.vertices.sigma[u])
        scale = np.mean([s.length for s in fr.sides])
        cons = build_constraints(fr, v, sigma, 17, 0.0)
        best, best_p = -np.inf, fr.U
        for spread in (0.2, 0.5, 1.0, 2.0):
            pts = fr.U + rng.normal(size=(args.points // 4, 3)) * scale * spread
            g = np.array([cons.values(p).min() for p in pts])
            if g.max() > best:
                best, best_p = g.max(), pts[np.argmax(g)]
        ok = validate_apex(fr, best_p, v, sigma, centres=centres).ok
        found += ok
        print(
            f"vertex {u}: best sampled slack {best / scale:+.4f} (edge lengths)"
            + ("  VALID APEX FOUND" if ok else "")
        )
    print(
        f"{args.mesh}: {len(bad)} infeasible; random search ({args.points} points each) "
        f"found a valid apex for {found}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
