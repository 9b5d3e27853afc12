"""Request and response sizes and times of the Hops server (issue 32), and its pictures.

    .venv/bin/python benchmarks/hops.py [--changes N] [--pictures DIR] [NAME ...]

Starts ``filletfold hops`` on a free port of this machine
(:func:`filletfold.hops.server.run_hops`) and, per mesh (built-in example names, default
``blob`` (162 vertices), ``shell:cells=24x16`` (425), ``geodesic-sphere:level=3`` (642) and
``level=4`` (2562)), posts over HTTP the
*Round* request Grasshopper sends (the mesh as rhino3dm encodes it), then ``--changes`` radius
changes (10.5 %, 11 %, ...: a slider, each value new), then a *Pattern* request (A4 sheets).
Printed per request: its size, the response's size and the wall time from the client (median
over the changes). With ``--pictures DIR`` it draws
``DIR/grasshopper-round.png`` and ``DIR/grasshopper-pattern.png`` from the decoded responses
of the first mesh (rhino3dm decodes, matplotlib draws): what a Grasshopper canvas would show
after baking, not a screenshot of Grasshopper.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
import urllib.request
from pathlib import Path

import numpy as np
import rhino3dm

from filletfold.hops.server import run_hops
from filletfold.mesh import example_mesh

DEFAULT = ["blob", "shell:cells=24x16", "geodesic-sphere:level=3", "geodesic-sphere:level=4"]
INPUTS = {"Radius": "10%", "Depth": "30%", "Samples": 24, "Sharp": "auto"}
TYPES = {str: "System.String", int: "System.Int32"}


def rhino_mesh(name: str):
    v, faces = example_mesh(name)
    mesh = rhino3dm.Mesh()
    for x, y, z in v.tolist():
        mesh.Vertices.Add(x, y, z)
    for f in faces:
        f = [int(i) for i in f]
        if len(f) <= 4:
            mesh.Faces.AddFace(*f)
        else:
            for k in range(1, len(f) - 1):
                mesh.Faces.AddFace(f[0], f[k], f[k + 1])
    return mesh, len(v)


def body(pointer: str, mesh_data: str, inputs: dict) -> bytes:
    values = [
        {
            "ParamName": "Mesh",
            "InnerTree": {"{0}": [{"type": "Rhino.Geometry.Mesh", "data": mesh_data}]},
        }
    ]
    for name, value in inputs.items():
        item = {"type": TYPES[type(value)], "data": json.dumps(value)}
        values.append({"ParamName": name, "InnerTree": {"{0}": [item]}})
    return json.dumps({"pointer": pointer, "values": values, "dataversion": 7}).encode()


def post(url: str, data: bytes) -> tuple[float, bytes]:
    t = time.perf_counter()
    with urllib.request.urlopen(urllib.request.Request(url, data=data)) as reply:
        out = reply.read()
    return time.perf_counter() - t, out


def decoded(text: bytes) -> dict:
    out = {}
    for value in json.loads(text)["values"]:
        tree = {}
        for path, items in value["InnerTree"].items():
            tree[path] = [
                rhino3dm.CommonObject.Decode(json.loads(i["data"]))
                if i["type"].startswith("Rhino.Geometry.") and "archive3dm" in i["data"]
                else json.loads(i["data"])
                for i in items
            ]
        out[value["ParamName"]] = tree
    return out


def curve_points(curve) -> np.ndarray:
    """A curve's points: a polyline's or a line's own, else 24 along it."""
    if isinstance(curve, rhino3dm.PolylineCurve):
        pts = [curve.Point(i) for i in range(curve.PointCount)]
        return np.array([[p.X, p.Y, p.Z] for p in pts])
    if isinstance(curve, rhino3dm.LineCurve):
        pts = (curve.PointAtStart, curve.PointAtEnd)
        return np.array([[p.X, p.Y, p.Z] for p in pts])
    domain = curve.Domain
    ts = np.linspace(domain.T0, domain.T1, 24)
    return np.array([[p.X, p.Y, p.Z] for p in (curve.PointAt(t) for t in ts)])


def pictures(round_text: bytes, pattern_text: bytes, folder: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from filletfold.export.palette import ASSIGNMENT_COLOR, PATCH_COLOR, TAB_HINGE_COLOR

    folder.mkdir(parents=True, exist_ok=True)
    out = decoded(round_text)
    fig = plt.figure(figsize=(8, 6), dpi=100)
    ax = fig.add_subplot(projection="3d")
    kinds = ("cone", "cylinder", "fillet", "face")
    polys, colours = [], []
    for path, meshes in out["Folded"].items():
        colour = PATCH_COLOR[kinds[int(path[1:-1])]]
        for mesh in meshes:
            v = np.array([[p.X, p.Y, p.Z] for p in mesh.Vertices.ToPoint3dArray()])
            for f in range(len(mesh.Faces)):
                a, b, c, d = mesh.Faces[f]
                poly = v[[a, b, c] if c == d else [a, b, c, d]]
                normal = np.cross(poly[1] - poly[0], poly[2] - poly[0])
                light = abs(normal @ (0.4, -0.5, 0.75)) / max(np.linalg.norm(normal), 1e-300)
                polys.append(poly)
                colours.append(tuple(min(1.0, x * (0.45 + 0.6 * light)) for x in colour))
    ax.add_collection3d(Poly3DCollection(polys, facecolors=colours, edgecolors="none"))
    for name, colour in (("Mountain", ASSIGNMENT_COLOR["M"]), ("Valley", ASSIGNMENT_COLOR["V"])):
        for curve in out[name]["0"]:
            p = curve_points(curve)
            ax.plot(*p.T, color=colour, linewidth=0.6)
    allv = np.concatenate(polys)
    lo, hi = allv.min(axis=0), allv.max(axis=0)
    c, r = (lo + hi) / 2, (hi - lo).max() / 2
    ax.set(xlim=(c[0] - r, c[0] + r), ylim=(c[1] - r, c[1] + r), zlim=(c[2] - r, c[2] + r))
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=25, azim=-60)
    ax.set_axis_off()
    ax.set_title("Round: Folded (by kind), Mountain (red), Valley (blue)")
    fig.savefig(folder / "grasshopper-round.png", bbox_inches="tight")
    plt.close(fig)
    out = decoded(pattern_text)
    fig, ax = plt.subplots(figsize=(8, 6), dpi=100)
    layers = (("Sheets", "#999999"), ("Cut", ASSIGNMENT_COLOR["B"]), ("Tab", TAB_HINGE_COLOR),
              ("Mountain", ASSIGNMENT_COLOR["M"]), ("Valley", ASSIGNMENT_COLOR["V"]))  # fmt: skip
    for name, colour in layers:
        for curve in out[name]["0"]:
            p = curve_points(curve)
            ax.plot(p[:, 0], p[:, 1], color=colour, linewidth=0.5)
    ax.set_aspect("equal")
    ax.set_axis_off()
    units = out["Units"]["0"][0]
    ax.set_title(f"Pattern: Cut, Tab, Mountain, Valley, Sheets ({units})")
    fig.savefig(folder / "grasshopper-pattern.png", bbox_inches="tight")
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", default=DEFAULT)
    parser.add_argument("--changes", type=int, default=5)
    parser.add_argument("--pictures", type=Path)
    args = parser.parse_args(argv)
    print(f"# {' '.join([Path(sys.argv[0]).name, *sys.argv[1:]])}")
    print(f"# {platform.node()} {platform.machine()} python {platform.python_version()}")
    server = run_hops(port=0, say=lambda line: None)
    try:
        for k, name in enumerate(args.names):
            mesh, n = rhino_mesh(name)
            data = json.dumps(mesh.Encode())
            first = body("/round", data, INPUTS)
            t, reply = post(server.url + "round", first)
            print(f"{name} ({n} vertices): Round {len(first):,} B -> {len(reply):,} B in {t:.3f} s")
            times = []
            for i in range(args.changes):
                change = body("/round", data, {**INPUTS, "Radius": f"{10 + 0.5 * (i + 1):g}%"})
                t, reply = post(server.url + "round", change)
                times.append(t)
            if times:
                print(
                    f"  radius change: {len(change):,} B -> {len(reply):,} B, median "
                    f"{statistics.median(times):.3f} s (min {min(times):.3f}, "
                    f"{args.changes} changes)"
                )
            pattern = body(
                "/pattern", data, {**INPUTS, "Size": "auto", "Sheet": "A4", "Material": ""}
            )
            t, preply = post(server.url + "pattern", pattern)
            print(f"  Pattern (A4): {len(pattern):,} B -> {len(preply):,} B in {t:.3f} s")
            if k == 0 and args.pictures:
                pictures(reply, preply, args.pictures)
    finally:
        server.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
