"""Where the app listens (issue 30): this machine only unless --allow-remote, a bad address
or a busy port refused at once, naming them, before any design is made."""

from __future__ import annotations

import os
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
        busy = f"port {port} on 127.0.0.1 is in use by .+ \\(pid {os.getpid()}\\)"
        with pytest.raises(ParameterError, match=busy):
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


def test_an_upload_over_the_limit_is_dropped_while_it_streams():
    """Issue 30: an upload's size was checked once viser had received all of it (a 1 GB file
    held 2.3 GB). A transfer announced over the limit keeps nothing; one whose parts exceed
    what it announced is dropped at the first part over; the page says why."""
    pytest.importorskip("viser")
    from viser import _messages as m

    from filletfold.app import run_app
    from filletfold.app.session import UPLOAD_LIMIT_BYTES

    from .page import Page

    app = run_app("tetrahedron", host="127.0.0.1", port=0)
    page = Page(app.url)
    try:
        view = app.wait_view()
        api = view.client.gui  # the page's own panel
        button = view._upload_button._impl.uuid

        def held():  # the transfers the page's panel keeps, once the server has read them
            time.sleep(0.3)
            return api._current_file_upload_states

        page.send(m.FileTransferStartUpload(button, "t1", "huge.obj", "", 20_000, 1 << 30))
        assert "t1" not in held()
        assert "huge.obj" in view.status and "up to 50 MB" in view.status
        page.send(m.FileTransferStartUpload(button, "t2", "small.obj", "", 3, 1000))
        assert "t2" in held()
        page.send(m.FileTransferPart(button, "t2", 0, b"v" * 600))
        assert "t2" in held()
        page.send(m.FileTransferPart(button, "t2", 1, b"v" * 600))
        assert "t2" not in held()  # 1200 bytes of 1000: dropped
        assert "small.obj" in view.status
        assert UPLOAD_LIMIT_BYTES == 50 * 1024 * 1024
    finally:
        page.close()
        app.stop()
