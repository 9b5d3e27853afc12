"""A design's folder written whole: the old design or the new one, never a mix.

:func:`write_design_folder` writes every file of a design into a staging folder beside the
target (same parent, so the same filesystem), then puts it in the target's place in one step:
an atomic exchange of the two folders where the system has one (Linux ``renameat2``), else two
renames, whose one unsafe moment -- a process killed between them -- the next run repairs.
So a reader of the folder, or a run killed at any point, sees the old design or the new one.

A folder is a design folder when every file in it has a name this tool writes
(:data:`DESIGN_FILES`). Any other file (the user's) makes the folder refused unless ``force``:
then the new files are written beside the others, each atomically
(:func:`~filletfold.export.atomic.write_outputs`), and the old design's files that the new
design does not write are removed, so no file of an earlier design is left to be read with the
new one. A staging folder left by a killed run (its process gone) is removed by the next run
that writes beside it.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import secrets
import shutil
import stat
import tempfile
from collections.abc import Mapping
from pathlib import Path

from ..errors import ExportError
from .atomic import (
    STAGING_MARK,
    _check_name,
    _clean_stale,
    _fsync_dir,
    _make_dirs,
    _os_message,
    _prefix,
    _raise_as_export_error,
    _remove_dirs,
    _write_staged,
    write_outputs,
)
from .cutfiles import FORMAT_FILES

__all__ = ["DESIGN_FILES", "STAGING_MARK", "check_design_folder", "write_design_folder"]

#: Every file name a design folder may hold: what ``filletfold round`` and ``filletfold
#: export`` write.
DESIGN_FILES = frozenset(
    {name for names in FORMAT_FILES.values() for name in names}
    | {"timings.json", "assembly.txt", "assembly.pdf"}
)


def write_design_folder(
    folder, files: Mapping[str, object], *, force: bool = False, inputs=()
) -> list[Path]:
    """Write ``files`` as the whole contents of the design folder ``folder``.

    Files without a ``design.fold`` among them are added to the folder instead (each
    replaced all or nothing, the others kept): more files of the design already there.

    Parameters
    ----------
    folder : str or os.PathLike
        Created with its parents when missing. A folder that holds any file whose name is
        not in :data:`DESIGN_FILES` is refused unless ``force``.
    files : mapping of str to contents
        As :func:`~filletfold.export.atomic.write_outputs` takes them.
    force : bool
        Write beside files this tool did not write (they are kept; the old design's files
        are replaced or removed).
    inputs : iterable of path
        Files the design was made from (the mesh): a folder whose new files would replace one
        is refused, even with ``force``.

    Returns
    -------
    list of Path
        The written files, in the order of ``files``.

    Raises
    ------
    ExportError
        Naming the folder and why (a file in the way, files that are not the design's, an
        input that would be overwritten, an OS error); the folder is then as it was.
    """
    folder = Path(folder)
    names = [_check_name(n) for n in files]
    _clean_stale(folder)
    present = check_design_folder(folder, force=force, inputs=inputs)
    if "design.fold" not in names:  # files added to a design (its pictures): the rest kept
        return write_outputs(folder, {n: files[n] for n in names})
    if present is not None and (
        any(n not in DESIGN_FILES for n in present) or _in_place_only(folder)
    ):
        return _beside(folder, files, names, present)
    return _swap(folder, files, names)


def check_design_folder(folder, *, force: bool = False, inputs=()) -> list | None:
    """Why a design cannot be written into ``folder`` (see :func:`write_design_folder`), as
    an :class:`ExportError`; asked before a design is made, so that a long run does not end
    refused. Returns the names of the files in it (None: no folder yet)."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ExportError(f"cannot write into {folder}: it is a file, not a folder")
    for given in inputs:
        given = Path(given)
        if given.is_file() and given.name in DESIGN_FILES and folder.is_dir():
            mine = folder / given.name
            if mine.exists() and mine.samefile(given):
                raise ExportError(
                    f"cannot write into {folder}: its {given.name} is the input mesh, which the "
                    "design's files would replace; choose another output folder (-o)"
                )
    if not folder.is_dir():
        return None
    try:
        present = sorted(p.name for p in folder.iterdir())
    except OSError as exc:
        raise ExportError(_os_message(exc, f"into {folder}")) from exc
    foreign = [n for n in present if n not in DESIGN_FILES]
    if foreign and not force:
        more = f" and {len(foreign) - 3} more" if len(foreign) > 3 else ""
        raise ExportError(
            f"{folder} holds files filletfold did not write ({', '.join(foreign[:3])}{more}); "
            "write into a new or empty folder, or give --force to write beside them (the "
            "old design's files are replaced)"
        )
    return present


def _beside(folder: Path, files, names: list, present: list) -> list[Path]:
    """The files written one by one into ``folder`` (each all or nothing), then the old
    design's files the new design does not write removed."""
    written = write_outputs(folder, {n: files[n] for n in names})
    for stale in sorted(set(present) & DESIGN_FILES - set(names)):
        try:
            (folder / stale).unlink()
        except FileNotFoundError:
            pass
        except OSError as exc:
            raise ExportError(_os_message(exc, f"(remove) {folder / stale}")) from exc
    return written


def _in_place_only(folder: Path) -> bool:
    """Whether ``folder`` cannot be replaced whole: a link, a mount point, or the working
    folder (or one holding it)."""
    if folder.is_symlink() or os.path.ismount(folder):
        return True
    try:
        here, there = Path.cwd().resolve(), folder.resolve()
    except OSError:
        return True
    return there == here or there in here.parents


def _swap(folder: Path, files, names: list) -> list[Path]:
    """Stage the files beside ``folder`` and put the staged folder in its place."""
    parent = folder.parent
    created = _make_dirs(parent)
    try:
        stage = _new_folder(parent, _prefix(folder, "new"))
        if folder.is_dir():  # the design folder keeps its permissions
            os.chmod(stage, stat.S_IMODE(folder.stat().st_mode))
    except OSError as exc:
        _remove_dirs(created)
        raise ExportError(_os_message(exc, f"a staging folder beside {folder}")) from exc
    try:
        _write_staged(stage, files, names)
        _fsync_dir(stage)
        if not folder.exists():
            os.rename(stage, folder)
        elif _exchange(stage, folder):
            shutil.rmtree(stage, ignore_errors=True)  # the old design, now staged
        else:
            old = Path(tempfile.mkdtemp(prefix=_prefix(folder, "old"), dir=parent))
            os.rename(folder, old / "design")  # killed here: the next run puts it back
            os.rename(stage, folder)
            shutil.rmtree(old, ignore_errors=True)
        _fsync_dir(parent)
    except BaseException as exc:
        shutil.rmtree(stage, ignore_errors=True)
        _remove_dirs(created)
        _raise_as_export_error(exc, folder)
    return [folder / n for n in names]


def _new_folder(parent: Path, prefix: str) -> Path:
    """A new folder ``parent/prefix...`` made as ``mkdir`` makes one (the umask's permissions,
    not ``mkdtemp``'s owner-only ones: it becomes the output folder)."""
    for _ in range(100):
        path = parent / f"{prefix}{secrets.token_hex(4)}"
        try:
            path.mkdir()
        except FileExistsError:
            continue
        return path
    raise FileExistsError(f"no free name for a staging folder in {parent}")


_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Swap the folders ``a`` and ``b`` atomically (Linux ``renameat2(RENAME_EXCHANGE)``);
    False where the system cannot (then nothing changed)."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    fn.restype = ctypes.c_int
    done = fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    return done == 0
