"""All-or-nothing output writing."""

from __future__ import annotations

import errno
import os

import pytest

from filletfold.errors import ExportError
from filletfold.export import write_file_atomic, write_outputs


def _snapshot(root):
    """Every path under ``root`` with the bytes of each file (None for folders)."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for d in dirnames:
            out[os.path.relpath(os.path.join(dirpath, d), root)] = None
        for f in filenames:
            p = os.path.join(dirpath, f)
            with open(p, "rb") as fh:
                out[os.path.relpath(p, root)] = fh.read()
    return out


@pytest.fixture
def existing(tmp_path):
    """A folder ``out`` holding ``a.txt`` and ``b.txt`` (old versions) and ``keep.txt``."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.txt").write_bytes(b"old a")
    (out / "b.txt").write_bytes(b"old b")
    (out / "keep.txt").write_bytes(b"keep")
    return out


def _fail_replace_on(monkeypatch, call: int, exc: OSError):
    """Make the ``call``-th os.replace raise ``exc`` (later calls work again)."""
    real = os.replace
    count = {"n": 0}

    def fake(src, dst, *args, **kwargs):
        count["n"] += 1
        if count["n"] == call:
            raise exc
        return real(src, dst, *args, **kwargs)

    monkeypatch.setattr(os, "replace", fake)
    return count


def test_write_outputs_success(tmp_path):
    folder = tmp_path / "deep" / "er" / "out"
    files = {"p.svg": "<svg>é</svg>\n", "m.obj": "v 0 0 0\r\n", "b.bin": b"\x00\x01"}
    paths = write_outputs(folder, files)
    assert paths == [folder / "p.svg", folder / "m.obj", folder / "b.bin"]
    assert (folder / "p.svg").read_bytes() == "<svg>é</svg>\n".encode()
    assert (folder / "m.obj").read_bytes() == b"v 0 0 0\r\n"
    assert (folder / "b.bin").read_bytes() == b"\x00\x01"
    # nothing but the folder beside it: the temporary directory is gone
    assert sorted(p.name for p in folder.parent.iterdir()) == ["out"]


def test_write_outputs_replaces_and_keeps_others(existing):
    write_outputs(existing, {"a.txt": "new a", "c.txt": "new c"})
    snap = _snapshot(existing)
    assert snap == {"a.txt": b"new a", "b.txt": b"old b", "c.txt": b"new c", "keep.txt": b"keep"}
    assert sorted(p.name for p in existing.parent.iterdir()) == ["out"]


def test_write_outputs_bad_value_midway_changes_nothing(existing):
    before = _snapshot(existing.parent)
    match = r"'b\.txt': contents must be str, bytes or an iterator of str, not int"
    with pytest.raises(ExportError, match=match):
        write_outputs(existing, {"a.txt": "new a", "b.txt": 123, "c.txt": "new c"})
    assert _snapshot(existing.parent) == before


def test_write_outputs_replace_fails_on_second_file(existing, monkeypatch):
    before = _snapshot(existing.parent)
    count = _fail_replace_on(monkeypatch, 2, OSError(errno.EIO, "Input/output error"))
    with pytest.raises(ExportError, match=r"cannot write into .*Input/output error"):
        write_outputs(existing, {"a.txt": "new a", "b.txt": "new b", "c.txt": "new c"})
    assert count["n"] >= 2
    assert _snapshot(existing.parent) == before


def test_write_outputs_new_file_removed_on_failure(existing, monkeypatch):
    before = _snapshot(existing.parent)
    _fail_replace_on(monkeypatch, 2, OSError(errno.EIO, "Input/output error"))
    with pytest.raises(ExportError):
        write_outputs(existing, {"new.txt": "x", "a.txt": "new a"})
    assert _snapshot(existing.parent) == before


def test_write_outputs_created_folder_removed_on_failure(tmp_path):
    folder = tmp_path / "x" / "y"
    with pytest.raises(ExportError, match="must be str, bytes or an iterator of str"):
        write_outputs(folder, {"a.txt": "a", "b.txt": None})
    assert list(tmp_path.iterdir()) == []


def test_write_outputs_permission_denied(existing, monkeypatch):
    before = _snapshot(existing.parent)
    _fail_replace_on(monkeypatch, 1, PermissionError(errno.EACCES, "Permission denied"))
    with pytest.raises(ExportError, match="permission denied"):
        write_outputs(existing, {"a.txt": "new a"})
    assert _snapshot(existing.parent) == before


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="needs a non-root POSIX user")
def test_write_outputs_read_only_folder(existing):
    existing.parent.chmod(0o500)
    try:
        with pytest.raises(ExportError, match="permission denied"):
            write_outputs(existing, {"a.txt": "new a"})
    finally:
        existing.parent.chmod(0o700)
    assert (existing / "a.txt").read_bytes() == b"old a"


def test_write_outputs_folder_is_a_file(tmp_path):
    f = tmp_path / "out"
    f.write_text("I am a file")
    with pytest.raises(ExportError, match="it is a file, not a folder"):
        write_outputs(f, {"a.txt": "a"})
    assert f.read_text() == "I am a file"


def test_write_outputs_parent_is_a_file(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    with pytest.raises(ExportError, match="is a file, not a folder"):
        write_outputs(f / "sub" / "out", {"a.txt": "a"})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_write_outputs_target_is_a_folder(existing):
    (existing / "a.txt").unlink()
    (existing / "a.txt").mkdir()
    with pytest.raises(ExportError, match="a folder of that name exists"):
        write_outputs(existing, {"a.txt": "a"})


@pytest.mark.parametrize("name", ["", "../x", "sub/x", ".", "..", 3])
def test_write_outputs_bad_names(tmp_path, name):
    with pytest.raises(ExportError, match="name"):
        write_outputs(tmp_path / "out", {name: "x"})
    assert list(tmp_path.iterdir()) == []


def test_write_file_atomic(tmp_path):
    p = tmp_path / "a" / "b.json"
    assert write_file_atomic(p, "{}\n") == p
    assert p.read_text() == "{}\n"
    write_file_atomic(p, b"[]")
    assert p.read_bytes() == b"[]"
    assert sorted(x.name for x in p.parent.iterdir()) == ["b.json"]


def test_write_file_atomic_failure_keeps_old(tmp_path, monkeypatch):
    p = tmp_path / "b.json"
    p.write_text("old")
    _fail_replace_on(monkeypatch, 1, OSError(errno.ENOSPC, "No space left on device"))
    with pytest.raises(ExportError, match="no space left on device"):
        write_file_atomic(p, "new")
    assert p.read_text() == "old"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["b.json"]


def test_write_file_atomic_rejects(tmp_path):
    with pytest.raises(ExportError, match="must be str, bytes or an iterator of str, not list"):
        write_file_atomic(tmp_path / "x", [1])
    (tmp_path / "d").mkdir()
    with pytest.raises(ExportError, match="it is a folder"):
        write_file_atomic(tmp_path / "d", "x")
    assert sorted(x.name for x in tmp_path.iterdir()) == ["d"]


def test_contents_built_when_written_and_a_failing_build_writes_nothing(tmp_path):
    """Callables are built one at a time, in order, as their files are written (one file's
    contents in memory at a time); one that fails leaves the folder as it was."""
    calls = []

    def first():
        calls.append("a")
        return "A"

    def broken():
        calls.append("b")
        raise ValueError("boom")

    out = tmp_path / "o"
    with pytest.raises(ExportError, match="boom"):
        write_outputs(out, {"a.txt": first, "b.txt": broken})
    assert calls == ["a", "b"] and not out.exists()
    write_outputs(out, {"a.txt": first, "b.bin": lambda: b"B"})
    assert (out / "a.txt").read_text() == "A" and (out / "b.bin").read_bytes() == b"B"


def test_text_is_encoded_a_chunk_at_a_time(tmp_path, monkeypatch):
    """Text is written as UTF-8 in chunks of characters (no encoded copy of the whole text):
    the file holds exactly the text's encoding, multi-byte characters across chunk ends too."""
    from filletfold.export import atomic

    monkeypatch.setattr(atomic, "ENCODE_CHUNK", 3)
    text = "aé€\U0001d11eb" * 7 + "\n"
    write_outputs(tmp_path / "out", {"t.txt": text, "b.bin": b"\x00\xff"})
    assert (tmp_path / "out" / "t.txt").read_bytes() == text.encode("utf-8")
    assert (tmp_path / "out" / "b.bin").read_bytes() == b"\x00\xff"
    write_file_atomic(tmp_path / "one.txt", text)
    assert (tmp_path / "one.txt").read_bytes() == text.encode("utf-8")


def test_text_chunks_are_written_as_they_come_and_a_bad_one_writes_nothing(existing):
    """An iterator of text is written a chunk at a time (each made only when its turn comes);
    one that fails, or yields something that is not text, leaves the folder as it was."""
    made = []

    def chunks(n, bad=None):
        for i in range(n):
            if i == bad:
                yield b"not text"
            made.append(i)
            yield f"part {i}\n"

    write_outputs(existing, {"a.txt": chunks(3)})
    assert (existing / "a.txt").read_text() == "part 0\npart 1\npart 2\n" and made == [0, 1, 2]
    before = _snapshot(existing.parent)
    with pytest.raises(ExportError, match="a text chunk must be str, not bytes"):
        write_outputs(existing, {"c.txt": "new c", "a.txt": chunks(3, bad=1)})
    assert _snapshot(existing.parent) == before

    def broken():
        yield "half"
        raise ValueError("boom")

    with pytest.raises(ExportError, match="boom"):
        write_outputs(existing, {"a.txt": broken()})
    assert _snapshot(existing.parent) == before
