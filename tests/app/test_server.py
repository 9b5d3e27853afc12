"""The app in a real headless browser, driven through the page (Debian's ``chromium`` and
``chromium-driver``; skipped with the reason when either is missing, ``.ci/run`` installs them).

The browser is driven by chromedriver's W3C WebDriver HTTP protocol through the small client
:class:`WebDriver` (urllib only). The test loads the page, checks that the 3D canvas draws the
design, moves the radius slider with the keyboard and sees the design change in the server and
in the picture, and uploads a bad file through the page's upload control and sees the reader's
error in the page. Screenshots are kept as test artefacts in ``tests/artifacts/``
(git-ignored).
"""

from __future__ import annotations

import base64
import io
import json
import os
import shutil
import signal
import socket
import subprocess
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMEDRIVER = shutil.which("chromedriver")
ARTIFACTS = Path(__file__).parent.parent / "artifacts"
#: Flags that keep chromium headless and off the network.
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--window-size=1200,800",
]
ELEMENT = "element-6066-11e4-a52e-4f735466cecf"  # W3C key of an element reference
ARROW_RIGHT = "\ue014"
BAD_OBJ = b"v 1 2\nf 1 2 3\n"

# The nearest control (CSS selector arguments[1]) around the element whose own text is
# arguments[0]: a viser input sits beside its label, an upload input inside its button's box.
FIND_BY_LABEL = """
const [label, selector] = arguments;
const own = (e) => [...e.childNodes].some(
  (n) => n.nodeType === Node.TEXT_NODE && n.textContent.trim() === label);
const hit = [...document.querySelectorAll("body *")].find(own);
for (let a = hit; a; a = a.parentElement) {
  const control = a.querySelector(selector);
  if (control) return control;
}
return null;
"""


class WebDriverError(RuntimeError):
    """An error answer of chromedriver, or no answer in time."""


class WebDriver:
    """A minimal W3C WebDriver client for chromedriver (one browser session).

    Parameters
    ----------
    port : int
        Port chromedriver listens on (127.0.0.1).
    profile : Path
        Chromium's user-data directory.
    start_timeout : float
        Seconds to wait for the browser to start.
    """

    def __init__(self, port: int, profile: Path, start_timeout: float = 60.0):
        self.base = f"http://127.0.0.1:{port}"
        options = {"binary": CHROMIUM, "args": [*CHROMIUM_ARGS, f"--user-data-dir={profile}"]}
        caps = {"alwaysMatch": {"browserName": "chrome", "goog:chromeOptions": options}}
        value = self._call("POST", "/session", {"capabilities": caps}, timeout=start_timeout)
        self.session = value["sessionId"]

    def _call(self, method: str, path: str, body=None, timeout: float = 60.0):
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(
            self.base + path, data=data, method=method, headers={"Content-Type": "application/json"}
        )
        try:
            with urllib.request.urlopen(req, timeout=timeout) as r:
                return json.loads(r.read())["value"]
        except urllib.error.HTTPError as exc:
            value = json.loads(exc.read() or b"{}").get("value", {})
            raise WebDriverError(f"{value.get('error')}: {value.get('message')}") from None
        except (OSError, TimeoutError) as exc:
            raise WebDriverError(f"no answer from chromedriver to {method} {path}: {exc}") from None

    def cmd(self, method: str, path: str, body=None, timeout: float = 60.0):
        """A command of this session (``path`` after ``/session/ID``)."""
        return self._call(method, f"/session/{self.session}{path}", body, timeout)

    def get(self, url: str) -> None:
        """Load a page."""
        self.cmd("POST", "/url", {"url": url})

    def script(self, source: str, *args):
        """Run JavaScript in the page; returns its result (elements as references)."""
        return self.cmd("POST", "/execute/sync", {"script": source, "args": list(args)})

    def find_by_label(self, label: str, selector: str) -> str:
        """Element id of the control ``selector`` next to the text ``label``."""
        found = self.script(FIND_BY_LABEL, label, selector)
        if not found:
            raise WebDriverError(f"no {selector} next to {label!r} in the page")
        return found[ELEMENT]

    def send_keys(self, element: str, text: str) -> None:
        """Type ``text`` into an element (for a file input: the file's path)."""
        self.cmd("POST", f"/element/{element}/value", {"text": text})

    def text(self) -> str:
        """The page's visible text."""
        return self.script("return document.body.innerText;")

    def screenshot(self, out: Path):
        """Save a PNG of the viewport to ``out``; returns it as an (h, w, 3) float array."""
        from matplotlib.image import imread

        png = base64.b64decode(self.cmd("GET", "/screenshot"))
        out.write_bytes(png)
        return imread(io.BytesIO(png))[..., :3]

    def quit(self) -> None:
        """End the browser session."""
        try:
            self.cmd("DELETE", "", timeout=20)
        except WebDriverError:
            pass


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait(predicate, timeout: float, what: str):
    """Poll ``predicate`` until it returns neither None nor False (that value is returned), or
    fail naming ``what``."""
    end = time.monotonic() + timeout
    while True:
        value = predicate()
        if value is not None and value is not False:
            return value
        if time.monotonic() > end:
            pytest.fail(f"timed out after {timeout:.0f} s waiting for {what}")
        time.sleep(0.1)


def _orange(img) -> float:
    """Fraction of the picture in the cones' orange."""
    return float(((img[..., 0] > 0.8) & (img[..., 1] > 0.55) & (img[..., 2] < 0.5)).mean())


class Browser:
    """chromedriver and a headless chromium session, stopped together.

    chromium sometimes hangs at start when headless: each attempt gets ``start_timeout``
    seconds, and after ``attempts`` hangs :meth:`start` returns None with the reason in
    :attr:`reason`.
    """

    def __init__(self, tmp: Path):
        self.tmp = tmp
        self.proc = None
        self.driver = None
        self.reason = ""

    def start(self, attempts: int = 3, start_timeout: float = 60.0) -> WebDriver | None:
        """Start chromedriver and a browser session (retrying hung starts)."""
        for attempt in range(attempts):
            port = _free_port()
            self.proc = subprocess.Popen(
                [CHROMEDRIVER, f"--port={port}", "--allowed-ips=127.0.0.1"],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                start_new_session=True,  # its own process group: stopped with its browser
            )
            try:
                _wait_port(port, 20)
                self.driver = WebDriver(port, self.tmp / f"profile{attempt}", start_timeout)
                return self.driver
            except WebDriverError as exc:
                self.reason = str(exc)
                self._kill()
        self.reason = f"chromium did not start in {attempts} attempts (last: {self.reason})"
        return None

    def _kill(self) -> None:
        if self.proc is None:
            return
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)  # chromedriver and the chromium it started
        except ProcessLookupError:
            pass
        self.proc.wait(timeout=10)
        self.proc = None

    def stop(self) -> None:
        """End the session and stop chromedriver and its browser."""
        if self.driver is not None:
            self.driver.quit()
            self.driver = None
        self._kill()


def _wait_port(port: int, timeout: float) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.05)
    raise WebDriverError(f"chromedriver did not listen on port {port} in {timeout:.0f} s")


@pytest.fixture
def browser(tmp_path):
    """A WebDriver session on headless chromium (skipped when it cannot be had)."""
    if CHROMIUM is None:
        pytest.skip("chromium is not installed (.ci/run installs Debian's chromium)")
    if CHROMEDRIVER is None:
        pytest.skip("chromedriver is not installed (.ci/run installs Debian's chromium-driver)")
    b = Browser(tmp_path)
    driver = b.start()
    if driver is None:
        pytest.skip(b.reason)
    try:
        yield driver
    finally:
        b.stop()


@pytest.fixture
def app():
    """The app on a free port, its first design made (a page draws it when it connects)."""
    pytest.importorskip("viser")
    from filletfold.app import run_app

    app = run_app("icosahedron", host="127.0.0.1", port=_free_port())
    try:
        yield app
    finally:
        app.stop()


@pytest.mark.slow
def test_page_draws_slider_changes_design_and_bad_upload_shows_error(app, browser, tmp_path):
    ARTIFACTS.mkdir(exist_ok=True)
    browser.get(app.url + "/")
    view = app.wait_view(timeout=60)  # the page's own view: its session, panel and scene

    # 1. the canvas draws the design: many colours, not blank, the cones' orange present
    shot = ARTIFACTS / "app-icosahedron.png"

    def drawn():
        img = browser.screenshot(shot)
        return img if _orange(img) > 0.002 else None

    first = _wait(drawn, 60, "the canvas to draw the cones")
    canvas = np.s_[:, :800]  # left of the GUI panel
    colours = np.unique((first[canvas] * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 200
    assert np.any(first[canvas] < 0.95, axis=-1).mean() > 0.05
    assert "icosahedron" in browser.text()

    # 2. move the radius slider in the page (keyboard on its thumb): 10 % -> 15 %
    before = view.session.design_id
    thumb = browser.find_by_label("Radius (% edge)", '[role="slider"]')
    browser.send_keys(thumb, ARROW_RIGHT * 10)  # step 0.5
    _wait(lambda: view.session.params.radius == "15.0%", 20, "the slider's value at the server")
    _wait(
        lambda: (
            view.session.design_id > before
            and view.drawn_id == view.session.latest_id
            and view.session.design.params.radius == "15.0%"
        ),
        60,
        "the design of radius 15 % drawn",
    )
    changed = ARTIFACTS / "app-icosahedron-radius15.png"

    def redrawn():
        img = browser.screenshot(changed)
        return img if np.abs(img[canvas] - first[canvas]).max(axis=-1).mean() > 0.002 else None

    after = _wait(redrawn, 60, "the canvas to show the new radius")
    assert _orange(after) > 0.002
    assert "radius 15.0%" in browser.text()  # the status line names the drawn design's radius
    assert "15" in browser.script(
        "return arguments[0].getAttribute('aria-valuenow');",
        {ELEMENT: thumb},
    )

    # 3. upload a bad file through the page's upload control: the reader's error appears
    design = view.session.design
    bad = tmp_path / "bad.obj"
    bad.write_bytes(BAD_OBJ)
    upload = browser.find_by_label("Upload mesh (OBJ/OFF/PLY/STL, ≤ 50 MB)", 'input[type="file"]')
    browser.send_keys(upload, str(bad))

    def error_shown():
        text = browser.text()
        return text if "bad.obj: line 1" in text else None

    text = _wait(error_shown, 30, "the reader's error in the page")
    assert "error: bad.obj: line 1: vertex needs 3 coordinates" in text
    assert view.session.design is design  # the design stays
    browser.screenshot(ARTIFACTS / "app-bad-upload.png")
