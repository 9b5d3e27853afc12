"""A page of the app without a browser: a viser websocket client, as the page's JavaScript is.

:class:`Page` connects to an app as a browser tab does (viser's subprotocol, this machine's
Origin), reads what the server sends (counting the bytes, never decoding the scene) and sends
what the panel sends when the user moves a control (:meth:`Page.set`), so tests can drive
several pages at once.
"""

from __future__ import annotations

import threading
import time

import msgspec
import viser
from viser._messages import GuiUpdateMessage, ViewerCameraMessage
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect


class Page:
    """One connected page of the app at ``url`` (``http://HOST:PORT``); a context manager
    that closes it.

    Attributes
    ----------
    received : int
        Bytes the server sent this page so far.
    """

    def __init__(self, url: str, timeout: float = 10.0):
        host_port = url.split("://", 1)[1].rstrip("/")
        self.ws = connect(
            f"ws://{host_port}",
            subprotocols=[f"viser-v{viser.__version__}"],
            origin=url.rstrip("/"),
            open_timeout=timeout,
            max_size=None,
        )
        self.received = 0
        self._lock = threading.Lock()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        # viser counts a page as connected once its viewer reports a camera
        camera = ViewerCameraMessage(
            (1.0, 0.0, 0.0, 0.0),
            (0.0, 0.0, 5.0),
            1.0,
            0.01,
            100.0,
            800,
            1200,
            (0.0, 0.0, 0.0),
            (0.0, 0.0, 1.0),
        )
        self.send(camera)

    def _read(self) -> None:
        try:
            for message in self.ws:
                with self._lock:
                    self.received += len(message)
        except ConnectionClosed:
            pass

    def set(self, handle, value) -> None:
        """Send what the page sends when the user sets the control ``handle`` (a viser GUI
        handle of this page's panel) to ``value``."""
        self.send(GuiUpdateMessage(handle._impl.uuid, {"value": value}))

    def send(self, message) -> None:
        """Send a viser message as the page's JavaScript would."""
        self.ws.send(msgspec.msgpack.encode(message.as_serializable_dict()))

    def settle(self, quiet: float = 0.3, timeout: float = 10.0) -> int:
        """Wait until nothing has arrived for ``quiet`` seconds; returns :attr:`received`."""
        end = time.monotonic() + timeout
        last = -1
        while self.received != last and time.monotonic() < end:
            last = self.received
            time.sleep(quiet)
        return self.received

    def close(self) -> None:
        """Close the connection (as closing the tab does)."""
        self.ws.close()
        self._reader.join(timeout=10)

    def __enter__(self) -> Page:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
