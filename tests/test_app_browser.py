"""The app in a real headless browser (Debian's chromium; skipped when it is not installed).

The screenshot is kept as a test artefact in ``tests/artifacts/`` (git-ignored).
"""

from __future__ import annotations

import io
import shutil
import socket
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
ARTIFACTS = Path(__file__).parent / "artifacts"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _screenshot(url: str, out: Path, tmp: Path) -> bool:
    """Take a screenshot; False when chromium hangs (it sometimes does headless, at start)."""
    out.unlink(missing_ok=True)
    args = [
        CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--no-first-run", f"--user-data-dir={tmp / 'profile'}", "--window-size=1200,800",
        "--virtual-time-budget=15000", f"--screenshot={out}", url,
    ]  # fmt: skip
    try:
        subprocess.run(args, check=True, capture_output=True, timeout=60)
    except subprocess.TimeoutExpired:
        return False
    return out.exists()


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (.ci/run installs it)")
def test_page_draws_the_design(tmp_path):
    pytest.importorskip("viser")
    from matplotlib.image import imread

    from filletfold.app import run_app

    app = run_app("icosahedron", host="127.0.0.1", port=_free_port())
    try:
        # the first design is computed in the app's worker: wait for it before looking
        end = time.monotonic() + 60
        while app.session.design_id == 0 or "computing" in app.status:
            assert time.monotonic() < end, "the app did not finish its first design"
            time.sleep(0.1)
        ARTIFACTS.mkdir(exist_ok=True)
        shot = ARTIFACTS / "app-icosahedron.png"
        taken = False
        for attempt in range(3):  # a loaded machine can take the shot before the first frame
            if not _screenshot(app.url + "/", shot, tmp_path / str(attempt)):
                continue
            taken = True
            img = imread(io.BytesIO(shot.read_bytes()))[..., :3]
            orange = (img[..., 0] > 0.8) & (img[..., 1] > 0.55) & (img[..., 2] < 0.5)
            if orange.mean() > 0.002:
                break
        if not taken:
            pytest.skip("chromium hung three times without writing a screenshot")
        # the canvas draws the model: many colours, and the patch colours are present
        colours = np.unique((img * 255).astype(np.uint8).reshape(-1, 3), axis=0)
        assert len(colours) > 200
        not_white = np.any(img < 0.95, axis=-1).mean()
        assert not_white > 0.1
        assert orange.mean() > 0.002  # the cones
    finally:
        app.stop()
