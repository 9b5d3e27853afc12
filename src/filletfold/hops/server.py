"""The Hops server (``filletfold hops``): the Grasshopper components *Round* and *Pattern*.

Grasshopper's Hops component calls an HTTP endpoint: ``GET /`` lists the components,
``GET /round`` describes one, ``POST /round`` (or ``POST /solve`` with ``"pointer"``) solves it
with its inputs as ``{"values": [{"ParamName": ..., "InnerTree": {"{0}": [{"type": ...,
"data": ...}]}}]}``, each ``data`` a JSON text (a mesh: the JSON of ``rhino3dm``'s
``Mesh.Encode()``). The components are declared with ``ghhops-server`` (the ``hops`` extra:
``pip install 'filletfold[hops]'``), which reads the inputs and writes the outputs; the HTTP
server is this module's own (:class:`HopsServer`), so that it listens where
:func:`~filletfold.app.bind.check_bind` allows (this machine only), reads at most
:data:`REQUEST_LIMIT_BYTES`, and answers a failure in one line.

The components parse their inputs, call the library (:func:`~filletfold.design.round_mesh`,
reusing an earlier design of the same mesh: :class:`Designs`) and convert the design with
:mod:`filletfold.hops.convert`:

* *Round* (mesh, radius, depth, samples, sharp) -> the folded patches, their names, the
  mountain and valley creases, the flat pattern, each vertex's status, the summary; laid out
  as vertex modules without tabs, as the browser app draws a slider change.
* *Pattern* (the same, and size, sheet and sheet material) -> the cut, mountain, valley and
  tab curves of ``pattern.3dm`` (and a material's reliefs and kerf grooves), the sheets'
  outlines and the labels, laid out as the command line lays it out (nets, glue tabs, the
  default size), in the drawing's units.

A bad input or a design that fails answers HTTP 500 with ``{"values": [], "errors": [one
line]}`` (as ghhops-server answers a failure, so Hops shows it on the component), naming the
input or the element; never a traceback.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import logging
import socket
import threading
import time
from collections import OrderedDict
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import numpy as np

from ..defaults import DEFAULT_DEPTH, DEFAULT_RADIUS, DEFAULT_SAMPLES, DEFAULT_SHARP
from ..errors import FilletfoldError, MeshReadError, ParameterError, one_line

__all__ = [
    "PATTERN_URI",
    "REQUEST_LIMIT_BYTES",
    "ROUND_URI",
    "Designs",
    "HopsServer",
    "HopsService",
    "run_hops",
]

ROUND_URI = "/round"
PATTERN_URI = "/pattern"
#: The largest request read (a mesh of about a million triangles as Rhino encodes it): the
#: browser app's upload limit.
REQUEST_LIMIT_BYTES = 50 * 1024 * 1024
#: Meshes whose designs are kept for reuse (each with its last Round and Pattern design).
KEEP_MESHES = 4
#: The Grasshopper tab the components appear on.
CATEGORY = "filletfold"

log = logging.getLogger("filletfold.hops")


def import_ghhops():
    """Import ``ghhops_server``, or raise a one-line :class:`ParameterError` saying how to get
    it. Its import would set up the root logger at DEBUG (``logging.basicConfig``), printing
    every library's debug messages: a handler is in place while it imports, so that it does
    not."""
    root = logging.getLogger()
    placeholder = None
    if not root.handlers:
        placeholder = logging.NullHandler()
        root.addHandler(placeholder)
    try:
        import ghhops_server
    except ImportError:
        raise ParameterError(
            "the hops command needs ghhops-server: pip install 'filletfold[hops]'", name="hops"
        ) from None
    finally:
        if placeholder is not None:
            root.removeHandler(placeholder)
    return ghhops_server


def mesh_key(mesh) -> str:
    """A digest of a :class:`~filletfold.mesh.polymesh.PolyMesh`'s vertices and faces."""
    h = hashlib.sha1(np.ascontiguousarray(mesh.vertices, dtype=np.float64).tobytes())
    h.update(np.asarray(mesh.face_start, dtype=np.int64).tobytes())
    h.update(np.asarray(mesh.halfedge_from, dtype=np.int64).tobytes())
    return h.hexdigest()


class Designs:
    """The designs the server made, per mesh (the last :data:`KEEP_MESHES` meshes), for reuse.

    :meth:`design` answers a request it has answered before at once, and otherwise makes the
    design with ``reuse=`` the mesh's latest design (:func:`~filletfold.design.round_mesh`:
    the cleaned mesh is taken over, and with the same radius and sharp kinds the rounding,
    frames and normals too; a Pattern after a Round of the same parameters runs the layout
    stage only). One design is made at a time.
    """

    def __init__(self, keep: int = KEEP_MESHES):
        self.keep = keep
        self._held: OrderedDict = OrderedDict()  # mesh key -> {role: (params, design)}
        self._lock = threading.Lock()

    def design(self, mesh, params, role: str):
        """The design of ``mesh`` with ``params`` (a :class:`~filletfold.parameters.Parameters`)
        for ``role`` (``"round"`` or ``"pattern"``)."""
        from ..design import round_mesh

        key = mesh_key(mesh)
        with self._lock:
            held = self._held.get(key, {})
            for given, design in held.values():
                if given == params:
                    self._held.move_to_end(key)
                    return design
            reuse = held.get(role, next(iter(held.values()), (None, None)))[1]
            design = round_mesh(mesh, params, reuse=reuse, certify=False)
            held = self._held.setdefault(key, {})
            held[role] = (params, design)
            self._held.move_to_end(key)
            while len(self._held) > self.keep:
                self._held.popitem(last=False)
            return design


def _text(value, name: str, default: str) -> str:
    """A text input (Grasshopper turns a number slider's value into text): stripped, the
    default when empty."""
    if value is None:
        return default
    if isinstance(value, bool) or not isinstance(value, str | int | float):
        raise ParameterError(f"{name} must be text or a number, got {value!r}", name=name)
    text = str(value).strip()
    return text or default


def _parameters(radius, depth, samples, sharp, **more):
    """The :class:`~filletfold.parameters.Parameters` of a component's inputs, checked."""
    from ..parameters import Parameters

    if isinstance(samples, float) and samples.is_integer():
        samples = int(samples)
    params = Parameters().replace(
        radius=_text(radius, "radius", DEFAULT_RADIUS),
        depth=_text(depth, "depth", DEFAULT_DEPTH),
        samples=samples,
        sharp=_text(sharp, "sharp", DEFAULT_SHARP),
        **more,
    )
    params.check()
    return params


class HopsService:
    """The components and their designs, without any HTTP: :meth:`query` and :meth:`solve`
    answer what the server is asked (the tests call them directly too).

    Parameters
    ----------
    designs : Designs, optional
        Where the designs are kept (a new one by default).
    """

    def __init__(self, designs: Designs | None = None):
        self.designs = designs or Designs()
        #: Each component's URI -> (its name, its inputs' names).
        self.components: dict = {}
        self._local = threading.local()
        self._lock = threading.Lock()  # ghhops prints each input while it reads it: quieted
        self.hops = self._components(import_ghhops())

    # -- the components ------------------------------------------------------------------
    def _components(self, hs):
        hops = hs.Hops()  # the standalone dispatcher; this module serves it over HTTP
        logging.getLogger("Hops").setLevel(logging.WARNING)
        item, tree, many = hs.HopsParamAccess.ITEM, hs.HopsParamAccess.TREE, hs.HopsParamAccess.LIST
        design_inputs = [
            hs.HopsMesh("Mesh", "M", "The polyhedral mesh (its polygons may be n-gons)"),
            hs.HopsString(
                "Radius", "R", "Rounding radius: a length, or N% of the mean edge length"
            ),
            hs.HopsString("Depth", "D", "Apex depth along the vertex normal: a length or N%"),
            hs.HopsInteger("Samples", "N", "Most points per arc (at least 3)"),
            hs.HopsString(
                "Sharp",
                "S",
                "Vertices without a cone kept sharp: auto, none, all, or a list of saddle, "
                "infeasible, boundary",
            ),
        ]

        @hops.component(
            ROUND_URI,
            name="Round",
            nickname="Round",
            description="Round every edge by a cylinder and every vertex by a cone "
            "(filletfold): the folded patches, the creases and the flat pattern",
            category=CATEGORY,
            subcategory="Design",
            inputs=design_inputs,
            outputs=[
                hs.HopsMesh(
                    "Folded",
                    "F",
                    "A mesh per patch; branches cone, cylinder, fillet, face",
                    access=tree,
                ),
                hs.HopsString("Names", "P", "Each patch's name, as Folded", access=tree),
                hs.HopsCurve("Mountain", "M", "Mountain creases, folded", access=many),
                hs.HopsCurve("Valley", "V", "Valley creases, folded", access=many),
                hs.HopsCurve(
                    "Pattern",
                    "C",
                    "The flat pattern: {0} cuts, {1} mountain, {2} valley",
                    access=tree,
                ),
                hs.HopsString("Status", "St", "Each vertex's status", access=many),
                hs.HopsString("Summary", "Sum", "The design's summary", access=item),
            ],
        )
        def round_component(
            mesh,
            radius=DEFAULT_RADIUS,
            depth=DEFAULT_DEPTH,
            samples=DEFAULT_SAMPLES,
            sharp=DEFAULT_SHARP,
        ):
            return self._run(7, self._round, mesh, radius, depth, samples, sharp)

        @hops.component(
            PATTERN_URI,
            name="Pattern",
            nickname="Pattern",
            description="The pattern to cut (filletfold): cut, mountain, valley and tab "
            "curves as on pattern.3dm's layers, sheet outlines and labels, in the drawing's "
            "units",
            category=CATEGORY,
            subcategory="Fabricate",
            inputs=[
                *design_inputs,
                hs.HopsString(
                    "Size", "Sz", "The object's size (300mm, 30cm, 12in), auto or none (unitless)"
                ),
                hs.HopsString(
                    "Sheet", "Sh", "Sheet size: A4, A3, Letter or WxH in mm; empty: no sheets"
                ),
                hs.HopsString(
                    "Material",
                    "Mat",
                    "Sheet material (card-300gsm, aluminium-1mm, plywood-3mm, ...; empty: none): "
                    "fillets no tighter than it bends, reliefs and kerf grooves",
                ),
            ],
            outputs=[
                hs.HopsCurve("Cut", "C", "Layer CUT: piece borders and tab outlines", access=many),
                hs.HopsCurve("Mountain", "M", "Layer MOUNTAIN", access=many),
                hs.HopsCurve("Valley", "V", "Layer VALLEY", access=many),
                hs.HopsCurve("Tab", "T", "Layer TAB: the tabs' hinges", access=many),
                hs.HopsCurve(
                    "Relief", "Rf", "Layer RELIEF: cut out (a relieved material)", access=many
                ),
                hs.HopsCurve(
                    "KerfFront", "KF", "Layer KERF_FRONT: grooves cut from the front", access=many
                ),
                hs.HopsCurve(
                    "KerfBack", "KB", "Layer KERF_BACK: grooves cut from the back", access=many
                ),
                hs.HopsCurve("Sheets", "Sh", "Each sheet's outline", access=many),
                hs.HopsPoint("LabelPoints", "LP", "Where each label is", access=many),
                hs.HopsString("Labels", "L", "Each label's text", access=many),
                hs.HopsString("Units", "U", "The drawing's unit (empty: none)", access=item),
                hs.HopsString("Summary", "Sum", "The design's summary", access=item),
            ],
        )
        def pattern_component(
            mesh,
            radius=DEFAULT_RADIUS,
            depth=DEFAULT_DEPTH,
            samples=DEFAULT_SAMPLES,
            sharp=DEFAULT_SHARP,
            size="auto",
            sheet="",
            material="",
        ):
            inputs = (radius, depth, samples, sharp, size, sheet, material)
            return self._run(12, self._pattern, mesh, inputs)

        names = [p.name for p in design_inputs]
        self.components = {
            ROUND_URI: ("Round", names),
            PATTERN_URI: ("Pattern", [*names, "Size", "Sheet", "Material"]),
        }
        return hops

    def _run(self, n_outputs: int, fn, *args):
        """``fn(*args)``; a failure is kept as its one line (the response gives it, not
        ghhops-server's traceback) and the outputs are empty."""
        try:
            return fn(*args)
        except FilletfoldError as exc:
            self._local.error = str(exc)
        except Exception as exc:
            self._local.error = f"internal error: {one_line(exc)}"
        return (None,) * n_outputs

    def _round(self, mesh, radius, depth, samples, sharp):
        from .convert import mesh_from_rhino, round_outputs

        pm = mesh_from_rhino(mesh)
        params = _parameters(radius, depth, samples, sharp, layout="modules", tabs=False)
        out = round_outputs(self.designs.design(pm, params, "round"))
        keys = ("folded", "names", "mountain", "valley", "pattern", "status", "summary")
        return tuple(out[k] for k in keys)

    def _pattern(self, mesh, inputs):
        from .convert import mesh_from_rhino, pattern_outputs

        radius, depth, samples, sharp, size, sheet, material = inputs
        pm = mesh_from_rhino(mesh)
        size = _text(size, "size", "auto")
        sheet = _text(sheet, "sheet", "")
        material = _text(material, "material", "")
        params = _parameters(
            radius,
            depth,
            samples,
            sharp,
            size=None if size.lower() == "none" else size,
            sheet=sheet or None,
            material=material or None,
        )
        out = pattern_outputs(self.designs.design(pm, params, "pattern"))
        keys = ("cut", "mountain", "valley", "tab", "relief", "kerf_front", "kerf_back")
        keys += ("sheets", "label_points", "labels")
        return (*(out[k] for k in keys), out["units"], out["summary"])

    # -- requests ------------------------------------------------------------------------
    def query(self, uri: str) -> tuple[int, str]:
        """``(HTTP status, JSON text)`` of a ``GET``: the components' descriptions."""
        found, text = self.hops.query(uri=uri)
        return (200 if found else 404), text

    def solve(self, uri: str, payload: bytes | str) -> tuple[int, str]:
        """``(HTTP status, JSON text)`` of a ``POST``: the component's outputs, or a failure
        as ``{"values": [], "errors": [one line]}`` with status 500 (404 for no component)."""
        try:
            uri = _check_request(uri, payload, self.components)
        except FilletfoldError as exc:
            return 500, _errors(str(exc))
        with self._lock:
            self._local.error = None
            try:
                with contextlib.redirect_stdout(io.StringIO()):
                    ok, text = self.hops.solve(uri=uri, payload=payload)
            except FilletfoldError as exc:
                return 500, _errors(str(exc))
            except Exception as exc:  # an input ghhops-server could not read
                return 500, _errors(_input_failure(exc))
            if self._local.error:
                return 500, _errors(self._local.error)
        if not ok:
            errors = json.loads(text).get("errors") or ["the request could not be solved"]
            return 500, _errors(one_line(Exception(errors[0])).split(": ", 1)[-1])
        return 200, text


def _errors(message: str) -> str:
    return json.dumps({"values": [], "errors": [message]})


def _input_failure(exc: Exception) -> str:
    text = one_line(exc)
    return f"an input could not be read: {text}"


def _check_request(uri: str, payload, components: dict) -> str:
    """The component's URI of a solve request, after checking the request names one and
    holds a value for each of its inputs (else a one-line :class:`ParameterError` or
    :class:`MeshReadError`)."""
    try:
        data = json.loads(payload)
    except (ValueError, UnicodeDecodeError) as exc:
        raise ParameterError(f"request: not JSON ({exc})", name="request") from None
    if not isinstance(data, dict) or not isinstance(data.get("values"), list):
        raise ParameterError("request: no list of 'values'", name="request")
    if uri == "/solve":
        pointer = data.get("pointer")
        if not isinstance(pointer, str):
            raise ParameterError("request: /solve needs a 'pointer'", name="request")
        uri = pointer if pointer.startswith("/") else "/" + pointer
    if uri not in components:
        raise ParameterError(f"request: no component at {uri}", name="request")
    component, inputs = components[uri]
    given = {}
    for value in data["values"]:
        tree = value.get("InnerTree") if isinstance(value, dict) else None
        if not isinstance(tree, dict) or not isinstance(value.get("ParamName"), str):
            raise ParameterError("request: a value without ParamName or InnerTree", name="request")
        given[value["ParamName"]] = tree
    for name in inputs:
        items = given.get(name, {}).get("{0}")
        if not isinstance(items, list) or not items:
            raise ParameterError(f"{name}: no value given", name=name)
        for item in items:
            if not isinstance(item, dict) or not isinstance(item.get("data"), str):
                raise ParameterError(f"{name}: a value without its data", name=name)
            if name == "Mesh":
                _check_mesh_data(item["data"])
    extra = sorted(set(given) - set(inputs))
    if extra:
        raise ParameterError(f"{extra[0]}: not an input of {component}", name=extra[0])
    return uri


def _check_mesh_data(text: str) -> None:
    """A mesh's ``data``: the JSON of an encoded Rhino object (else a :class:`MeshReadError`)."""
    try:
        obj = json.loads(text)
    except ValueError:
        raise MeshReadError("Mesh: its data is not JSON") from None
    keys = ("version", "archive3dm", "opennurbs", "data")
    if not isinstance(obj, dict) or any(k not in obj for k in keys):
        raise MeshReadError("Mesh: its data is not an encoded Rhino object")
    if not isinstance(obj["data"], str) or not all(
        isinstance(obj[k], int) and not isinstance(obj[k], bool) for k in keys[:3]
    ):
        raise MeshReadError("Mesh: its data is not an encoded Rhino object")


class _Server6(ThreadingHTTPServer):
    address_family = socket.AF_INET6


class HopsServer:
    """A running Hops server (:func:`run_hops`): ``url``, :meth:`wait`, :meth:`stop`."""

    def __init__(self, httpd: ThreadingHTTPServer, service: HopsService, host: str):
        self.httpd, self.service = httpd, service
        port = httpd.server_address[1]
        self.url = f"http://{'[' + host + ']' if ':' in host else host}:{port}/"
        self._thread = threading.Thread(
            target=httpd.serve_forever, name="filletfold-hops", daemon=True
        )
        self._thread.start()

    def wait(self) -> None:
        """Block until Ctrl-C (then stop)."""
        try:
            while self._thread.is_alive():
                self._thread.join(0.5)
        except KeyboardInterrupt:
            pass
        finally:
            self.stop()

    def stop(self) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()


def _handler(service: HopsService, say):
    from ..app.bind import LOCAL_ORIGIN

    class Handler(BaseHTTPRequestHandler):
        server_version = "filletfold-hops"
        protocol_version = "HTTP/1.1"

        def log_message(self, format, *args):
            pass

        def _send(self, status: int, text: str) -> None:
            body = text.encode("utf-8")
            self.send_response(status)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            if self.command != "HEAD":
                self.wfile.write(body)

        def _refused(self) -> bool:
            origin = self.headers.get("Origin")
            if origin is not None and not LOCAL_ORIGIN.fullmatch(origin):
                self._send(403, _errors(f"request from {origin} refused: this machine only"))
                return True
            return False

        def do_HEAD(self):
            self._send(200, "")

        def do_GET(self):
            if not self._refused():
                self._send(*service.query(self.path.split("?")[0]))

        def do_POST(self):
            if self._refused():
                return
            t0 = time.perf_counter()
            try:
                length = int(self.headers.get("Content-Length", ""))
            except ValueError:
                length = -1
            if not 0 <= length <= REQUEST_LIMIT_BYTES:
                self.close_connection = True
                limit = REQUEST_LIMIT_BYTES // (1024 * 1024)
                self._send(413, _errors(f"request: no length, or over the limit of {limit} MB"))
                return
            payload = self.rfile.read(length)
            uri = self.path.split("?")[0]
            status, text = service.solve(uri, payload)
            self._send(status, text)
            ms = 1000 * (time.perf_counter() - t0)
            what = "" if status == 200 else ": " + json.loads(text)["errors"][0]
            say(f"POST {uri} {status} in {ms:.0f} ms ({length:,} -> {len(text):,} bytes){what}")

    return Handler


def run_hops(host: str = "127.0.0.1", port: int = 5000, say=None) -> HopsServer:
    """Start the Hops server and return at once (it serves in a thread).

    Parameters
    ----------
    host : str
        An address of this machine only (:func:`~filletfold.app.bind.check_bind`: another is
        refused).
    port : int
        0 picks a free one; a port in use is refused.
    say : callable, optional
        ``say(line)`` for each solve answered (its time and sizes).

    Raises
    ------
    ParameterError
        ghhops-server or rhino3dm missing, an address other machines reach, or a port in use.
    """
    from ..app.bind import check_bind
    from ..export.rhino import require_rhino3dm

    bind = check_bind(host, port, allow_remote=True)  # resolved, the port free
    if bind.remote:  # this machine only: Hops runs beside Rhino
        raise ParameterError(
            f"--host {host} lets other machines reach the server (whoever reaches it can make "
            "it compute); bind 127.0.0.1",
            name="host",
        )
    require_rhino3dm()
    service = HopsService()
    address = bind.addresses[0]
    server_class = _Server6 if ":" in address else ThreadingHTTPServer
    try:
        httpd = server_class((address, port), _handler(service, say or log.info))
    except OSError as exc:
        raise ParameterError(
            f"cannot listen on {host}:{port}: {exc.strerror or exc}", name="port"
        ) from None
    httpd.daemon_threads = True
    return HopsServer(httpd, service, host)
