"""The browser app on viser: a thin front end over :class:`~filletfold.app.session.AppSession`.

The page shows the folded surface (patches coloured, creases mountain red / valley blue), the
crease pattern laid flat beside it, vertex status markers and a legend; the panel holds the
example list, an upload button, sliders for radius, depth and samples, the material-loss
switch, a vertex inspector with its own depth, and the download button.

Every page (browser tab) is an :class:`AppView` with its own session, panel, scene and worker:
one page's upload or slider never changes what another page shows. A new page starts from the
design computed when the app started; at most :data:`MAX_PAGES` pages are served at once and
:data:`MAX_COMPUTING` designs computed at once (the others wait, and say so).

A page's changes are handed to its worker thread; changes that arrive while it computes are
merged into the next computation, a computation that a newer change makes useless is stopped at
its next progress report, and a result older than the one shown is dropped. While the worker
computes, the panel shows the stage and a progress bar.
"""

from __future__ import annotations

import contextlib
import functools
import io
import logging
import threading
import time
import webbrowser

from ..defaults import DEFAULT_ARC_STEP, DEFAULT_SAMPLES
from ..errors import FilletfoldError, ParameterError
from ..mesh import example_names
from ..vertex.batch import warm_kernel
from .bind import check_bind, check_origins
from .session import UPLOAD_LIMIT_BYTES, AppSession, nearest_vertex_to_ray
from .upload import bound_uploads, on_refused
from .view import (
    CAMERA_LOOK_AT,
    CAMERA_POSITION,
    CREASE_RGB,
    PATCH_RGB,
    legend_markdown,
    scene_arrays,
)

log = logging.getLogger(__name__)

DEFAULT_RADIUS_PERCENT = 10.0
DEFAULT_DEPTH_PERCENT = 30.0
#: Shortest time between two progress updates sent to the page, in seconds.
PROGRESS_INTERVAL = 0.1
#: Most pages (browser tabs) served at once; each holds a design of its own.
MAX_PAGES = 8
#: Most designs computed at once over all pages (each may take a core and its memory).
MAX_COMPUTING = 1


class _Superseded(Exception):
    """Raised from the progress callback to stop a computation a newer change replaces."""


def _import_viser():
    try:
        import viser
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise FilletfoldError("the browser app needs viser: pip install 'filletfold[app]'") from exc
    return viser


class AppServer:
    """A running app: the viser server and one :class:`AppView` per connected page.

    Attributes
    ----------
    session : AppSession
        The design the app started with: every new page starts from a fork of it
        (:meth:`AppSession.fork`).
    host : str
    port : int
    url : str
        ``http://HOST:PORT``.
    remote : bool
        Whether other machines reach it (``--allow-remote``).
    views : dict of int to AppView
        The pages connected now, by viser client id.
    refused : int
        Pages turned away because :data:`MAX_PAGES` were open.
    """

    def __init__(self, server, session: AppSession, host: str):
        self.server = server
        self.session = session
        self.host = host
        self.port = int(server.get_port())
        self.url = f"http://{host}:{self.port}"
        self.remote = False
        self.views: dict[int, AppView] = {}
        self.refused = 0
        self._pages = threading.Condition()
        self._opening = 0  # pages being built (counted against MAX_PAGES)
        self._stopping = False
        self._stopped = threading.Event()
        self._computing = threading.BoundedSemaphore(MAX_COMPUTING)
        server.on_client_connect(self._connected)
        server.on_client_disconnect(self._disconnected)

    # -- pages ----------------------------------------------------------------------------
    def _connected(self, client) -> None:
        """A page connected: give it a view of its own, or say why not."""
        with self._pages:
            full = len(self.views) + self._opening >= MAX_PAGES
            if self._stopping:
                return
            if full:
                self.refused += 1
            else:
                self._opening += 1
        if full:
            client.gui.add_markdown(
                f"**error:** the app serves at most {MAX_PAGES} pages at once: close another "
                "page of it, then reload this one"
            )
            log.info("app: page %s refused, %d pages open", client.client_id, MAX_PAGES)
            return
        view = None
        try:
            view = AppView(client, self.session.fork(), self._computing)
            view.draw()
        finally:
            with self._pages:
                self._opening -= 1
                if view is not None:
                    self.views[client.client_id] = view
                self._pages.notify_all()
        log.info("app: page %s opened", client.client_id)

    def _disconnected(self, client) -> None:
        """A page closed: stop its worker and let its design go."""
        with self._pages:
            view = self.views.pop(client.client_id, None)
            self._pages.notify_all()
        if view is not None:
            view.stop(wait=False)
            log.info("app: page %s closed", client.client_id)

    def wait_view(self, client_id: int | None = None, timeout: float = 30.0) -> AppView:
        """The view of page ``client_id`` (None: the first page connected), once it is built.

        Raises
        ------
        TimeoutError
            No such page within ``timeout`` seconds.
        """

        def find():
            if client_id is not None:
                return self.views.get(client_id)
            return self.views[min(self.views)] if self.views else None

        with self._pages:
            if not self._pages.wait_for(lambda: find() is not None, timeout):
                which = "no page" if client_id is None else f"no page {client_id}"
                raise TimeoutError(f"{which} in {timeout:g} s")
            return find()

    # -- lifecycle ------------------------------------------------------------------------
    def stop(self) -> None:
        """Stop every page's worker and the viser server (idempotent)."""
        with self._pages:
            if self._stopping:
                return
            self._stopping = True
            views = list(self.views.values())
        for view in views:
            view.stop(wait=False)
        for view in views:
            view.join(timeout=30)
        with _quiet_stdout():
            self.server.stop()
        self._stopped.set()
        log.info("filletfold app stopped")

    def wait(self) -> None:
        """Block until :meth:`stop` (Ctrl-C stops the app)."""
        try:
            while not self._stopped.wait(0.5):
                pass
        except KeyboardInterrupt:
            self.stop()


class AppView:
    """One page of the app: its panel, its scene, its session and its worker thread.

    Parameters
    ----------
    client : viser.ClientHandle
        The page; the panel and scene are made on its ``gui`` and ``scene`` (seen by it only).
    session : AppSession
        This page's own state.
    computing : threading.Semaphore
        Held while a design is computed (shared by the pages: :data:`MAX_COMPUTING`).

    Attributes
    ----------
    session : AppSession
    status : str
        The status line shown in the page (Markdown).
    progress : tuple or None
        ``(stage, done, total)`` of the computation in progress, None when idle.
    drawn_id : int
        Design id (:attr:`AppSession.design_id`) of the scene last drawn.
    timings : dict
        Seconds of the last computation (``compute``) and drawing (``draw``).
    """

    def __init__(self, client, session: AppSession, computing):
        self.client = client
        self.session = session
        self.status = "starting"
        self._computing = computing
        self._wake = threading.Condition()
        self._dirty = False
        self._upload = None
        self._stopping = False
        self._busy = False
        self._selected = 0
        self._phase = ""
        self._last_progress = 0.0
        self.progress = None
        self.drawn_id = 0
        self._drawn = threading.Condition()
        self.timings: dict[str, float] = {}
        self._nodes: dict = {}  # scene nodes by name, made by the first draw
        self._clickable: set = set()  # folded nodes that select a vertex on a click
        self._vertex_points = None  # the drawn vertex markers, for clicks
        self._build_gui()
        self._worker = threading.Thread(
            target=self._work, name=f"filletfold-page-{client.client_id}", daemon=True
        )
        self._worker.start()

    # -- lifecycle ------------------------------------------------------------------------
    def stop(self, wait: bool = True) -> None:
        """Stop the worker (a computation in progress stops at its next progress report)."""
        with self._wake:
            self._stopping = True
            self._wake.notify_all()
        if wait:
            self.join()

    def join(self, timeout: float = 30.0) -> None:
        """Wait for the worker to end (after :meth:`stop`)."""
        self._worker.join(timeout=timeout)

    def draw(self) -> None:
        """Draw the session's current design in the page."""
        self._draw()

    # -- worker ---------------------------------------------------------------------------
    def request_update(self) -> None:
        """Ask the worker to recompute with the current parameters."""
        with self._wake:
            self._dirty = True
            self._wake.notify_all()
        self._set_status("computing…")

    def request_load(self, source: str, content: bytes | None = None) -> None:
        """Ask the worker to load an example or an uploaded file (replacing any load not yet
        started)."""
        with self._wake:
            self._upload = functools.partial(self.session.load, source, content)
            self._wake.notify_all()
        self._set_status(f"loading {source}…")

    def request_coarsen(self, faces: int | None) -> None:
        """Ask the worker to design the loaded mesh coarsened to about ``faces`` triangles
        (None: as loaded), replacing any load not yet started."""
        with self._wake:
            self._upload = functools.partial(self.session.coarsen, faces)
            self._wake.notify_all()
        self._set_status(f"coarsening to {faces} triangles…" if faces else "the loaded mesh again…")

    def wait_drawn(self, design_id: int, timeout: float = 30.0) -> bool:
        """Wait until the scene shows design ``design_id`` or a newer one.

        Returns
        -------
        bool
            False on timeout.
        """
        with self._drawn:
            return self._drawn.wait_for(lambda: self.drawn_id >= design_id, timeout)

    def wait_idle(self, timeout: float = 30.0) -> bool:
        """Wait until the worker has nothing to do (every change computed and drawn, or failed).

        Returns
        -------
        bool
            False on timeout.
        """
        with self._wake:
            return self._wake.wait_for(
                lambda: not (self._busy or self._dirty or self._upload), timeout
            )

    def _work(self) -> None:
        while True:
            with self._wake:
                self._busy = False
                self._wake.notify_all()
                while not (self._dirty or self._upload or self._stopping):
                    self._wake.wait()
                if self._stopping:
                    return
            if not self._take_turn():
                return
            with self._wake:
                upload, self._upload = self._upload, None
                dirty, self._dirty = self._dirty, False
                self._busy = True
            t = time.perf_counter()
            try:
                if upload is not None:
                    self._phase = "load"
                    upload(progress=self._report_progress)  # a load, or a coarsening
                    self._after_load()
                if dirty:
                    self._phase = "recompute"
                    self.session.recompute(progress=self._report_progress)
                self._phase = ""
                self.timings["compute"] = time.perf_counter() - t
                self._draw()
            except _Superseded:
                # the newer change is waiting: the next turn computes and draws it
                log.debug("app: computation superseded by a newer change")
            except FilletfoldError as exc:
                self._set_status(f"**error:** {exc}")
                log.info("app: %s", exc)
            except Exception as exc:  # keep the app alive; show what happened
                log.exception("app: unexpected error")
                self._set_status(f"**unexpected error:** {type(exc).__name__}: {exc}")
            finally:
                self._computing.release()
                self._phase = ""
                self._end_progress()

    def _take_turn(self) -> bool:
        """Wait until no more than :data:`MAX_COMPUTING` designs are computed (saying so in
        the page meanwhile); False when the page stops while it waits."""
        if self._computing.acquire(blocking=False):
            return True
        self._set_status("waiting: another page of this app is computing…")
        while not self._computing.acquire(timeout=0.2):
            with self._wake:
                if self._stopping:
                    return False
        return True

    def _report_progress(self, stage: str, done: int, total: int) -> None:
        """``round_mesh``'s progress callback (worker thread): show the stage in the page, at
        most every :data:`PROGRESS_INTERVAL` seconds; stop when a newer change replaces this
        computation."""
        with self._wake:
            superseded = (
                self._stopping
                or self._upload is not None
                or (self._dirty and self._phase == "recompute")
            )
        if superseded:
            raise _Superseded
        first = self.progress is None or self.progress[0] != stage
        self.progress = (stage, done, total)
        now = time.monotonic()
        if not first and done < total and now - self._last_progress < PROGRESS_INTERVAL:
            return
        self._last_progress = now
        percent = 100.0 * done / total if total else 100.0
        self._progress_bar.value = min(max(percent, 0.0), 100.0)
        self._progress_bar.visible = True
        self._set_status(f"computing… {stage} {done}/{total}")

    def _end_progress(self) -> None:
        self.progress = None
        if self._stopping:  # a closed page is sent nothing
            return
        self._progress_bar.visible = False
        self._progress_bar.value = 0.0

    # -- GUI ------------------------------------------------------------------------------
    def _upload_refused(self, filename: str, size: int) -> None:
        """An upload dropped while it streamed (:mod:`~filletfold.app.upload`): say why; the
        current design stays."""
        self._set_status(
            f"**error:** {filename}: the file is {size / 1e6:.1f} MB or more; the app accepts "
            f"files up to {UPLOAD_LIMIT_BYTES // (1024 * 1024)} MB"
        )

    def _set_status(self, text: str) -> None:
        self.status = text
        handle = getattr(self, "_status_md", None)
        if handle is not None and not self._stopping:  # a closed page is sent nothing
            handle.content = text

    def _build_gui(self) -> None:
        gui = self.client.gui
        self._status_md = gui.add_markdown("starting…")
        self._progress_bar = gui.add_progress_bar(0.0, visible=False, animated=True)
        with gui.add_folder("Mesh"):
            names = list(example_names())
            name = self.session.name
            self._example = gui.add_dropdown(
                "Example", names, initial_value=name if name in names else names[0]
            )
            self._upload_button = gui.add_upload_button(
                "Upload mesh (OBJ/OFF/PLY/STL, ≤ 50 MB)", icon=None
            )
            self._faces = gui.add_number("Coarsen to triangles (0: as loaded)", 0, min=0, step=100)
            self._coarsen_button = gui.add_button("Coarsen")
        with gui.add_folder("Parameters"):
            self._radius = gui.add_slider("Radius (% edge)", 1.0, 50.0, 0.5, DEFAULT_RADIUS_PERCENT)
            self._depth = gui.add_slider("Depth (% edge)", 1.0, 150.0, 1.0, DEFAULT_DEPTH_PERCENT)
            self._samples = gui.add_slider("Samples", 3, 64, 1, DEFAULT_SAMPLES)
            self._arc_step = gui.add_slider(
                "Arc step (°, 0 = off)", 0.0, 10.0, 0.25, DEFAULT_ARC_STEP
            )
            self._loss = gui.add_checkbox("Material loss", False)
            self._tabs = gui.add_checkbox("Glue tabs (always in the download)", False)
            self._show_pattern = gui.add_checkbox("Show crease pattern", True)
        with gui.add_folder("Vertex"):
            self._vertex = gui.add_number("Vertex index", 0, min=0, step=1)
            self._vertex_depth = gui.add_number("Its depth (% edge, 0 = default)", 0.0, min=0.0)
            self._vertex_md = gui.add_markdown("")
        with gui.add_folder("Download"):
            self._download = gui.add_button("Download design (zip)")
        gui.add_markdown(legend_markdown())

        @self._example.on_update
        def _(event) -> None:
            if event.client is not None:
                self.request_load(self._example.value)

        @self._upload_button.on_upload
        def _(event) -> None:
            f = event.target.value
            self.request_load(f.name, f.content)

        on_refused(gui, self._upload_refused)

        @self._coarsen_button.on_click
        def _(_event) -> None:
            faces = int(self._faces.value)
            self.request_coarsen(faces if faces > 0 else None)

        for handle in (
            self._radius,
            self._depth,
            self._samples,
            self._arc_step,
            self._loss,
            self._tabs,
        ):
            handle.on_update(lambda _event: self._params_changed())

        @self._show_pattern.on_update
        def _(_event) -> None:
            for node in getattr(self, "_flat_nodes", []):
                node.visible = self._show_pattern.value

        @self._vertex.on_update
        def _(event) -> None:
            if event.client is not None:
                self._select(int(self._vertex.value))

        @self._vertex_depth.on_update
        def _(event) -> None:
            if event.client is None:  # set by the app itself, not by the user
                return
            value = float(self._vertex_depth.value)
            try:
                self.session.set_vertex_depth(self._selected, f"{value}%" if value > 0 else None)
            except FilletfoldError as exc:
                self._set_status(f"**error:** {exc}")
                return
            self.request_update()

        @self._download.on_click
        def _(event) -> None:
            try:
                data = self.session.export_zip()
            except FilletfoldError as exc:
                self._set_status(f"**error:** {exc}")
                return
            stem = (self.session.name or "design").rsplit(".", 1)[0].replace(":", "_")
            self.client.send_file_download(f"{stem}-filletfold.zip", data)

    def _params_changed(self) -> None:
        self.session.set_params(
            radius=f"{float(self._radius.value)}%",
            depth=f"{float(self._depth.value)}%",
            samples=int(self._samples.value),
            arc_step=float(self._arc_step.value),
            material_loss=bool(self._loss.value),
            tabs=bool(self._tabs.value),
        )
        self.request_update()

    def _after_load(self) -> None:
        self._selected = 0
        self._vertex.value = 0
        self._vertex_depth.value = 0.0
        if self.session.name in self._example.options:
            self._example.value = self.session.name

    def _select(self, u: int) -> None:
        self._selected = u
        try:
            info = self.session.vertex_info(u)
        except FilletfoldError as exc:
            self._vertex_md.content = f"**error:** {exc}"
            return

        def num(x):
            return "–" if x is None else f"{x:.4g}"

        lines = [
            f"**vertex {u}**: {info['status']} ({info['kind']})",
            f"reason: {info['reason'] or '–'}",
            f"depth used {num(info['depth'])}, requested {num(info['depth_requested'])}",
            f"margin {num(info['margin'])}",
            "normal " + ", ".join(num(x) for x in info["normal"] or []),
        ]
        self._vertex_md.content = "  \n".join(lines)
        override = info["override"]
        percent = float(override[:-1]) if isinstance(override, str) and override[-1:] == "%" else 0
        self._vertex_depth.value = percent

    def _node(self, name: str, add, *args, update: dict, **kwargs):
        """The scene node ``name``: ``add(name, *args, **kwargs)`` the first time, later only
        given the props ``update`` (viser sends the ones that changed). Updating a node instead
        of adding it again spares the page a new three.js object and material per node."""
        node = self._nodes.get(name)
        if node is None:
            node = self._nodes[name] = add(name, *args, **kwargs)
        else:
            for prop, value in update.items():
                setattr(node, prop, value)
        return node

    def _clicked(self, event) -> None:
        """A click on the folded surface selects the vertex nearest to the ray."""
        points = self._vertex_points
        if points is None:
            return
        u = nearest_vertex_to_ray(points, event.ray_origin, event.ray_direction)
        if u >= 0:
            self._vertex.value = u
            self._select(u)

    def _update_scene(self, arrays) -> None:
        """Give the scene nodes the arrays of a design (:func:`~.view.scene_arrays`)."""
        self._vertex_points = arrays.vertex_points
        scene = self.client.scene
        show_pattern = bool(self._show_pattern.value)
        flat_nodes = []
        for kind, rgb in PATCH_RGB.items():
            for root, parts in (("/folded", arrays.folded), ("/pattern", arrays.flat)):
                name = f"{root}/{kind}"
                folded = root == "/folded"
                if kind in parts:
                    vertices, faces = parts[kind]
                    update = {"vertices": vertices, "faces": faces}
                else:  # hidden: its old arrays need not be sent
                    (vertices, faces), update = _empty_mesh(), {}
                node = self._node(
                    name,
                    scene.add_mesh_simple,
                    vertices,
                    faces,
                    update=update,
                    color=rgb,
                    side="double",
                    flat_shading=False,
                )
                if folded and name not in self._clickable:
                    # point clouds take no clicks in viser; the surface does
                    node.on_click(self._clicked)
                    self._clickable.add(name)
                node.visible = kind in parts and (folded or show_pattern)
                if kind in parts and not folded:
                    flat_nodes.append(node)
        for root, segs in (
            ("/folded", arrays.folded_creases),
            ("/pattern", arrays.flat_creases),
        ):
            for a, points in segs.items():
                name = f"{root}/crease_{a}"
                shown = len(points) > 0
                node = self._node(
                    name,
                    scene.add_line_segments,
                    points if shown else _empty_segments(),
                    CREASE_RGB[a],
                    update={"points": points} if shown else {},
                    thickness=2.0 if a != "B" else 1.0,
                    thickness_units="screen",
                )
                node.visible = shown and (root == "/folded" or show_pattern)
                if shown and root == "/pattern":
                    flat_nodes.append(node)
        self._node(
            "/folded/vertices",
            scene.add_point_cloud,
            arrays.vertex_points,
            arrays.vertex_colors,
            update={
                "points": arrays.vertex_points,
                "colors": arrays.vertex_colors,
                "point_size": arrays.point_size,
            },
            point_size=arrays.point_size,
            point_shape="circle",
            point_shading="flat",
        )
        self._flat_nodes = flat_nodes

    def _draw(self) -> None:
        t = time.perf_counter()
        design, design_id = self.session.design, self.session.design_id
        if design is None:
            return
        arrays = scene_arrays(design)
        # one window of messages: the page applies the scene and the status line together
        with self.client.atomic():
            self._update_scene(arrays)
            counts = ", ".join(f"{n} {s}" for s, n in design.status_counts().items() if n)
            shown = (
                f", pattern drawn at {arrays.pattern_scale:.0%}" if arrays.pattern_scale < 1 else ""
            )
            coarse = self.session.coarsening
            self._set_status(
                f"**{design.source}**: {len(design.mesh.vertices)} vertices ({counts}), "
                f"{len(design.pattern.faces)} pattern faces{shown}  \n{params_text(design.params)}"
                + (f"  \n{coarse.summary()}" if coarse is not None else "")
            )
            n = len(design.mesh.vertices)
            self._vertex.max = max(n - 1, 0)
            if self._selected < n:
                self._select(self._selected)
        self.timings["draw"] = time.perf_counter() - t
        with self._drawn:
            self.drawn_id = max(self.drawn_id, design_id)
            self._drawn.notify_all()


def params_text(params) -> str:
    """The parameters a design was computed with, as the status line shows them.

    Parameters
    ----------
    params : filletfold.parameters.Parameters

    Returns
    -------
    str
        E.g. ``radius 10.0%, depth 30.0% (own depth at 2 vertices), samples 24, arc step 1.5°``.
    """

    def length(x) -> str:
        if isinstance(x, str):
            return x
        try:
            return f"{float(x):.4g}"
        except (TypeError, ValueError):
            return "per element"

    depth = params.depth
    own = ""
    if isinstance(depth, dict):
        n = sum(1 for k in depth if k != "default")
        where = f"{n} vertex" if n == 1 else f"{n} vertices"
        depth, own = depth.get("default"), f" (own depth at {where})" if n else ""
    radius = ("max " if params.material_loss else "") + length(params.radius)
    text = f"radius {radius}, depth {length(depth)}{own}, samples {params.samples}"
    text += f", arc step {params.arc_step:g}°" if params.arc_step > 0 else ", no arc step"
    return text + (", material loss" if params.material_loss else "")


@contextlib.contextmanager
def _quiet_stdout():
    """Send what viser prints to the log (debug level) instead of stdout."""
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        yield
    if buf.getvalue().strip():
        log.debug("viser: %s", buf.getvalue().strip())


def _empty_mesh():
    import numpy as np

    return np.zeros((3, 3)), np.array([[0, 1, 2]])


def _empty_segments():
    import numpy as np

    return np.zeros((1, 2, 3))


def run_app(
    mesh="icosahedron",
    host: str = "127.0.0.1",
    port: int = 0,
    open_browser: bool = False,
    allow_remote: bool = False,
) -> AppServer:
    """Start the browser app on ``mesh`` and return at once (the server runs in threads).

    Parameters
    ----------
    mesh : str, os.PathLike or PolyMesh
        A built-in example name or a mesh file; its design is computed before the server starts.
    host : str
        Address to bind (default only this machine).
    port : int
        Port to bind; 0 picks a free one.
    open_browser : bool
        Open the page in the default browser.
    allow_remote : bool
        Let ``host`` be an address other machines reach (see
        :func:`~filletfold.app.bind.check_bind`, which checks the address and the port
        before the design is made).

    Returns
    -------
    AppServer
        ``.url`` is the page's address; call ``.stop()`` (or ``.wait()`` to block until
        Ctrl-C).

    Raises
    ------
    FilletfoldError
        viser is missing, or the mesh cannot be read or rounded.
    """
    viser = _import_viser()
    bind = check_bind(host, port, allow_remote=allow_remote)  # before the design: fail at once
    check_origins()  # a page of another site may not drive a local app
    bound_uploads()  # an upload's size checked while it streams, not once it is held
    session = AppSession(
        radius=f"{DEFAULT_RADIUS_PERCENT}%",
        depth=f"{DEFAULT_DEPTH_PERCENT}%",
        samples=DEFAULT_SAMPLES,
    )
    session.load(mesh)
    # with numba (the fast extra), load the solver kernel now so every later change uses it
    threading.Thread(target=warm_kernel, name="filletfold-kernel", daemon=True).start()
    with _quiet_stdout():  # viser prints its own banner; the URL is logged and returned
        server = viser.ViserServer(host=host, port=port, label="filletfold", verbose=False)
    try:
        # every design is drawn scaled to the same box, so one initial camera frames them all;
        # set before any page connects (moving a connected page's camera can blank its canvas)
        server.initial_camera.position = CAMERA_POSITION
        server.initial_camera.look_at = CAMERA_LOOK_AT
        if port and server.get_port() != port:  # taken since it was checked: no other port
            raise ParameterError(
                f"port {port} on {host} is in use by another program; choose another --port, "
                "or --port 0 for a free one",
                name="port",
            )
        app = AppServer(server, session, host)
        app.remote = bind.remote
    except BaseException:
        server.stop()
        raise
    log.info("filletfold app at %s", app.url)
    if open_browser:
        webbrowser.open(app.url)
    return app
