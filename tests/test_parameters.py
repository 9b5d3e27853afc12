"""One :class:`Parameters`: built by the API and the command line, written by the report,
read back by ``filletfold round --from`` to give the same design (the same bytes)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import filletfold
from filletfold.cli import main
from filletfold.errors import ParameterError
from filletfold.parameters import Parameters


def _files(folder: Path) -> dict:
    """Every file of a design folder but timings.json (the one that differs between runs)."""
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.name != "timings.json"}


def test_the_report_writes_the_parameters_it_reads_back():
    p = Parameters(
        radius=np.array([0.1, 0.2, 0.3]),
        depth={"default": "30%", 3: 0.5},
        max_loss="2%",
        sheet="A4",
        units="mm",
        scale=2.5,
        tabs=False,
        clamp=False,
    )
    text = json.dumps(p.as_dict())
    back = Parameters.from_dict(json.loads(text))
    assert json.dumps(back.as_dict()) == text
    assert isinstance(back.radius, np.ndarray) and back.radius.tolist() == [0.1, 0.2, 0.3]
    assert back.depth == {"default": "30%", "3": 0.5}
    assert list(p.as_dict()) == [f for f in Parameters.__dataclass_fields__]


def test_an_older_report_keeps_the_defaults_of_what_it_lacks():
    assert Parameters.from_dict({"radius": "5%"}) == Parameters(radius="5%")


@pytest.mark.parametrize(
    ("data", "match"),
    [
        ({"radius": "5%", "colour": "red"}, "unknown parameter 'colour'"),
        ({"samples": 2.5}, "samples must be integer, got number"),
        ({"samples": True}, "samples must be integer, got bool"),
        ({"clamp": "yes"}, "clamp must be bool or null, got string"),
        ({"radius": [[1, 2], [3, 4]]}, "radius must be a flat list of numbers"),
        ({"radius": ["a", 2]}, "radius must be a list of numbers"),
        (["radius"], "must be a JSON object, got list"),
    ],
)
def test_a_bad_report_parameter_is_named(data, match):
    with pytest.raises(ParameterError, match=match):
        Parameters.from_dict(data, where="report.json: parameters")


def test_replace_refuses_an_unknown_name():
    with pytest.raises(ParameterError, match="unknown parameter 'radiu'"):
        Parameters().replace(radiu="5%")
    with pytest.raises(ParameterError, match="unknown parameter 'radiu'"):
        filletfold.round_mesh("cube", radiu="5%")


def test_what_strict_decided_follows_a_new_strict():
    resolved = Parameters().resolved()
    assert resolved.clamp is True and resolved.fit_vertices is True
    strict = resolved.replace(strict=True).resolved()
    assert strict.clamp is False and strict.fit_vertices is False
    # a value chosen apart from strict stays
    chosen = Parameters(fit_vertices=False).resolved().replace(strict=True, clamp=True).resolved()
    assert chosen.clamp is True and chosen.fit_vertices is False
    kept = Parameters(clamp=False).resolved().replace(strict=True).resolved()
    assert kept.clamp is False


def test_what_material_loss_decided_follows_a_new_material_loss():
    resolved = Parameters().resolved()
    assert resolved.sharp == "saddle,infeasible,boundary"
    assert resolved.replace(material_loss=True).resolved().sharp == "saddle,infeasible"
    chosen = Parameters(sharp="saddle").resolved()
    assert chosen.replace(material_loss=True).resolved().sharp == "saddle"


def test_a_parameters_object_and_keywords_give_the_same_design():
    by_object = filletfold.round_mesh("l-prism", Parameters(radius="15%", samples=8))
    by_keywords = filletfold.round_mesh("l-prism", radius="15%", samples=8)
    assert by_object.params == by_keywords.params
    assert by_object.params.radius == "15%" and by_object.params.clamp is True
    np.testing.assert_array_equal(by_object.pattern.vertices_2d, by_keywords.pattern.vertices_2d)
    # keywords replace the object's fields
    both = filletfold.round_mesh("l-prism", Parameters(radius="15%"), radius="12%")
    assert both.params.radius == "12%"


def test_round_from_its_report_gives_the_same_files(tmp_path, capsys):
    first, again = tmp_path / "first", tmp_path / "again"
    args = ["round", "l-prism", "-o", str(first), "-r", "12%", "--depth", "40%", "-n", "8"]
    assert main([*args, "--no-tabs", "--sharp", "saddle", "--units", "cm", "--scale", "2"]) == 0
    assert main(["round", "--from", str(first / "report.json"), "-o", str(again)]) == 0
    assert _files(first) == _files(again)
    report = json.loads((again / "report.json").read_text())
    assert report["parameters"]["tabs"] is False and report["parameters"]["units"] == "cm"


def test_options_given_with_from_replace_the_reports(tmp_path):
    first, again = tmp_path / "first", tmp_path / "again"
    assert main(["round", "cube", "-o", str(first), "-r", "12%", "--no-tabs"]) == 0
    assert main(["round", "--from", str(first / "report.json"), "-o", str(again), "-d", "45%"]) == 0
    params = json.loads((again / "report.json").read_text())["parameters"]
    assert params["radius"] == "12%" and params["depth"] == "45%" and params["tabs"] is False
    # a mesh given too replaces the report's
    other = tmp_path / "other"
    assert (
        main(["round", "octahedron", "--from", str(first / "report.json"), "-o", str(other)]) == 0
    )
    report = json.loads((other / "report.json").read_text())
    assert report["source"] == "octahedron" and report["parameters"]["radius"] == "12%"


def test_a_design_of_the_api_is_made_again_from_its_report(tmp_path):
    """Per-edge radii and per-vertex depths go through the report too."""
    base = filletfold.round_mesh("cube")
    radius = np.full(base.mesh.n_edges, 0.08)
    radius[:4] = 0.12
    design = filletfold.round_mesh("cube", radius=radius, depth={"default": "30%", 3: 0.5})
    first, again = tmp_path / "first", tmp_path / "again"
    design.export(first)
    assert main(["round", "--from", str(first / "report.json"), "-o", str(again)]) == 0
    assert _files(first) == _files(again)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (None, "no such file"),
        ("{", "invalid JSON"),
        ("[" * 100000 + "]" * 100000, "nested too deeply"),
        ('{"source": "cube"}', "not a filletfold report (no object 'parameters')"),
        ('{"parameters": {}}', "not a filletfold report (no string 'source')"),
        ('{"source": "cube", "parameters": {"radius": true}}', "radius must be"),
    ],
)
def test_a_bad_report_is_a_one_line_error(tmp_path, capsys, text, match):
    report = tmp_path / "report.json"
    if text is not None:
        report.write_text(text)
    assert main(["round", "--from", str(report), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "error:" in err and match in " ".join(err.split())
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_round_needs_a_mesh_or_a_report(capsys):
    assert main(["round"]) == 2
    err = capsys.readouterr().err
    assert "give MESH" in err and len(err.strip().splitlines()) == 1
