"""The design folder written whole (issue 30): new or old, never a mix; the user's files
refused or kept; the input never overwritten; what a killed run left cleaned up."""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from filletfold.errors import ExportError
from filletfold.export import folder as ff
from filletfold.export.folder import DESIGN_FILES, write_design_folder


def _files(token: str, names=("design.fold", "report.json", "pattern.svg")) -> dict:
    return {n: f"{n} {token}\n" for n in names}


def _tokens(folder: Path) -> set:
    return {p.read_text().split()[-1] for p in folder.iterdir()}


def test_a_new_design_replaces_the_old_one_whole(tmp_path):
    out = tmp_path / "out"
    write_design_folder(out, _files("1", ("design.fold", "report.json", "pattern.pdf")))
    written = write_design_folder(out, _files("2"))
    assert sorted(p.name for p in out.iterdir()) == sorted(p.name for p in written)
    assert "pattern.pdf" not in {p.name for p in out.iterdir()}  # no file of the old design
    assert _tokens(out) == {"2"}
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no staging folder left


def test_a_folder_of_the_users_files_is_refused_unless_forced(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    (out / "pattern.pdf").write_text("an old design's file")
    with pytest.raises(ExportError, match=r"mine holds files filletfold did not write \(notes"):
        write_design_folder(out, _files("1"))
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt", "pattern.pdf"]
    write_design_folder(out, _files("1"), force=True)
    names = sorted(p.name for p in out.iterdir())
    assert names == ["design.fold", "notes.txt", "pattern.svg", "report.json"]
    assert (out / "notes.txt").read_text() == "keep me"


def test_the_input_mesh_is_never_overwritten(tmp_path):
    out = tmp_path / "here"
    out.mkdir()
    mesh = out / "folded.obj"
    mesh.write_text("v 0 0 0\n")
    for force in (False, True):
        with pytest.raises(ExportError, match=r"folded\.obj is the input mesh"):
            write_design_folder(out, _files("1", ("folded.obj",)), force=force, inputs=[mesh])
    assert mesh.read_text() == "v 0 0 0\n"


def test_what_a_killed_run_left_is_cleaned_up_or_put_back(tmp_path):
    out = tmp_path / "out"
    write_design_folder(out, _files("1"))
    dead = _dead_pid()
    stale = tmp_path / f".out.{ff.STAGING_MARK}-{dead}-new-abc"
    stale.mkdir()
    (stale / "design.fold").write_text("half")
    write_design_folder(out, _files("2"))
    assert not stale.exists() and _tokens(out) == {"2"}
    # killed between its two renames: the old design aside, no folder; put back, then replaced
    aside = tmp_path / f".out.{ff.STAGING_MARK}-{dead}-old-xyz"
    aside.mkdir()
    os.rename(out, aside / "design")
    assert not out.exists()
    ff._clean_stale(out)
    assert _tokens(out) == {"2"} and not aside.exists()


def test_a_running_writers_staging_folder_is_left_alone(tmp_path):
    out = tmp_path / "out"
    busy = tmp_path / f".out.{ff.STAGING_MARK}-{os.getppid()}-new-abc"
    busy.mkdir()
    write_design_folder(out, _files("1"))
    assert busy.is_dir()


def test_every_name_a_design_writes_is_a_design_file():
    assert {"design.fold", "report.json", "timings.json", "assembly.txt"} <= DESIGN_FILES


_CHILD = """
import sys
from filletfold.export import folder as ff
if sys.argv[2] == "renames":
    ff._exchange = lambda a, b: False
names = ["design.fold"] + [f"part{i}.txt" for i in range(5)]
ff.DESIGN_FILES = ff.DESIGN_FILES | set(names)
g = 0
while True:
    g += 1
    ff.write_design_folder(sys.argv[1], {n: (f"{g} " * 200_000) + str(g) for n in names})
    if g == 1:
        print("written", flush=True)  # the kill comes at a random moment after this
"""


@pytest.mark.parametrize(
    ("mode", "kills"),
    [
        pytest.param("exchange", 2, id="exchange-2"),
        pytest.param("exchange", 12, id="exchange-12", marks=pytest.mark.slow),
        pytest.param("renames", 12, id="renames-12", marks=pytest.mark.slow),
    ],
)
def test_a_run_killed_at_any_moment_leaves_the_old_design_or_the_new(tmp_path, mode, kills):
    """A writer killed (SIGKILL) at random moments: the folder is always one whole design
    (every file of one generation), once the next run has put back what the kill left."""
    rng = random.Random(30)
    env = {**os.environ, "PYTHONPATH": str(Path(ff.__file__).parents[2])}
    out = tmp_path / "out"
    seen = set()
    for _ in range(kills):
        child = subprocess.Popen(
            [sys.executable, "-c", _CHILD, str(out), mode], env=env, stdout=subprocess.PIPE
        )
        assert child.stdout.readline() == b"written\n"  # one whole design, however loaded
        time.sleep(rng.random() * 0.6)  # then killed at a random moment of the next writes
        child.send_signal(signal.SIGKILL)
        child.wait()
        child.stdout.close()
        ff._clean_stale(out)
        if not out.exists():
            continue
        names = sorted(p.name for p in out.iterdir())
        assert names == ["design.fold"] + [f"part{i}.txt" for i in range(5)], names
        tokens = _tokens(out)
        assert len(tokens) == 1, tokens
        seen |= tokens
    assert seen  # at least one design was whole on disk
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def _dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_files_without_a_design_are_added_to_the_design_there(tmp_path):
    out = tmp_path / "out"
    write_design_folder(out, _files("1"))
    write_design_folder(out, _files("2", ("pattern.png", "preview.png")))
    names = sorted(p.name for p in out.iterdir())
    assert names == ["design.fold", "pattern.png", "pattern.svg", "preview.png", "report.json"]


def test_the_design_folder_has_the_permissions_mkdir_gives(tmp_path):
    """Not the owner-only ones of a temporary folder: the staged folder becomes the output."""
    out = tmp_path / "out"
    write_design_folder(out, _files("1"))
    mask = os.umask(0)
    os.umask(mask)
    assert (out.stat().st_mode & 0o777) == 0o777 & ~mask
    out.chmod(0o750)
    write_design_folder(out, _files("2"))  # replaced: its permissions kept
    assert (out.stat().st_mode & 0o777) == 0o750
