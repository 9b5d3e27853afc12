"""The browser app's state, without any GUI: mesh, parameters, the current design.

:class:`AppSession` is what the viser front end (:mod:`filletfold.app.server`) drives. It keeps
the current mesh and parameters, recomputes the design on request, and numbers every request so
that a newer change supersedes an older one: a result computed for an old request never replaces
a result of a newer one. A failed load or recompute raises the library's error and leaves the
current design in place.
"""

from __future__ import annotations

import io
import logging
import math
import os
import tempfile
import threading
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..defaults import DEFAULT_ARC_STEP, DEFAULT_DEPTH, DEFAULT_RADIUS, DEFAULT_SAMPLES
from ..design import Design, round_mesh
from ..errors import MeshReadError, ParameterError
from ..export.cutfiles import cut_files
from ..export.outputs import mesh_fold_keys, summary_records
from ..export.report import report_json
from ..layout.tabs import assembly_text
from ..mesh import SUPPORTED_EXTENSIONS, load_mesh
from ..mesh.coarsen import Coarsening, coarsen_and_clean
from ..mesh.polymesh import PolyMesh
from ..parameters import Parameters, unsettled

log = logging.getLogger(__name__)

#: Largest mesh file the app accepts, in bytes (50 MB).
UPLOAD_LIMIT_BYTES = 50 * 1024 * 1024
#: Date and time of every entry of the zip (the earliest a zip can hold).
ZIP_DATE = (1980, 1, 1, 0, 0, 0)
#: Files in the zip from :meth:`AppSession.export_zip`, besides ``report.json``.
ZIP_FORMATS = ("fold", "simulator", "obj", "svg", "dxf")
#: Parameters :meth:`AppSession.set_params` accepts.
PARAM_NAMES = ("radius", "depth", "samples", "arc_step", "material_loss", "clamp", "tabs")


@dataclass(frozen=True)
class Request:
    """One recompute: its id and a snapshot of everything the design depends on.

    Attributes
    ----------
    id : int
        Increases with every request of a session.
    mesh : PolyMesh
    name : str
        What the mesh came from (example name or file name).
    params : Parameters
        The parameters of :func:`~filletfold.design.round_mesh` (``depth`` already merged
        with the per-vertex overrides).
    reuse : Design or None
        The current design when the request was made: what it shares with the request (same
        mesh and rounding) is taken over, so a per-vertex depth re-solves only that vertex.
    """

    id: int
    mesh: PolyMesh
    name: str
    params: Parameters = field(default_factory=Parameters)
    reuse: Design | None = None


def _plain(x):
    """JSON-friendly value: floats (None for NaN), lists for arrays."""
    if x is None:
        return None
    arr = np.asarray(x, dtype=float)
    if arr.ndim == 0:
        v = float(arr)
        return v if math.isfinite(v) else None
    return [None if not math.isfinite(v) else float(v) for v in arr.ravel()]


def read_upload(filename: str, content: bytes) -> PolyMesh:
    """Read an uploaded mesh file through the library's reader.

    Parameters
    ----------
    filename : str
        The uploaded file's name; its extension chooses the reader.
    content : bytes
        The file's bytes, at most :data:`UPLOAD_LIMIT_BYTES`.

    Returns
    -------
    PolyMesh
        The cleaned mesh.

    Raises
    ------
    MeshReadError
        Over the size cap, an unsupported extension, or the reader's own error.
    MeshError
        The mesh is invalid.
    """
    name = Path(filename or "upload").name or "upload"
    if len(content) > UPLOAD_LIMIT_BYTES:
        raise MeshReadError(
            f"{name}: the file is {len(content) / 1e6:.1f} MB; the app accepts files up to "
            f"{UPLOAD_LIMIT_BYTES // (1024 * 1024)} MB"
        )
    if Path(name).suffix.lower() not in SUPPORTED_EXTENSIONS:
        raise MeshReadError(
            f"{name}: unsupported file type; supported: {', '.join(SUPPORTED_EXTENSIONS)}"
        )
    with tempfile.TemporaryDirectory(prefix="filletfold-upload-") as tmp:
        path = Path(tmp) / name
        path.write_bytes(content)
        try:
            mesh, _ = load_mesh(path)
        except MeshReadError as exc:
            # name the file as the user knows it, not by its temporary path
            raise MeshReadError(str(exc).replace(str(path), name)) from None
    return mesh


class AppSession:
    """The stateful part of the browser app: mesh, parameters, current design.

    Parameters
    ----------
    radius, depth : float or str
        As for :func:`~filletfold.design.round_mesh` (``"10%"`` of the mean edge length...).
    samples : int
    arc_step : float
        Largest turn between two samples of an arc (degrees; see
        :func:`~filletfold.design.round_mesh`).
    material_loss : bool

    Attributes
    ----------
    mesh : PolyMesh or None
    name : str
        What the mesh came from.
    params : Parameters
        The parameters shown (the sliders change ``radius``, ``depth``, ``samples``,
        ``arc_step``, ``material_loss``, ``clamp``, ``tabs``: :data:`PARAM_NAMES`).
    vertex_depth : dict of int to float or str
        Per-vertex depth overrides.
    design : Design or None
        The newest design computed.
    design_id : int
        Request id of ``design`` (0 before the first).
    loaded : PolyMesh or None
        The mesh as loaded: :meth:`coarsen` always starts from it.
    coarsening : Coarsening or None
        What :meth:`coarsen` did to ``loaded`` to give ``mesh`` (None: ``mesh`` is ``loaded``).
    """

    def __init__(
        self,
        *,
        radius=DEFAULT_RADIUS,
        depth=DEFAULT_DEPTH,
        samples: int = DEFAULT_SAMPLES,
        arc_step: float = DEFAULT_ARC_STEP,
        material_loss: bool = False,
    ):
        self.mesh: PolyMesh | None = None
        self.loaded: PolyMesh | None = None
        self.coarsening: Coarsening | None = None
        self.name = ""
        self.params = Parameters(
            radius=radius,
            depth=depth,
            samples=samples,
            arc_step=arc_step,
            material_loss=material_loss,
            clamp=True,
            tabs=False,  # the download always has them (see export_files)
            # a slider change redraws the modules (torus: 66 ms; joined into nets on every
            # change, 820 ms); the download is laid out in nets, as the command line does
            layout="modules",
        )
        self.vertex_depth: dict = {}
        self.design: Design | None = None
        self.design_id = 0
        self._next_id = 0
        self._lock = threading.RLock()

    def fork(self) -> AppSession:
        """A session of its own that starts where this one is (same mesh, parameters, per-vertex
        depths and design; the design is shared, never changed in place): one per page of
        the app, so one page's changes never reach another's."""
        with self._lock:
            other = AppSession.__new__(AppSession)
            other.__dict__.update(self.__dict__)
            other.vertex_depth = dict(self.vertex_depth)
            other._lock = threading.RLock()
            return other

    # -- requests -------------------------------------------------------------------------
    def begin(self, *, mesh: PolyMesh | None = None, name: str | None = None) -> Request:
        """Number a new request and snapshot the state it is computed from.

        Parameters
        ----------
        mesh, name : optional
            A mesh to compute instead of the current one (a load in progress).
        """
        with self._lock:
            self._next_id += 1
            mesh = self.mesh if mesh is None else mesh
            if mesh is None:
                raise MeshReadError("no mesh loaded")
            params = self.params
            if self.vertex_depth:
                params = params.replace(depth={"default": params.depth, **self.vertex_depth})
            return Request(
                self._next_id, mesh, self.name if name is None else name, params, self.design
            )

    @staticmethod
    def compute(request: Request, progress=None) -> Design:
        """The design of a request (slow; no session state is touched).

        Parameters
        ----------
        request : Request
        progress : callable, optional
            ``progress(stage, done, total)``, passed on to
            :func:`~filletfold.design.round_mesh` (called during its long stages, in the
            computing thread). An exception it raises stops the computation and propagates.
        """
        design = round_mesh(
            request.mesh,
            request.params,
            progress=progress,
            reuse=request.reuse,
            certify=False,  # a slider drag needs the picture; the download certifies
        )
        design.source = request.name
        return design

    def commit(self, request: Request, design: Design) -> bool:
        """Make ``design`` current unless a newer request's design already is.

        Returns
        -------
        bool
            Whether the design was taken.
        """
        with self._lock:
            if request.id <= self.design_id:
                log.debug("request %d superseded by %d", request.id, self.design_id)
                return False
            self.design, self.design_id = design, request.id
            if request.mesh is not self.mesh:
                self.mesh, self.name = request.mesh, request.name
            return True

    @property
    def latest_id(self) -> int:
        """Id of the newest request begun."""
        return self._next_id

    # -- state changes --------------------------------------------------------------------
    def load(self, source, content: bytes | None = None, *, progress=None) -> Design:
        """Load a mesh and compute its design; on any error keep the current one.

        Parameters
        ----------
        source : str, os.PathLike or PolyMesh
            A built-in example name, a file path, or (with ``content``) the uploaded file name.
        content : bytes, optional
            The uploaded file's bytes.
        progress : callable, optional
            ``progress(stage, done, total)`` during the design's long stages (see
            :meth:`compute`).

        Returns
        -------
        Design
            The new current design.

        Raises
        ------
        MeshReadError
            Unreadable file, over :data:`UPLOAD_LIMIT_BYTES`, or unknown example.
        FilletfoldError
            Invalid mesh, or the design of the new mesh fails.
        """
        if content is not None:
            mesh, name = read_upload(str(source), content), Path(str(source)).name
        elif isinstance(source, PolyMesh):
            mesh, name = source, "mesh"
        else:
            path = Path(os.fspath(source))
            if path.is_file() and path.stat().st_size > UPLOAD_LIMIT_BYTES:
                raise MeshReadError(
                    f"{source}: the file is over the app's limit of "
                    f"{UPLOAD_LIMIT_BYTES // (1024 * 1024)} MB"
                )
            mesh, _ = load_mesh(str(source) if isinstance(source, str) else path)
            name = str(source) if not path.exists() else path.name
        return self._design_mesh(mesh, name, progress, loaded=mesh, coarsening=None)

    def coarsen(self, faces: int | None, *, progress=None) -> Design:
        """Design the loaded mesh coarsened to about ``faces`` triangles (quadric decimation,
        :func:`~filletfold.mesh.coarsen.coarsen_mesh`), or the loaded mesh itself with
        ``None``; the per-vertex depths are cleared (the vertices are new). On any error the
        current design stays.

        Returns
        -------
        Design
            The new current design; :attr:`coarsening` says what the coarsening did.

        Raises
        ------
        FilletfoldError
            No mesh loaded, a bad count, or the design fails.
        """
        with self._lock:
            loaded, name = self.loaded, self.name
        if loaded is None:
            raise MeshReadError("no mesh loaded")
        if faces is None:
            return self._design_mesh(loaded, name, progress, loaded=loaded, coarsening=None)
        mesh, _, info = coarsen_and_clean(loaded, faces)
        return self._design_mesh(mesh, name, progress, loaded=loaded, coarsening=info)

    def _design_mesh(self, mesh, name, progress, *, loaded, coarsening) -> Design:
        """Make ``mesh`` current with its design (the per-vertex depths cleared), unless a
        newer request's design is taken first; remember what it was loaded and coarsened as."""
        with self._lock:
            saved = self.vertex_depth
            self.vertex_depth = {}
            try:
                request = self.begin(mesh=mesh, name=name)
            finally:
                self.vertex_depth = saved
        design = self.compute(request, progress)
        with self._lock:
            if self.commit(request, design):
                self.vertex_depth = {}
                self.loaded, self.coarsening = loaded, coarsening
        return self.design

    def set_params(self, **kw) -> None:
        """Change parameters (``radius``, ``depth``, ``samples``, ``arc_step``, ``material_loss``,
        ``clamp``, ``tabs``: glue tabs in the shown pattern, off by default for speed).

        Raises
        ------
        ParameterError
            For an unknown parameter name.
        """
        for key in kw:
            if key not in PARAM_NAMES:
                raise ParameterError(
                    f"unknown parameter {key!r}: choose from {', '.join(PARAM_NAMES)}", name=key
                )
        with self._lock:
            self.params = self.params.replace(**kw)

    def set_vertex_depth(self, u: int, depth) -> None:
        """Give vertex ``u`` its own apex depth (``None`` removes the override).

        Raises
        ------
        ParameterError
            When ``u`` is not a vertex of the current mesh.
        """
        with self._lock:
            n = 0 if self.mesh is None else len(self.mesh.vertices)
            if isinstance(u, bool) or not isinstance(u, int | np.integer) or not 0 <= u < n:
                raise ParameterError(f"vertex {u!r} does not exist (0..{n - 1})", name="vertex")
            if depth is None:
                self.vertex_depth.pop(int(u), None)
            else:
                self.vertex_depth[int(u)] = depth

    def recompute(self, *, progress=None) -> Design:
        """Recompute the design of the current state.

        Parameters
        ----------
        progress : callable, optional
            ``progress(stage, done, total)`` during the design's long stages (see
            :meth:`compute`).

        Returns
        -------
        Design
            The current design afterwards (a newer request's, if one finished first).

        Raises
        ------
        FilletfoldError
            When the design fails; the current design stays.
        """
        request = self.begin()
        design = self.compute(request, progress)
        self.commit(request, design)
        return self.design

    # -- queries --------------------------------------------------------------------------
    def vertex_info(self, u: int) -> dict:
        """What the app shows about vertex ``u`` of the current design.

        Returns
        -------
        dict
            ``vertex``, ``kind``, ``status``, ``reason``, ``margin``, ``depth`` (used),
            ``depth_requested``, ``normal`` (3 floats), ``apex`` (3 floats or None), ``override``
            (the per-vertex depth given, or None). NaN becomes None.
        """
        with self._lock:
            design = self.design
            if design is None:
                raise ParameterError("no design computed yet", name="vertex")
            res = design.vertices
            n = len(res.status)
            if isinstance(u, bool) or not isinstance(u, int | np.integer) or not 0 <= u < n:
                raise ParameterError(f"vertex {u!r} does not exist (0..{n - 1})", name="vertex")
            apex = _plain(res.apex[u])
            return {
                "vertex": int(u),
                "kind": res.kind[u],
                "status": res.status[u],
                "reason": res.reason[u],
                "margin": _plain(res.margin[u]),
                "depth": _plain(res.depth[u]),
                "depth_requested": _plain(res.depth_requested[u]),
                "normal": _plain(res.normal[u]),
                "apex": None if apex is None or None in apex else apex,
                "override": self.vertex_depth.get(int(u)),
            }

    def export_files(self) -> dict[str, str | bytes]:
        """The current design's files, built in memory (nothing is written)."""
        with self._lock:
            design = self.design
        if design is None:
            raise ParameterError("no design computed yet", name="design")
        if design.stages is not None and (
            design.fabrication.get("tabs", 0) == 0 or design.params.layout == "modules"
        ):
            # the shown design was computed as modules without glue tabs: lay it out in nets
            # with tabs, as the command line does (the layout stage only)
            # a default size settles anew for the nets' pieces
            p = unsettled(design.params, design.fabrication.get("default_size"))
            source = design.source
            design = round_mesh(design.mesh, p, tabs=True, layout="auto", reuse=design)
            design.source = source
        files = dict(
            cut_files(
                design.pattern,
                ZIP_FORMATS,
                units=design.params.units,  # at the design's size, as the command line draws
                scale=design.params.scale,
                title=f"filletfold design of {design.source}",
                description="Curved-crease rounded design: vertex modules",
                fold_extra=mesh_fold_keys(design),
            )
        )
        files["report.json"] = report_json(summary_records(design))  # as the CLI writes it
        seams = design.fabrication.get("seams")
        if seams:
            files["assembly.txt"] = assembly_text(seams)
        return files

    def export_zip(self) -> bytes:
        """A zip of ``design.fold``, ``annotations.json``, ``simulator.fold``,
        ``simulator.svg`` (for Origami Simulator), ``report.json``, ``folded.obj``,
        ``pattern.svg`` and ``pattern.dxf`` (and ``assembly.txt`` with glue tabs), built in
        memory.

        Every entry is dated :data:`ZIP_DATE` (not the time of the export), so the same
        design gives the same bytes."""
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w") as zf:
            for name, data in self.export_files().items():
                info = zipfile.ZipInfo(name, date_time=ZIP_DATE)
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = 0o644 << 16  # rw-r--r--
                zf.writestr(info, data)
        return buf.getvalue()


def nearest_vertex_to_ray(points: np.ndarray, origin, direction) -> int:
    """Index of the point closest to a ray (a click in the 3D view).

    Parameters
    ----------
    points : (n, 3) float
    origin, direction : (3,) float

    Returns
    -------
    int
        -1 for no points.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    if not len(points):
        return -1
    o = np.asarray(origin, dtype=float)
    d = np.asarray(direction, dtype=float)
    d = d / max(np.linalg.norm(d), 1e-300)
    rel = points - o
    t = np.maximum(rel @ d, 0.0)
    dist = np.linalg.norm(rel - t[:, None] * d, axis=1)
    return int(np.argmin(dist))
