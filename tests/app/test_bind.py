"""Where the app listens (issue 30): this machine only unless --allow-remote, a bad address
or a busy port refused at once, naming them, before any design is made."""

from __future__ import annotations

import socket
import time

import pytest

from filletfold.app.bind import RESOLVE_SECONDS, check_bind
from filletfold.cli import main
from filletfold.errors import ParameterError


def test_this_machine_only_unless_allowed():
    assert not check_bind("127.0.0.1", 0).remote
    assert not check_bind("localhost", 0).remote
    refused = r"--host 0\.0\.0\.0 lets other machines .*--allow-remote"
    with pytest.raises(ParameterError, match=refused):
        check_bind("0.0.0.0", 0)
    assert check_bind("0.0.0.0", 0, allow_remote=True).remote


def test_a_bad_address_fails_at_once():
    t = time.perf_counter()
    for host in ("no-such-host.invalid", "", "999.1.1.1"):
        with pytest.raises(ParameterError, match="host"):
            check_bind(host, 0)
    assert time.perf_counter() - t < 3 * RESOLVE_SECONDS + 1


def test_a_busy_port_is_refused_not_replaced():
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(ParameterError, match=f"port {port} on 127.0.0.1 is in use"):
            check_bind("127.0.0.1", port)
    check_bind("127.0.0.1", port)  # free again


def test_the_command_refuses_before_it_makes_a_design(capsys):
    t = time.perf_counter()
    assert main(["app", "cube", "--host", "0.0.0.0"]) == 2
    assert "--allow-remote" in capsys.readouterr().err
    assert time.perf_counter() - t < 5


def test_a_page_of_another_site_cannot_open_a_local_apps_websocket():
    pytest.importorskip("viser")
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    from filletfold.app import run_app

    app = run_app("tetrahedron", host="127.0.0.1", port=0)
    try:
        url = f"ws://127.0.0.1:{app.port}"
        with pytest.raises(InvalidStatus, match="403"):
            connect(url, origin="http://evil.example", open_timeout=10).close()
        for page in (f"http://127.0.0.1:{app.port}", f"http://localhost:{app.port}", None):
            connect(url, origin=page, open_timeout=10).close()  # the app's own page
    finally:
        app.stop()
