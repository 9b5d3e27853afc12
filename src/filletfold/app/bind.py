"""Where the app may listen: checked before anything is computed (issue 30).

The app drives a design (and reads the files a user uploads) for whoever can reach its port,
so it listens on this machine only unless told otherwise: :func:`check_bind` refuses an
address other machines can reach (``0.0.0.0``, a LAN address, a public name) unless
``allow_remote``, fails at once on an address that does not resolve (within
:data:`RESOLVE_SECONDS`) and on a port something else listens on (unless the port is 0: a free
one), instead of hanging or moving silently to another port.
"""

from __future__ import annotations

import errno
import functools
import ipaddress
import os
import re
import socket
import threading
from dataclasses import dataclass

from ..errors import ParameterError

__all__ = ["LOCAL_ORIGIN", "RESOLVE_SECONDS", "Bind", "check_bind", "check_origins"]

#: The pages that may open the app's websocket when it listens on this machine only: its own
#: page, as ``localhost``, a ``127.x.y.z`` address or ``[::1]``, on any port. A page of any
#: other site open in a browser here is refused (a client that sends no ``Origin``, not a
#: browser, is let in).
LOCAL_ORIGIN = re.compile(r"https?://(localhost|127(\.\d{1,3}){3}|\[::1\])(:\d+)?")

#: How long an address may take to resolve before the app gives up on it.
RESOLVE_SECONDS = 3.0


@dataclass(frozen=True)
class Bind:
    """A checked address: ``host`` as given, its ``addresses``, and whether other machines
    can reach it (``remote``)."""

    host: str
    addresses: tuple
    remote: bool


def check_bind(host: str, port: int, *, allow_remote: bool = False) -> Bind:
    """Check that the app may listen on ``host``:``port``.

    Raises
    ------
    ParameterError
        Naming ``host`` or ``port``: an empty host, one that does not resolve in
        :data:`RESOLVE_SECONDS`, one other machines can reach without ``allow_remote``, a port
        outside 0..65535 or one in use.
    """
    if not isinstance(port, int) or isinstance(port, bool) or not 0 <= port <= 65535:
        raise ParameterError(f"port must be in 0..65535, got {port!r}", name="port")
    host = (host or "").strip()
    if not host:
        raise ParameterError(
            "--host is empty; give an address (127.0.0.1: this machine only)", name="host"
        )
    addresses = _resolve(host)
    remote = _remote(addresses)
    if remote and not allow_remote:
        raise ParameterError(
            f"--host {host} lets other machines reach the app (whoever reaches it can drive "
            "it and upload files to it); give --allow-remote to serve it so, or bind "
            "127.0.0.1",
            name="host",
        )
    if port:
        _check_free(addresses[0], port, host)
    return Bind(host, addresses, remote)


def _resolve(host: str) -> tuple:
    """The addresses of ``host``, resolved in a thread so that a name server that does not
    answer costs :data:`RESOLVE_SECONDS`, not minutes."""
    found: list = []

    def resolve():
        try:
            infos = socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)
            found.append(tuple(dict.fromkeys(info[4][0] for info in infos)))
        except (OSError, UnicodeError) as exc:
            found.append(exc)

    worker = threading.Thread(target=resolve, name="filletfold-resolve", daemon=True)
    worker.start()
    worker.join(RESOLVE_SECONDS)
    if not found:
        raise ParameterError(
            f"--host {host} did not resolve within {RESOLVE_SECONDS:g} s", name="host"
        )
    if isinstance(found[0], Exception) or not found[0]:
        why = getattr(found[0], "strerror", None) or str(found[0]) or "no address"
        raise ParameterError(f"--host {host} is not an address of this machine: {why}", name="host")
    return found[0]


def _remote(addresses) -> bool:
    """Whether other machines reach any of ``addresses`` (a host's, resolved)."""
    return not all(_local(a) for a in addresses)


def _local(address: str) -> bool:
    """Whether only this machine reaches ``address`` (a loopback address)."""
    try:
        return ipaddress.ip_address(address.split("%")[0]).is_loopback
    except ValueError:
        return False


def _check_free(address: str, port: int, host: str) -> None:
    """A :class:`ParameterError` naming ``port`` when something listens there already, or
    when ``host`` is not an address of this machine."""
    family = socket.AF_INET6 if ":" in address else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as servers bind
        try:
            probe.bind((address, port))
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                owner = port_owner(port)
                by = f"by {owner}" if owner else "by another program"
                raise ParameterError(
                    f"port {port} on {host} is in use {by}; choose another --port, or --port 0 "
                    "for a free one",
                    name="port",
                ) from None
            if exc.errno == errno.EADDRNOTAVAIL:
                raise ParameterError(
                    f"--host {host} is not an address of this machine", name="host"
                ) from None
            raise ParameterError(
                f"cannot listen on {host}:{port}: {exc.strerror or exc}", name="port"
            ) from None


def check_origins() -> None:
    """Make the websocket server viser starts check the page's ``Origin`` when it listens on
    this machine only (:data:`LOCAL_ORIGIN`): without it, any site open in a browser on this
    machine could drive a local app. Installed once, for every app of the process: viser
    passes no ``origins`` of its own, and a remote bind (``--allow-remote``) keeps none."""
    import websockets.asyncio.server as ws

    if getattr(ws.serve, "_filletfold_origins", False):
        return
    serve = ws.serve

    @functools.wraps(serve)
    def checked(handler, host=None, port=None, *args, **kwargs):
        if kwargs.get("origins") is None and host is not None:
            try:  # local as check_bind decides it; an address that fails it: checked too
                local = not _remote(_resolve(str(host)))
            except ParameterError:
                local = True
            if local:
                kwargs["origins"] = [LOCAL_ORIGIN, None]
        return serve(handler, host, port, *args, **kwargs)

    checked._filletfold_origins = True
    ws.serve = checked


def port_owner(port: int) -> str | None:
    """The program listening on TCP ``port`` (``"python3 (pid 123)"``), where the system says
    (Linux ``/proc``: the socket's inode in ``/proc/net/tcp*``, then the process holding it;
    only this user's processes can be looked into); None when it cannot be told."""
    inodes = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            with open(table) as fh:
                rows = fh.readlines()[1:]
        except OSError:
            continue
        for row in rows:
            cols = row.split()
            if len(cols) > 9 and cols[3] == "0A" and int(cols[1].rsplit(":", 1)[1], 16) == port:
                inodes.add(f"socket:[{cols[9]}]")  # 0A: listening
    if not inodes:
        return None
    try:
        pids = [d for d in os.listdir("/proc") if d.isdigit()]
    except OSError:
        return None
    for pid in sorted(pids, key=int):
        try:
            fds = os.listdir(f"/proc/{pid}/fd")
            if not any(os.readlink(f"/proc/{pid}/fd/{fd}") in inodes for fd in fds):
                continue
            with open(f"/proc/{pid}/comm") as fh:
                return f"{fh.read().strip()} (pid {pid})"
        except OSError:
            continue
    return None
