"""The Hops components (:mod:`filletfold.hops`): a solve request as Grasshopper sends it, the
geometry it returns read back with rhino3dm and held against the command line's design."""

from __future__ import annotations

import json
import urllib.error
import urllib.request

import numpy as np
import pytest

from filletfold.cli import main
from filletfold.mesh import example_mesh

rhino3dm = pytest.importorskip("rhino3dm")
pytest.importorskip("ghhops_server")

from filletfold.hops.server import HopsService, run_hops  # noqa: E402

#: The inputs of Round as Grasshopper's Hops component sends them (a text input's data is the
#: JSON of its text, an integer's the JSON of the integer).
ROUND_INPUTS = {
    "Radius": ("System.String", "10%"),
    "Depth": ("System.String", "30%"),
    "Samples": ("System.Int32", 24),
    "Sharp": ("System.String", "auto"),
}


def rhino_mesh(name: str):
    """A built-in example as a Rhino mesh: triangles and quads as they are, a larger polygon
    as the triangles of a fan (as Rhino holds an n-gon: its faces, with the n-gon on top)."""
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
    return mesh


def request(pointer: str, mesh_data: str, inputs: dict) -> bytes:
    """A solve request of Hops (the fields of its JSON schema, the values as data trees)."""
    values = [
        {
            "ParamName": "Mesh",
            "InnerTree": {"{0}": [{"type": "Rhino.Geometry.Mesh", "data": mesh_data}]},
        }
    ]
    for name, (kind, value) in inputs.items():
        values.append(
            {"ParamName": name, "InnerTree": {"{0}": [{"type": kind, "data": json.dumps(value)}]}}
        )
    return json.dumps(
        {
            "absolutetolerance": 0.001,
            "angletolerance": 1.0,
            "modelunits": "Millimeters",
            "algo": "",
            "pointer": pointer,
            "cachesolve": False,
            "recursionlevel": 0,
            "values": values,
            "warnings": [],
            "errors": [],
            "dataversion": 7,
        }
    ).encode()


def outputs(text: str) -> dict:
    """The response's outputs: name -> {branch: [decoded values]} (geometry decoded by
    rhino3dm, everything else by JSON)."""
    out = {}
    for value in json.loads(text)["values"]:
        tree = {}
        for path, items in value["InnerTree"].items():
            decoded = []
            for item in items:
                data = json.loads(item["data"])
                if item["type"].startswith("Rhino.Geometry.") and "archive3dm" in data:
                    data = rhino3dm.CommonObject.Decode(data)
                    assert data is not None, (value["ParamName"], item["type"])
                decoded.append(data)
            tree[path] = decoded
        out[value["ParamName"]] = tree
    return out


@pytest.fixture(scope="module")
def service():
    return HopsService()


@pytest.fixture(scope="module")
def cli_icosahedron(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cli") / "ico"
    assert main(["round", "icosahedron", "-o", str(folder), "--format", "fold,json", "-q"]) == 0
    return json.loads((folder / "design.fold").read_text())


def welded_folds(meshes) -> np.ndarray:
    """|dihedral angle| (degrees) at every edge where two patches' meshes meet, their vertices
    welded by position; sorted."""
    points, tris, patch = {}, [], []
    for k, mesh in enumerate(meshes):
        v = np.array([(p.X, p.Y, p.Z) for p in mesh.Vertices.ToPoint3dArray()])
        ids = [points.setdefault(tuple(np.round(p, 9)), len(points)) for p in v]
        for f in range(len(mesh.Faces)):
            a, b, c, d = mesh.Faces[f]
            corners = [ids[i] for i in ((a, b, c) if c == d else (a, b, c, d))]
            tris += [(corners[0], corners[i], corners[i + 1]) for i in range(1, len(corners) - 1)]
            patch += [k] * (len(corners) - 2)
    return _folds(np.array(list(points)), np.array(tris), np.array(patch))


def cli_folds(fold: dict) -> np.ndarray:
    """:func:`welded_folds` of a ``design.fold``'s folded form (its faces and patches)."""
    xyz = np.asarray(fold["file_frames"][0]["vertices_coords"], dtype=float)
    points: dict = {}
    ids = [points.setdefault(tuple(np.round(p, 9)), len(points)) for p in xyz]
    names = {n: k for k, n in enumerate(dict.fromkeys(fold["filletfold:faces_patch"]))}
    tris, patch = [], []
    for face, name in zip(fold["faces_vertices"], fold["filletfold:faces_patch"], strict=True):
        c = [ids[i] for i in face]
        tris += [(c[0], c[i], c[i + 1]) for i in range(1, len(c) - 1)]
        patch += [names[name]] * (len(c) - 2)
    return _folds(np.array(list(points)), np.array(tris), np.array(patch))


def _folds(xyz, tris, patch) -> np.ndarray:
    normal = np.cross(xyz[tris[:, 1]] - xyz[tris[:, 0]], xyz[tris[:, 2]] - xyz[tris[:, 0]])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    sides: dict = {}
    for t, tri in enumerate(tris.tolist()):
        for i in range(3):
            sides.setdefault(frozenset((tri[i], tri[(i + 1) % 3])), []).append(t)
    out = []
    for ts in sides.values():
        if len(ts) == 2 and patch[ts[0]] != patch[ts[1]]:
            cos = np.clip(normal[ts[0]] @ normal[ts[1]], -1, 1)
            out.append(np.degrees(np.arccos(cos)))
    return np.sort(out)


def test_a_round_request_as_grasshopper_sends_it_gives_the_command_lines_design(
    service, cli_icosahedron
):
    mesh = rhino_mesh("icosahedron")
    payload = request("/round", json.dumps(mesh.Encode()), ROUND_INPUTS)
    status, text = service.solve("/round", payload)
    assert status == 200, text
    out = outputs(text)
    assert list(out) == ["Folded", "Names", "Mountain", "Valley", "Pattern", "Status", "Summary"]
    names = [n for branch in out["Names"].values() for n in branch]
    folded = [m for branch in out["Folded"].values() for m in branch]
    assert all(isinstance(m, rhino3dm.Mesh) for m in folded)
    cli = cli_icosahedron
    assert sorted(names) == sorted(set(cli["filletfold:faces_patch"]))  # the same patches
    kinds = {path: {n.split()[0] for n in branch} for path, branch in out["Names"].items()}
    assert kinds == {"{0}": {"cone"}, "{1}": {"cylinder"}, "{3}": {"face"}}
    assert out["Status"]["0"] == ["ok"] * 12
    # the same fold angles: at every edge where two patches meet, on the returned meshes and
    # on the command line's folded form; among them the command line's M and V creases
    measured = welded_folds(folded)
    assert len(measured) > 500
    np.testing.assert_allclose(measured, cli_folds(cli), atol=1e-5)  # 12 digits in the file
    angles = np.array(cli["edges_foldAngle"], dtype=object)
    creases = np.abs(angles[np.isin(cli["edges_assignment"], ["M", "V"])].astype(float))
    assert len(creases) == 600
    assert np.isin(np.round(creases, 6), np.round(measured, 6)).all()
    # every crease is a mountain on the convex icosahedron; the curves decode as curves
    assert out["Valley"]["0"] == [] or out["Valley"] == {"0": []}
    assert all(isinstance(c, rhino3dm.Curve) for c in out["Mountain"]["0"])
    assert sorted(out["Pattern"]) == ["{0}", "{1}", "{2}"]


def test_a_polygon_held_as_triangles_gives_the_polygons_design(service):
    """The dodecahedron's pentagons arrive as fans of triangles (rhino3dm reads an n-gon's
    faces): the design is that of the pentagons."""
    status, text = service.solve(
        "/round",
        request("/round", json.dumps(rhino_mesh("dodecahedron").Encode()), ROUND_INPUTS),
    )
    assert status == 200, text
    names = [n for b in outputs(text)["Names"].values() for n in b]
    assert sum(n.startswith("face ") for n in names) == 12
    assert len(names) == 20 + 30 + 12


def _error(service, payload, uri="/round") -> str:
    status, text = service.solve(uri, payload)
    assert status == 500
    body = json.loads(text)
    assert body["values"] == []
    (message,) = body["errors"]
    assert "\n" not in message and "Traceback" not in message
    return message


def test_bad_inputs_give_one_line_naming_them(service):
    good = json.dumps(rhino_mesh("cube").Encode())
    assert _error(service, request("/round", good, {})).startswith("Radius: no value")
    assert "radius" in _error(
        service, request("/round", good, {**ROUND_INPUTS, "Radius": ("System.String", "wide")})
    )
    assert "samples" in _error(
        service, request("/round", good, {**ROUND_INPUTS, "Samples": ("System.Int32", 1)})
    )
    assert _error(service, b"{not json").startswith("request: not JSON")
    assert _error(service, request("/round", '{"a": 1}', ROUND_INPUTS)).startswith("Mesh:")
    assert _error(service, request("/round", "[", ROUND_INPUTS)).startswith("Mesh:")
    garbage = json.dumps({"version": 10000, "archive3dm": 60, "opennurbs": 1, "data": "AAAA"})
    assert _error(service, request("/round", garbage, ROUND_INPUTS)).startswith("Mesh:")
    line = rhino3dm.LineCurve(rhino3dm.Point3d(0, 0, 0), rhino3dm.Point3d(1, 0, 0))
    message = _error(service, request("/round", json.dumps(line.Encode()), ROUND_INPUTS))
    assert message.startswith("Mesh: expected a Rhino mesh")
    flat = rhino3dm.Mesh()
    for x, y in ((0, 0), (1, 0), (0, 1)):
        flat.Vertices.Add(x, y, float("nan") if x else 0.0)
    flat.Faces.AddFace(0, 1, 2)
    message = _error(service, request("/round", json.dumps(flat.Encode()), ROUND_INPUTS))
    assert "vertex 1" in message
    assert _error(service, request("/nothing", good, ROUND_INPUTS), "/nothing").startswith(
        "request: no component"
    )


def test_the_server_answers_over_http_on_this_machine_only():
    server = run_hops(port=0)
    try:
        with urllib.request.urlopen(server.url) as reply:
            listed = json.loads(reply.read())
        assert sorted(c["Name"] for c in listed) == ["Pattern", "Round"]
        with urllib.request.urlopen(server.url + "round") as reply:
            meta = json.loads(reply.read())
        assert [p["Name"] for p in meta["Inputs"]] == [
            "Mesh",
            "Radius",
            "Depth",
            "Samples",
            "Sharp",
        ]
        assert meta["Inputs"][1]["Default"] == "10%"
        bad = urllib.request.Request(server.url + "round", data=b"[]", method="POST")
        with pytest.raises(urllib.error.HTTPError) as failed:
            urllib.request.urlopen(bad)
        assert failed.value.code == 500
        assert json.loads(failed.value.read())["errors"] == ["request: no list of 'values'"]
        foreign = urllib.request.Request(
            server.url + "round", data=b"{}", headers={"Origin": "http://example.com"}
        )
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen(foreign)
        assert refused.value.code == 403
    finally:
        server.stop()


def test_a_host_other_machines_reach_is_refused():
    from filletfold.errors import ParameterError

    with pytest.raises(ParameterError, match="other machines"):
        run_hops(host="0.0.0.0", port=0)


def layer_counts(path) -> dict:
    """The number of objects on each layer of a ``.3dm`` file."""
    model = rhino3dm.File3dm.Read(str(path))
    layers = {layer.Index: layer.Name for layer in model.Layers}
    counts: dict = {}
    for obj in model.Objects:
        name = layers[obj.Attributes.LayerIndex]
        counts[name] = counts.get(name, 0) + 1
    return counts


def pattern_outputs(service, name: str, inputs: dict) -> dict:
    """The outputs of a *Pattern* request on a built-in example (branch {0}), asserting 200."""
    mesh = json.dumps(rhino_mesh(name).Encode())
    status, text = service.solve("/pattern", request("/pattern", mesh, inputs))
    assert status == 200, text
    return {k: v["0"] for k, v in outputs(text).items()}


def test_the_pattern_is_the_command_lines_pattern_3dm(service, tmp_path):
    """Pattern (size auto, sheets A4) gives the curves of the command line's pattern.3dm, layer
    by layer, and its sheets and labels."""
    folder = tmp_path / "ico"
    args = [
        "round",
        "icosahedron",
        "-o",
        str(folder),
        "--format",
        "3dm,json",
        "--sheet",
        "A4",
        "-q",
    ]
    assert main(args) == 0
    counts = layer_counts(folder / "pattern.3dm")
    inputs = {
        **ROUND_INPUTS,
        "Size": ("System.String", "auto"),
        "Sheet": ("System.String", "A4"),
        "Material": ("System.String", ""),
    }
    out = pattern_outputs(service, "icosahedron", inputs)
    for layer, name in (("CUT", "Cut"), ("MOUNTAIN", "Mountain"), ("TAB", "Tab")):
        assert len(out[name]) == counts[layer], layer
    assert len(out["Labels"]) == len(out["LabelPoints"]) == counts["LABEL"]
    assert out["Units"] == ["mm"]
    report = json.loads((folder / "report.json").read_text())
    assert len(out["Sheets"]) == report["fabrication"]["sheets"]


def test_the_pattern_in_a_sheet_material_has_its_reliefs_and_grooves(service, tmp_path):
    """Pattern with Material plywood-3mm: the reliefs and the kerf grooves of the command
    line's pattern.3dm, layer by layer; a bad material is one line naming it."""
    folder = tmp_path / "cube"
    args = ["round", "cube", "-o", str(folder), "--format", "3dm", "-q"]
    assert main([*args, "--material", "plywood-3mm", "--size", "1500mm"]) == 0
    counts = layer_counts(folder / "pattern.3dm")
    assert counts["RELIEF"] > 0 and counts["KERF_BACK"] > 0
    inputs = {
        **ROUND_INPUTS,
        "Size": ("System.String", "1500mm"),
        "Sheet": ("System.String", ""),
        "Material": ("System.String", "plywood-3mm"),
    }
    out = pattern_outputs(service, "cube", inputs)
    assert len(out["Relief"]) == counts["RELIEF"]
    assert len(out["KerfBack"]) == counts["KERF_BACK"]
    assert len(out.get("KerfFront", [])) == counts.get("KERF_FRONT", 0)
    inputs["Material"] = ("System.String", "cardboard")
    mesh = json.dumps(rhino_mesh("cube").Encode())
    status, text = service.solve("/pattern", request("/pattern", mesh, inputs))
    assert status != 200 and "unknown material 'cardboard'" in text and "\n" not in text.strip()
