"""The command line: thin front end, clear errors, no tracebacks."""

from __future__ import annotations

import json

import pytest

from filletfold.cli import main


def test_examples_lists_the_builtins(capsys):
    assert main(["examples"]) == 0
    out = capsys.readouterr().out
    for name in ("icosahedron", "cube", "torus", "open-box"):
        assert name in out


def test_round_writes_the_design(tmp_path, capsys):
    out = tmp_path / "ico"
    assert main(["round", "icosahedron", "-o", str(out), "--radius", "0.15", "--depth", "0.3"]) == 0
    text = capsys.readouterr().out
    assert "12 ok" in text and "wrote 7 files" in text
    report = json.loads((out / "report.json").read_text())
    assert report["parameters"]["radius"] == "0.15"
    assert report["status_counts"]["ok"] == 12


def test_relative_radius_and_depth(tmp_path):
    assert (
        main(
            [
                "round",
                "cube",
                "--radius",
                "10%",
                "--depth",
                "60%",
                "--report-tables",
                "-o",
                f"{tmp_path}/c",
            ]
        )
        == 0
    )
    report = json.loads((tmp_path / "c" / "report.json").read_text())
    assert report["edges"][0]["radius"] == pytest.approx(0.1)
    assert report["vertices"][0]["depth_requested"] == pytest.approx(0.6)


@pytest.mark.slow  # fast tier near its budget: in make test-slow (CI runs both)
def test_arc_step_sets_the_points_per_arc(tmp_path):
    """--arc-step is recorded in the report; a finer step (or 0) gives more pattern faces."""
    faces = {}
    for step in ("0", "1.5", "6"):
        out = tmp_path / f"sphere-{step}"
        args = ["round", "geodesic-sphere", "--arc-step", step, "--chord-tol", "0"]
        args += ["--format", "fold,json"]
        args += ["-o", str(out)]
        assert main(args) == 0
        report = json.loads((out / "report.json").read_text())
        assert report["parameters"]["arc_step"] == float(step)
        faces[step] = len(json.loads((out / "design.fold").read_text())["faces_vertices"])
    assert faces["0"] > faces["1.5"] > faces["6"]


def test_dry_run_writes_nothing(tmp_path):
    assert main(["round", "cube", "--dry-run", "-o", str(tmp_path / "x")]) == 0
    assert not (tmp_path / "x").exists()


def test_file_input_and_clamp(tmp_path):
    from filletfold.mesh import example_mesh, write_obj

    v, f = example_mesh("house")
    write_obj(tmp_path / "house.obj", v, f)
    assert (
        main(
            [
                "round",
                str(tmp_path / "house.obj"),
                "--radius",
                "40%",
                "--clamp",
                "-o",
                str(tmp_path / "h"),
            ]
        )
        == 0
    )
    assert (tmp_path / "h" / "design.fold").exists()


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["round", "no-such-thing"], "no such file and no built-in example"),
        (["round", "cube", "--radius", "3", "--strict-radius"], "exceeds its limit"),
        (["round", "cube", "--radius", "3", "--strict"], "exceeds its limit"),
        (["round", "cube", "--depth", "abc"], "depth must be a number"),
        (["round", "cube", "--arc-step", "-1"], "arc step must be in [0, 180] degrees"),
        (["round", "cube", "--view", "sideways"], "view must be front, back, top, side"),
    ],
)
def test_errors_are_one_line_with_exit_code_2(args, match, capsys, tmp_path):
    assert main([*args, "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "error:" in err and match in " ".join(err.split())
    assert len(err.strip().splitlines()) == 1  # one line, never wrapped
    assert "Traceback" not in err
    assert not (tmp_path / "o").exists()


def duplicate_face_obj(path):
    """A tetrahedron with its first face given twice."""
    path.write_text(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\nf 1 3 2\n"
    )
    return path


def test_defects_are_repaired_and_listed_or_refused_with_strict(tmp_path, capsys):
    mesh = duplicate_face_obj(tmp_path / "dup.obj")
    assert main(["round", str(mesh), "-o", str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    assert "repairs: 1 (1 drop-face" in out and "face 4: it uses the same vertices" in out
    report = json.loads((tmp_path / "o" / "report.json").read_text())
    assert report["repairs"] == [
        {
            "what": "drop-face",
            "where": "face 4",
            "why": "it uses the same vertices as face 0 (duplicate face)",
        }
    ]
    assert report["certificate"]["ok"] is True
    assert main(["round", str(mesh), "--strict", "-o", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert "degenerate face 4: it uses the same vertices as face 0" in err
    assert not (tmp_path / "s").exists()


def test_unforeseen_failure_is_one_line_and_debug_shows_the_traceback(
    tmp_path, capsys, monkeypatch
):
    from filletfold import pipeline

    def broken(*args, **kwargs):
        raise ZeroDivisionError("float division by zero\nsecond line")

    monkeypatch.setattr(pipeline, "face_piece_centres", broken)
    assert main(["round", "cube", "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines() == [
        "error: rounding the edges failed: ZeroDivisionError: float division by zero (run "
        "with --debug for the traceback)"
    ]
    assert main(["round", "cube", "--debug", "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err and "in broken" in err
    assert err.strip().splitlines()[-1].startswith("error: rounding the edges failed")
    assert not (tmp_path / "o").exists()


def test_unreadable_file(tmp_path, capsys):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 banana\n")
    assert main(["round", str(bad), "-o", str(tmp_path / "o")]) == 2
    assert "bad.obj" in capsys.readouterr().err


def test_material_loss_reports_the_programme(tmp_path, capsys):
    assert (
        main(
            [
                "round",
                "cube",
                "--material-loss",
                "--max-loss",
                "5%",
                "--report-tables",
                "-o",
                f"{tmp_path}/c",
            ]
        )
        == 0
    )
    out = " ".join(capsys.readouterr().out.split())
    assert "material loss: b =" in out and "not developable at 8 vertices" in out
    report = json.loads((tmp_path / "c" / "report.json").read_text())
    assert report["material_loss"]["ok"] is True and report["material_loss"]["bound"] > 0
    assert report["layout"]["kind"] == "net"  # not developable: not one sheet
    assert max(e["material_loss"] for e in report["edges"]) <= 0.05 + 1e-9


def test_material_loss_without_solution_is_an_error(capsys, tmp_path):
    assert main(["round", "random-convex", "--material-loss", "-o", str(tmp_path / "o")]) == 2
    assert "no consistent material loss" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.slow  # every format, written by the command: the fast tier under 3 minutes
def test_net_on_sheets_with_all_formats(tmp_path, capsys):
    out = tmp_path / "n"
    args = [
        "round",
        "dodecahedron",
        "--layout",
        "net",
        "--sheet",
        "A4",
        "--units",
        "mm",
        "--scale",
        "60",
        "--format",
        "all",
        "-o",
        str(out),
    ]
    assert main(args) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "(net)" in text and "glue tabs:" in text and "sheets:" in text
    names = sorted(p.name for p in out.iterdir())
    assert names == [
        "annotations.json",
        "assembly.pdf",
        "assembly.txt",
        "design.fold",
        "folded.3dm",
        "folded.glb",
        "folded.obj",
        "folded.ply",
        "folded.stl",
        "pattern.3dm",
        "pattern.dxf",
        "pattern.pdf",
        "pattern.png",
        "pattern.svg",
        "preview.png",
        "report.json",
        "simulator.fold",
        "simulator.svg",
        "timings.json",
    ]
    fab = json.loads((out / "report.json").read_text())["fabrication"]
    assert fab["sheets"] == len(fab["pieces_per_sheet"]) and fab["pieces"] < 20


def test_no_tabs(tmp_path):
    assert main(["round", "cube", "--no-tabs", "-o", str(tmp_path / "c")]) == 0
    fab = json.loads((tmp_path / "c" / "report.json").read_text())["fabrication"]
    assert fab["tabs"] == 0 and fab["cut_borders"] == 0


@pytest.mark.slow  # pictures drawn: the fast tier under 3 minutes
def test_view_turns_the_preview_only(tmp_path):
    """--view back draws preview.png from the other side; the other files keep their bytes."""
    for view in ("front", "back"):
        args = ["round", "tetrahedron", "--format", "fold,png,svg", "--view", view, "-q"]
        assert main([*args, "-o", str(tmp_path / view)]) == 0
    front, back = tmp_path / "front", tmp_path / "back"
    assert (front / "pattern.svg").read_bytes() == (back / "pattern.svg").read_bytes()
    assert (front / "pattern.png").read_bytes() == (back / "pattern.png").read_bytes()
    assert (front / "preview.png").read_bytes() != (back / "preview.png").read_bytes()
    # export reads design.fold (coordinates rounded in the file): the same file, the same view
    assert (front / "design.fold").read_bytes() == (back / "design.fold").read_bytes()
    assert main(["export", str(front), "--format", "png", "--view", "back"]) == 0
    assert main(["export", str(back), "--format", "png", "--view", "120,25"]) == 0
    assert (front / "preview.png").read_bytes() == (back / "preview.png").read_bytes()


def test_a_log_gets_a_line_per_stage(tmp_path, capsys):
    """With stderr not a terminal (CI, a pipe), progress is one line per stage with its
    seconds and counts; --quiet prints none."""
    import subprocess
    import sys

    out = str(tmp_path / "ico")
    cmd = [sys.executable, "-m", "filletfold", "round", "icosahedron", "-o", out]
    done = subprocess.run(cmd, capture_output=True, text=True, check=True)
    lines = [line for line in done.stderr.splitlines() if line.startswith("filletfold: ")]
    names = [line.split(" in ")[0] for line in lines]
    assert names[0] == "filletfold: reading the mesh"
    assert any(n.startswith("filletfold: apices ") and "/" in n for n in names)
    assert "filletfold: certificate" in names and names[-1] == "filletfold: writing the files"
    assert all(line.endswith(" s") for line in lines)
    # --quiet: none (in this process, whose captured stderr is not a terminal either)
    capsys.readouterr()
    assert main(["round", "icosahedron", "--quiet", "-o", str(tmp_path / "quiet")]) == 0
    assert "filletfold: " not in capsys.readouterr().err
