"""All-or-nothing writing of output files.

:func:`write_outputs` writes a set of files into one folder so that either every file is
replaced by its new contents or the folder is left exactly as it was. :func:`write_file_atomic`
does the same for one file.

The files are first written and fsynced in a temporary directory created beside the folder (so
on the same filesystem), then moved in with :func:`os.replace`, which is atomic per file. Before a
file is replaced, its old version is kept as a hard link (or a copy) in the temporary directory;
if a later move fails, the files already moved are put back and new ones removed.
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path

from ..errors import ExportError

__all__ = ["STAGING_MARK", "write_file_atomic", "write_outputs"]

#: What a staging folder's name holds after its target's name: ``.NAME.filletfold-PID-...``
#: (the writing process, so that a later run can tell a killed run's folder from a live one).
STAGING_MARK = "filletfold"
_STAGING = re.compile(rf"^\.(?P<name>.*)\.{STAGING_MARK}-(?P<pid>\d+)-(?P<kind>new|old)-")


def _encode(name: str, data) -> str | bytes | Iterator[str]:
    """``data`` ready for :func:`_write_all`: ``str`` as it is (encoded as UTF-8 while it is
    written), bytes-like values as bytes, an iterator of ``str`` chunks as it is (each chunk
    written as it comes)."""
    if isinstance(data, str):
        return data
    if isinstance(data, bytes | bytearray | memoryview):
        return bytes(data)
    if isinstance(data, Iterator):
        return data
    raise ExportError(
        f"cannot write {name!r}: contents must be str, bytes or an iterator of str, "
        f"not {type(data).__name__}"
    )


#: Characters of a text encoded at a time while it is written (the encoded copy of a whole
#: large text would double the export's peak memory).
ENCODE_CHUNK = 1 << 24


def _write_all(fh, data: str | bytes | Iterator[str]) -> None:
    """Write ``data`` to the binary file ``fh``: a ``str`` (or each ``str`` of an iterator)
    as UTF-8, :data:`ENCODE_CHUNK` characters at a time."""
    if isinstance(data, bytes):
        fh.write(data)
        return
    for text in (data,) if isinstance(data, str) else data:
        if not isinstance(text, str):
            raise ExportError(f"a text chunk must be str, not {type(text).__name__}")
        for i in range(0, len(text), ENCODE_CHUNK):
            fh.write(text[i : i + ENCODE_CHUNK].encode("utf-8"))


def _os_message(exc: OSError, what: str) -> str:
    """A one-line message for an OS error about ``what``."""
    if isinstance(exc, PermissionError) or exc.errno in (errno.EACCES, errno.EPERM):
        return f"cannot write {what}: permission denied"
    if exc.errno == errno.ENOSPC:
        return f"cannot write {what}: no space left on device"
    if exc.errno == errno.EROFS:
        return f"cannot write {what}: read-only file system"
    reason = exc.strerror or str(exc) or type(exc).__name__
    return f"cannot write {what}: {reason}"


def _check_name(name) -> str:
    """Validate one file name of :func:`write_outputs`: a plain name, no directory part."""
    if not isinstance(name, str) or not name:
        raise ExportError(f"output file name must be a non-empty string, got {name!r}")
    if name in (".", "..") or "/" in name or "\\" in name or "\0" in name:
        raise ExportError(f"output file name {name!r} must be a plain name without a directory")
    return name


def _make_dirs(folder: Path) -> list[Path]:
    """Create ``folder`` and missing parents; return the directories created, outermost first."""
    missing = []
    p = folder
    while not p.exists() and not p.is_symlink():
        missing.append(p)
        if p.parent == p:
            break
        p = p.parent
    if p.exists() and not p.is_dir():
        raise ExportError(f"cannot write into {folder}: {p} is a file, not a folder")
    created = []
    try:
        for d in reversed(missing):
            d.mkdir()
            created.append(d)
    except FileExistsError:
        # created concurrently by someone else; fine if it is a directory
        if not folder.is_dir():
            _remove_dirs(created)
            raise ExportError(f"cannot write into {folder}: it is not a folder") from None
    except OSError as exc:
        _remove_dirs(created)
        raise ExportError(_os_message(exc, f"folder {folder}")) from exc
    return created


def _remove_dirs(created: list[Path]) -> None:
    """Remove the directories of :func:`_make_dirs` again, innermost first, if empty."""
    for d in reversed(created):
        try:
            d.rmdir()
        except OSError:
            break


def _write_synced(path: Path, data: str | bytes | Iterator[str]) -> None:
    """Write ``data`` to a new file ``path`` and fsync it."""
    with open(path, "xb") as fh:
        _write_all(fh, data)
        fh.flush()
        os.fsync(fh.fileno())


def _write_staged(folder: Path, files: Mapping, names: list) -> None:
    """Write the files ``names`` of ``files`` (contents, or functions giving them) into the
    staging folder ``folder``, each fsynced, one file's contents in memory at a time."""
    for n in names:
        data = files[n]
        data = _encode(n, data() if callable(data) else data)
        _write_synced(folder / n, data)
        del data


def _fsync_dir(folder: Path) -> None:
    """Flush a directory entry change to disk where the platform allows it."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _prefix(folder: Path, kind: str) -> str:
    return f".{folder.name or 'out'}.{STAGING_MARK}-{os.getpid()}-{kind}-"


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's process: alive
        return True
    return True


def _clean_stale(folder: Path) -> None:
    """Remove the staging folders beside ``folder`` of runs whose process is gone; put back
    an old design a run killed between its two renames left aside (the folder missing)."""
    parent = folder.parent
    if not parent.is_dir():
        return
    try:
        entries = list(parent.iterdir())
    except OSError:
        return
    for entry in sorted(entries):
        m = _STAGING.match(entry.name)
        if not m or m["name"] != (folder.name or "out") or not entry.is_dir():
            continue
        if _alive(int(m["pid"])):
            continue
        kept = entry / "design"
        if m["kind"] == "old" and kept.is_dir() and not folder.exists():
            try:
                os.rename(kept, folder)
            except OSError:
                continue
        shutil.rmtree(entry, ignore_errors=True)


def _keep_old(target: Path, backup: Path) -> bool:
    """Preserve the current ``target`` (if any) at ``backup``; return whether there was one."""
    if not target.exists():
        return False
    try:
        os.link(target, backup)
    except OSError:
        shutil.copy2(target, backup)
    return True


def write_outputs(folder, files: Mapping[str, str | bytes]) -> list[Path]:
    """Write several files into ``folder``, all or nothing.

    Parameters
    ----------
    folder : str or os.PathLike
        Destination folder; created, with its parents, when missing.
    files : mapping of str to str, bytes, iterator of str, or callable
        File name (a plain name, no directory part) to contents, or to a function without
        arguments that returns them (called just before its file is written, so only one
        file's contents need to be in memory at a time). ``str`` contents are written as UTF-8
        without newline translation; an iterator's chunks are written as they come (a file
        made a part at a time is never whole in memory).

    Returns
    -------
    list of pathlib.Path
        The written paths, in the order of ``files``.

    Raises
    ------
    ExportError
        When a name or a value is invalid, ``folder`` (or a parent) is a file, a target name is an
        existing folder, or the OS refuses a write (permission denied, disk full...). When it is
        raised, ``folder`` holds exactly what it held before (and is removed again if this call
        created it), and no temporary directory is left behind.
    """
    folder = Path(folder)
    names = [_check_name(n) for n in files]
    if folder.exists() and not folder.is_dir():
        raise ExportError(f"cannot write into {folder}: it is a file, not a folder")
    for n in names:
        if (folder / n).is_dir():
            raise ExportError(f"cannot write {folder / n}: a folder of that name exists")

    _clean_stale(folder)
    created = _make_dirs(folder)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=_prefix(folder, "new"), dir=folder.parent))
    except OSError as exc:
        _remove_dirs(created)
        raise ExportError(_os_message(exc, f"temporary folder beside {folder}")) from exc

    new_dir, old_dir = tmp / "new", tmp / "old"
    moved: list[tuple[Path, Path | None]] = []  # (target, backup of its old version or None)
    try:
        new_dir.mkdir()
        old_dir.mkdir()
        _write_staged(new_dir, files, names)
        for n in names:
            target = folder / n
            backup = old_dir / n
            had_old = _keep_old(target, backup)
            os.replace(new_dir / n, target)
            moved.append((target, backup if had_old else None))
        _fsync_dir(folder)
    except BaseException as exc:
        restore_errors = _roll_back(moved)
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_dirs(created)
        if restore_errors:
            raise ExportError(
                f"writing into {folder} failed and {len(restore_errors)} file(s) could not be "
                f"restored: {', '.join(str(p) for p in restore_errors)}"
            ) from exc
        _raise_as_export_error(exc, folder)
    shutil.rmtree(tmp, ignore_errors=True)
    return [folder / n for n in names]


def _raise_as_export_error(exc: BaseException, folder: Path) -> None:
    """Raise ``exc`` as the one-line :class:`ExportError` of a failed write into ``folder``
    (an ExportError, and an interrupt, as they are)."""
    if isinstance(exc, ExportError) or not isinstance(exc, Exception):
        raise exc
    if isinstance(exc, OSError):
        raise ExportError(_os_message(exc, f"into {folder}")) from exc
    raise ExportError(f"writing into {folder} failed: {exc!r}") from exc


def _roll_back(moved: list[tuple[Path, Path | None]]) -> list[Path]:
    """Undo the moves of :func:`write_outputs`; return the targets that could not be restored."""
    failed = []
    for target, backup in reversed(moved):
        try:
            if backup is None:
                target.unlink()
            else:
                os.replace(backup, target)
        except OSError:
            failed.append(target)
    return failed


def write_file_atomic(path, data: str | bytes) -> Path:
    """Replace one file atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination file; missing parent folders are created.
    data : str or bytes
        Contents; ``str`` is written as UTF-8 without newline translation.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ExportError
        When ``data`` is not str or bytes, ``path`` is a folder, a parent is a file, or the OS
        refuses the write. The old file (if any) is then intact and no temporary file remains.
    """
    path = Path(path)
    payload = _encode(path.name, data)
    if path.is_dir():
        raise ExportError(f"cannot write {path}: it is a folder")
    created = _make_dirs(path.parent)
    tmp = None
    done = False
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        tmp = Path(tmp_name)
        with os.fdopen(fd, "wb") as fh:
            _write_all(fh, payload)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
        done = True
        _fsync_dir(path.parent)
    except OSError as exc:
        raise ExportError(_os_message(exc, str(path))) from exc
    finally:
        if not done:
            if tmp is not None:
                try:
                    tmp.unlink()
                except OSError:
                    pass
            _remove_dirs(created)
    return path
