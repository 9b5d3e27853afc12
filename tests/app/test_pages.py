"""Two pages of the app at once (issue 30): each has a design of its own.

All browser tabs of the app used to share one design: one user's upload replaced what
another user saw. Each page is now an :class:`~filletfold.app.server.AppView` with its own
session, panel, scene and worker. The pages here are websocket clients (:class:`.page.Page`)
that send what the page's JavaScript sends.
"""

from __future__ import annotations

import threading
import time

import pytest

pytest.importorskip("viser")

from filletfold.app import run_app
from filletfold.app import server as server_mod
from filletfold.app import session as session_mod

from .page import Page


def _until(predicate, timeout=60.0, what="") -> None:
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            pytest.fail(f"timed out after {timeout:.0f} s waiting for {what}")
        time.sleep(0.05)


@pytest.fixture
def app():
    app = run_app("cube", host="127.0.0.1", port=0)
    try:
        yield app
    finally:
        app.stop()


def test_two_pages_each_keep_their_own_design(app):
    with Page(app.url) as page_a, Page(app.url) as page_b:
        _until(lambda: len(app.views) == 2, 30, "two views")
        a, b = (app.views[k] for k in sorted(app.views))
        assert a.session is not b.session and a.client is not b.client
        assert a.wait_drawn(1) and b.wait_drawn(1)  # each page drew the starting design
        start = b.session.design
        assert a.session.design is start  # shared until one of them changes

        # page A moves its radius slider: only A's design changes
        page_a.set(a._radius, 15.0)
        _until(lambda: a.session.design.params.radius == "15.0%", 60, "A's new design")
        assert a.wait_idle(60)
        assert b.session.params.radius == "10.0%" and b.session.design is start
        assert "radius 15.0%" in a.status and "radius 10.0%" in b.status

        # page B picks another example; page A is sent nothing of it
        sent_to_a = page_a.settle()  # A's own redraw has arrived
        drawn_b = page_b.received
        page_b.set(b._example, "tetrahedron")
        _until(lambda: b.session.name == "tetrahedron" and b.wait_idle(1), 60, "B's load")
        _until(lambda: page_b.received > drawn_b + 10_000, 10, "B's scene at page B")
        assert page_a.settle() == sent_to_a  # anything (wrongly) sent to A has arrived
        assert a.session.name == "cube" and a.session.design.params.radius == "15.0%"
        assert b.status.startswith("**tetrahedron**") and a.status.startswith("**cube**")

        # closing page A ends its view and its worker; B goes on
        page_a.close()
        _until(lambda: len(app.views) == 1, 30, "A's view to go")
        a.join(10)
        assert not a._worker.is_alive()
        page_b.set(b._radius, 20.0)
        _until(lambda: b.session.design.params.radius == "20.0%", 60, "B's radius")


@pytest.mark.slow
def test_pages_over_the_limit_are_told_and_one_design_computed_at_a_time(app, monkeypatch):
    monkeypatch.setattr(server_mod, "MAX_PAGES", 2)
    real = session_mod.round_mesh
    hold, held = threading.Event(), threading.Event()
    running, most = [0], [0]
    lock = threading.Lock()

    def counted_round_mesh(*args, **kw):
        with lock:
            running[0] += 1
            most[0] = max(most[0], running[0])
        try:
            if hold.is_set():
                held.set()
                time.sleep(1.0)  # long enough for the other page to be kept waiting
            return real(*args, **kw)
        finally:
            with lock:
                running[0] -= 1

    monkeypatch.setattr(session_mod, "round_mesh", counted_round_mesh)
    with Page(app.url) as page_a, Page(app.url) as page_b:
        _until(lambda: len(app.views) == 2, 30, "two views")
        with Page(app.url) as page_c:  # a third page: refused, told why
            _until(lambda: app.refused == 1, 30, "the third page refused")
            _until(lambda: page_c.received > 0, 10, "the refusal at the third page")
            assert len(app.views) == 2
        a, b = (app.views[k] for k in sorted(app.views))

        # both pages change at once: one computes, the other waits and says so
        hold.set()
        page_a.set(a._radius, 12.0)
        assert held.wait(30)
        page_b.set(b._radius, 14.0)
        _until(lambda: "waiting: another page" in b.status, 10, "B to say it waits")
        _until(
            lambda: (
                a.session.design.params.radius == "12.0%"
                and b.session.design.params.radius == "14.0%"
            ),
            60,
            "both designs",
        )
        assert most[0] == 1
        assert b.wait_idle(30) and b.status.startswith("**cube**")
    _until(lambda: not app.views, 30, "the views of closed pages to go")
    with Page(app.url):  # room again
        assert app.wait_view(timeout=30).wait_drawn(1)
