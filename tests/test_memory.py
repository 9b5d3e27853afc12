"""Memory a stage frees goes back to the system (filletfold.memory, glibc only)."""

from __future__ import annotations

import re
import sys
import threading

import pytest

from filletfold.errors import stage
from filletfold.memory import _malloc_trim, release_memory

needs_glibc = pytest.mark.skipif(
    not sys.platform.startswith("linux") or _malloc_trim() is None, reason="needs glibc"
)


def _resident_mb() -> float:
    with open("/proc/self/status") as fh:
        return int(re.search(r"VmRSS:\s+(\d+)", fh.read()).group(1)) / 1024


def _churn_in_a_thread() -> None:
    """Many small blocks allocated and freed in another thread: glibc keeps them in that
    thread's arena (as the apex stage's threads leave theirs)."""

    def work():
        blocks = [bytearray(900) for _ in range(250_000)]  # ~240 MB in small chunks
        keep = blocks[-1]  # the arena's top stays in use: free() alone cannot shrink it
        del blocks
        work.keep = keep

    t = threading.Thread(target=work)
    t.start()
    t.join()


@needs_glibc
def test_release_gives_freed_arena_memory_back():
    _churn_in_a_thread()
    before = _resident_mb()
    assert release_memory()
    after = _resident_mb()
    assert before - after > 100, (before, after)


@needs_glibc
def test_a_new_stage_releases_the_memory_the_last_one_freed():
    _churn_in_a_thread()
    before = _resident_mb()
    stage("a test stage")
    assert before - _resident_mb() > 100


@needs_glibc
def test_the_arenas_can_be_capped():
    from filletfold.memory import limit_arenas

    assert limit_arenas(2)
