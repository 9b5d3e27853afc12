"""filletfold for the Blender extension, without ``bpy``: the design of a mesh and its files.

The extension runs filletfold in Blender's own Python when it imports there (installed into it:
``<blender's python> -m pip install <the filletfold clone>``), else in a subprocess of the
Python named in the panel (one that has filletfold: a clone's ``.venv/bin/python``), where
filletfold's compiled wheels (numba, scipy) cannot clash with Blender's. Either way the work is
the library's: :func:`folded` is ``round_mesh`` laid out as vertex modules without tabs (what the
browser app shows), :func:`export` writes what ``filletfold round MESH -o FOLDER`` writes.
"""

from __future__ import annotations

import json
import os
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

#: The patch kinds, in the order of filletfold's files and pictures.
KIND_ORDER = ("cone", "cylinder", "fillet", "face")
#: Each kind's colour (RGB, 0..1), as filletfold's pictures draw it.
PATCH_COLOR = {
    "cone": (0.96, 0.62, 0.25),
    "cylinder": (0.35, 0.6, 0.9),
    "fillet": (0.24, 0.78, 0.78),
    "face": (0.45, 0.78, 0.45),
}
#: The longest a subprocess may take (a design of a few thousand vertices takes seconds).
SUBPROCESS_SECONDS = 600


class EngineError(Exception):
    """A design or export failed: its message is filletfold's one-line error."""


@dataclass(frozen=True)
class Options:
    """The panel's parameters, as the command line spells them."""

    radius: str = "10%"
    depth: str = "30%"
    samples: int = 24
    sharp: str = "auto"

    def arguments(self) -> list[str]:
        return ["-r", self.radius, "-d", self.depth, "-n", str(self.samples), "--sharp", self.sharp]


def in_process() -> bool:
    """Whether filletfold imports in this Python."""
    try:
        import filletfold  # noqa: F401
    except ImportError:
        return False
    return True


def write_obj(path: Path, vertices, faces) -> None:
    """An OBJ of the mesh, every coordinate with all its digits."""
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in vertices]
    lines += ["f " + " ".join(str(i + 1) for i in face) for face in faces]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


_last: dict = {}  # the latest in-process design per mesh name, for reuse


def folded(vertices, faces, options: Options, python: str = "", name: str = "mesh") -> dict:
    """The folded form of a mesh: ``vertices`` (n, 3) and ``faces`` (lists of vertex indices),
    ``patches`` (each face's patch name, ``"cone 3"``), ``status`` (each mesh vertex's) and
    ``summary``.

    In this Python when filletfold imports here and ``python`` is empty (reusing the latest
    design of ``name``: a slider change re-solves what changed); else by ``python -m
    filletfold round`` in a subprocess, read back from its ``design.fold``.

    Raises
    ------
    EngineError
        filletfold's one-line error, or how to get filletfold.
    """
    if not python and in_process():
        from filletfold.design import round_mesh
        from filletfold.errors import FilletfoldError

        try:
            design = round_mesh(
                _polymesh(vertices, faces), layout="modules", tabs=False, certify=False,
                reuse=_last.get(name), **_fields(options),
            )  # fmt: skip
        except FilletfoldError as exc:
            raise EngineError(str(exc)) from None
        _last[name] = design
        p = design.pattern
        return {
            "vertices": p.vertices_3d.tolist(),
            "faces": [[int(i) for i in f] for f in p.faces],
            "patches": [str(n) for n in p.face_patch],
            "status": list(design.vertices.status),
            "summary": design.summary(),
        }
    with tempfile.TemporaryDirectory(prefix="filletfold-") as tmp:
        out = Path(tmp) / "design"
        extra = ["--format", "fold,json", "--layout", "modules", "--no-tabs", "--report-tables"]
        printed = _run(python, vertices, faces, options, out, extra, name)
        fold = json.loads((out / "design.fold").read_text(encoding="utf-8"))
        report = json.loads((out / "report.json").read_text(encoding="utf-8"))
    statuses = [v.get("status", "") for v in report.get("vertices", [])]
    return {
        "vertices": fold["file_frames"][0]["vertices_coords"],
        "faces": fold["faces_vertices"],
        "patches": fold["filletfold:faces_patch"],
        "status": statuses,
        "summary": "\n".join(x for x in printed.splitlines() if not x.startswith("wrote ")),
    }


def export(vertices, faces, options: Options, folder, python: str = "", name: str = "mesh"):
    """Write the design's files into ``folder`` as ``filletfold round MESH -o FOLDER`` does
    (``design.fold``, ``report.json``, ``timings.json``, ``folded.obj``, ``pattern.svg``; the
    folder new, empty or holding a design). Returns the paths written.

    Raises
    ------
    EngineError
        filletfold's one-line error, or how to get filletfold.
    """
    folder = Path(folder)
    if not python and in_process():
        from filletfold.design import round_mesh
        from filletfold.errors import FilletfoldError
        from filletfold.export.outputs import export_design

        try:
            design = round_mesh(_polymesh(vertices, faces), keep_stages=False, **_fields(options))
            design.source = f"{name}.obj"
            return [Path(p) for p in export_design(design, folder)]
        except FilletfoldError as exc:
            raise EngineError(str(exc)) from None
    _run(python, vertices, faces, options, folder, ["-q"], name)
    return sorted(p for p in folder.iterdir() if p.is_file())


def _fields(options: Options) -> dict:
    return {
        "radius": options.radius,
        "depth": options.depth,
        "samples": int(options.samples),
        "sharp": options.sharp,
    }


def _polymesh(vertices, faces):
    import numpy as np

    from filletfold.mesh.polymesh import PolyMesh

    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    return PolyMesh(v, [np.asarray(f, dtype=np.int64) for f in faces])


def _run(python, vertices, faces, options: Options, out: Path, extra: list, name: str) -> str:
    """``python -m filletfold round MESH -o OUT`` with the options, the mesh written as
    ``MESH`` (an OBJ named after the object) in a temporary folder; what it printed."""
    if not python:
        raise EngineError(
            "filletfold is not installed in Blender's Python: install it there, or give the "
            "panel's Python a Python that has it (a filletfold clone's .venv/bin/python)"
        )
    if not os.path.isfile(python):
        raise EngineError(f"Python {python}: no such file")
    with tempfile.TemporaryDirectory(prefix="filletfold-mesh-") as tmp:
        mesh = Path(tmp) / f"{_safe(name)}.obj"
        write_obj(mesh, vertices, faces)
        args = [python, "-m", "filletfold", "round", str(mesh), "-o", str(out)]
        try:
            done = subprocess.run(
                [*args, *options.arguments(), *extra],
                capture_output=True, text=True, timeout=SUBPROCESS_SECONDS,
            )  # fmt: skip
        except (OSError, subprocess.TimeoutExpired) as exc:
            raise EngineError(f"{python} -m filletfold: {exc}") from None
    if done.returncode not in (0, 1):  # 1: written, but the certificate fails (as the CLI)
        lines = [line for line in done.stderr.splitlines() if line.strip()]
        raise EngineError(lines[-1].removeprefix("error: ") if lines else "filletfold failed")
    return done.stdout


def _safe(name: str) -> str:
    keep = "".join(c if c.isalnum() or c in "-_." else "_" for c in name).strip("._")
    return keep or "mesh"
