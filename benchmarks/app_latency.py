"""Latency of the browser app: from a slider change to the redrawn design (issue 5).

    .venv/bin/python benchmarks/app_latency.py [--changes N] [--max-vertices V]
                                               [--no-browser] [NAME ...]

Server side, for every built-in example with at most ``--max-vertices`` vertices (default
200; the target is under 100 ms): the app is started once (no page connected), the example is
loaded, then the radius slider is set ``--changes`` times, alternating 12 % and 10 %, with the
same call the page's slider makes (``handle.value = x`` runs the slider's ``on_update``), and
each change is timed until the worker has computed the design and updated the scene in the
server (after the app's background load of the numba kernel, which would otherwise land in the
first example's CPU time). Printed: the median wall time, the median CPU time of the whole
process over the same span (all threads: the worker's computation and drawing, viser's event
loop; steadier than the wall time on a shared machine), and the medians of the wall time's two
parts (compute: ``round_mesh``; draw: the scene arrays and the viser scene update).

In the browser (skipped with the reason when chromium or chromedriver is missing): the page is
loaded in headless chromium through chromedriver, the radius slider's thumb gets an arrow key,
and the page times from that keydown to the first animation frame after the status line shows
the new radius (so after the scene update has reached the page). Prints the machine and the
command first.
"""

from __future__ import annotations

import argparse
import logging
import os
import statistics
import sys
import tempfile
import threading
import time
import warnings
from pathlib import Path

sys.path.insert(0, os.path.dirname(__file__))
sys.path.append(str(Path(__file__).resolve().parents[1]))  # for tests.app.test_server
from examples import machine

from filletfold.app import run_app
from filletfold.mesh import example_mesh, example_names

RADII = (12.0, 10.0)
BROWSER_EXAMPLE = "icosahedron"

# In the page: the keydown time, then a promise of the milliseconds from it to the first
# animation frame after the text arguments[0] appears.
ARM_PAGE = """
const want = arguments[0];
window.__ffT0 = null;
document.addEventListener("keydown", () => { window.__ffT0 = performance.now(); },
                          {capture: true, once: true});
window.__ffDone = new Promise((resolve) => {
  const seen = new MutationObserver(() => {
    if (!document.body.textContent.includes(want)) return;
    seen.disconnect();
    requestAnimationFrame(() => resolve(performance.now() - window.__ffT0));
  });
  seen.observe(document.body, {subtree: true, childList: true, characterData: true});
});
"""
AWAIT_PAGE = "const done = arguments[arguments.length - 1]; window.__ffDone.then(done);"


def server_latency(app, name: str, changes: int):
    """Medians (seconds) of ``changes`` radius changes on ``name``: total, CPU, compute, draw."""
    app.request_load(name)
    if not app.wait_idle(300) or app.session.name != name:
        raise RuntimeError(f"{name}: {app.status}")
    app._radius.value = 10.0
    app.wait_idle(300)
    totals, cpus, computes, draws = [], [], [], []
    for i in range(changes):
        value = RADII[i % 2]
        t, c = time.perf_counter(), time.process_time()
        app._radius.value = value  # what the slider's on_update runs
        app.wait_idle(300)
        totals.append(time.perf_counter() - t)
        cpus.append(time.process_time() - c)
        design = app.session.design
        if design.params.radius != f"{value}%" or app.drawn_id != app.session.design_id:
            raise RuntimeError(f"{name}: radius {value}% not drawn: {app.status}")
        computes.append(app.timings["compute"])
        draws.append(app.timings["draw"])
    return tuple(statistics.median(x) for x in (totals, cpus, computes, draws))


def browser_latency(app, changes: int):
    """Median milliseconds in the page from a radius arrow key to the redrawn design, or the
    reason it could not be measured."""
    from tests.app.test_server import (
        ARROW_RIGHT,
        CHROMEDRIVER,
        CHROMIUM,
        Browser,
        WebDriverError,
    )

    if CHROMIUM is None or CHROMEDRIVER is None:
        return "chromium or chromedriver is not installed"
    app.request_load(BROWSER_EXAMPLE)
    app._radius.value = 10.0
    app.wait_idle(300)
    with tempfile.TemporaryDirectory(prefix="filletfold-bench-") as tmp:
        browser = Browser(Path(tmp))
        driver = browser.start()
        if driver is None:
            return browser.reason
        try:
            driver.get(app.url + "/")
            end = time.monotonic() + 60
            while "radius 10.0%" not in driver.text():
                if time.monotonic() > end:
                    return "the page did not show the design in 60 s"
                time.sleep(0.2)
            time.sleep(2.0)  # let the first frames settle
            thumb = driver.find_by_label("Radius (% edge)", '[role="slider"]')
            times = []
            for i in range(changes):
                key, value = (ARROW_RIGHT, 10.5) if i % 2 == 0 else ("\ue012", 10.0)
                driver.script(ARM_PAGE, f"radius {value}%")
                driver.send_keys(thumb, key)
                driver.cmd("POST", "/timeouts", {"script": 60000})
                times.append(
                    driver.cmd("POST", "/execute/async", {"script": AWAIT_PAGE, "args": []})
                )
                app.wait_idle(60)
            return statistics.median(times)
        except WebDriverError as exc:
            return str(exc)
        finally:
            browser.stop()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", help="examples (default: the built-ins)")
    ap.add_argument("--changes", type=int, default=5, help="slider changes per example")
    ap.add_argument("--max-vertices", type=int, default=200)
    ap.add_argument("--no-browser", action="store_true", help="skip the browser measurement")
    args = ap.parse_args(argv)
    logging.disable(logging.CRITICAL)  # failures are rows of the table
    warnings.simplefilter("ignore", RuntimeWarning)  # numerical noise of failing examples
    print(f"# machine: {machine()}")
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"# load average (1, 5, 15 min) at the start: {load}")
    print(f"# command: {' '.join([os.path.basename(sys.executable), *sys.argv])}")
    print(
        f"# radius slider alternating {RADII[0]:g} % / {RADII[1]:g} % of the mean edge, depth "
        f"30 %, samples 24; median of {args.changes} changes; target < 100 ms"
    )
    print(
        f"{'example':22s} {'V':>4s} {'faces':>6s} {'total ms':>9s} {'cpu ms':>7s} "
        f"{'compute':>8s} {'draw':>6s} {'< 100 ms':>8s}"
    )
    app = run_app("tetrahedron", port=0)
    for thread in threading.enumerate():  # the app loads the numba kernel in the background:
        if thread.name == "filletfold-kernel":  # not in the first example's CPU time
            thread.join(120)
    try:
        for name in args.names or example_names():
            n_vertices = len(example_mesh(name)[0])
            if n_vertices > args.max_vertices:
                print(f"{name:22s} {n_vertices:4d}  skipped (over {args.max_vertices} vertices)")
                continue
            try:
                total, cpu, compute, draw = server_latency(app, name, args.changes)
            except RuntimeError as exc:
                print(f"{name:22s} {n_vertices:4d}  failed: {exc}")
                continue
            faces = len(app.session.design.pattern.faces)
            print(
                f"{name:22s} {n_vertices:4d} {faces:6d} {1e3 * total:9.1f} {1e3 * cpu:7.1f} "
                f"{1e3 * compute:8.1f} {1e3 * draw:6.1f} {'yes' if total < 0.1 else 'no':>8s}"
            )
        if not args.no_browser:
            result = browser_latency(app, args.changes)
            if isinstance(result, str):
                print(f"# browser: not measured: {result}")
            else:
                print(
                    f"# browser (headless chromium, software WebGL), {BROWSER_EXAMPLE}: arrow key "
                    f"on the radius slider to the redrawn page, median of {args.changes}: "
                    f"{result:.0f} ms"
                )
    finally:
        app.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
