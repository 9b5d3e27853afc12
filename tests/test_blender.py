"""The Blender extension (``blender/filletfold_blender``): its installable zip, and the extension
run headless in ``bpy`` on a built-in example, its objects and files held against the command
line's."""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest

from filletfold.cli import main

ROOT = Path(__file__).resolve().parents[1]
BLENDER = ROOT / "blender"
BPY_PYTHON = ROOT / "out" / "bpy-venv" / "bin" / "python"


def test_the_zip_holds_the_manifest_and_the_extension(tmp_path):
    sys.path.insert(0, str(BLENDER))
    try:
        import build_zip
    finally:
        sys.path.remove(str(BLENDER))
    target = build_zip.build(tmp_path)
    with zipfile.ZipFile(target) as zf:
        names = set(zf.namelist())
        manifest = tomllib.loads(zf.read("blender_manifest.toml").decode())
    assert {"blender_manifest.toml", "__init__.py", "engine.py"} <= names
    required = ("schema_version", "id", "version", "name", "tagline", "maintainer", "type")
    assert all(manifest[key] for key in required)
    assert manifest["type"] == "add-on" and manifest["blender_version_min"] >= "4.2.0"
    assert target.name == f"filletfold_blender-{manifest['version']}.zip"
    assert build_zip.build(tmp_path).read_bytes() == target.read_bytes()  # same bytes again


def _bpy_python() -> Path:
    """The Python of ``make bpy-venv`` (Blender 4.2 as a module and filletfold), built when
    missing; the test is skipped with the reason when it cannot be built."""
    if not (BPY_PYTHON.parent.parent / ".installed").exists():
        done = subprocess.run(
            ["make", "bpy-venv", f"PYTHON={sys.executable}"],
            cwd=ROOT, capture_output=True, text=True, timeout=1800,
        )  # fmt: skip
        if done.returncode != 0:
            why = (done.stderr.strip().splitlines() or ["no output"])[-1]
            pytest.skip(f"make bpy-venv failed (bpy 4.2 needs Python 3.11 and PyPI): {why}")
    return BPY_PYTHON


@pytest.mark.slow
def test_the_extension_in_bpy_makes_the_command_lines_design(tmp_path):
    python = _bpy_python()
    done = subprocess.run(
        [str(python), str(BLENDER / "check_extension.py"), "icosahedron", str(tmp_path),
         "--python", sys.executable],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    made = json.loads(done.stdout.strip().splitlines()[-1])
    # the objects: the mesh and its preview, a material per kind, the patches as attributes
    assert "icosahedron.filletfold" in made["objects"]
    assert made["materials"] == [f"filletfold {k}" for k in ("cone", "cylinder", "fillet", "face")]
    assert made["status"] == ["ok"] * 12
    assert made["message"].startswith("pattern:") or made["message"]
    # the files: those the command line writes for the same mesh (as Blender holds it)
    cli = tmp_path / "cli"
    assert main(["round", made["obj"], "-o", str(cli), "-q"]) == 0
    names = sorted(p.name for p in cli.iterdir())
    assert made["export"] == names
    assert made["subprocess_export"] == names
    ours = json.loads((tmp_path / "export" / "design.fold").read_text())
    theirs = json.loads((cli / "design.fold").read_text())
    for key in ("faces_vertices", "edges_assignment", "filletfold:faces_patch"):
        assert ours[key] == theirs[key], key
    np.testing.assert_allclose(ours["vertices_coords"], theirs["vertices_coords"], atol=1e-12)
    np.testing.assert_allclose(
        ours["file_frames"][0]["vertices_coords"],
        theirs["file_frames"][0]["vertices_coords"],
        atol=1e-12,
    )
    again = json.loads((tmp_path / "export-subprocess" / "design.fold").read_text())
    assert again["filletfold:faces_patch"] == theirs["filletfold:faces_patch"]
    # the preview's patches are the design's: the same patches by kind
    patches = theirs["filletfold:faces_patch"]
    kinds = ("cone", "cylinder", "fillet", "face")
    counts = {k: len({p for p in patches if p.split()[0] == k}) for k in kinds}
    shown = {}
    for kind, patch in zip(made["kinds"], made["patches"], strict=True):
        shown.setdefault(kinds[kind], set()).add(patch)
    assert {k: len(shown.get(k, ())) for k in kinds} == counts
    assert made["subprocess_faces"] == made["faces"]
    assert "no such file" in made["bad_python"][1]
