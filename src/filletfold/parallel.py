"""Threads for the stages that split into independent parts (vertex slices, solver parts).

numpy releases the GIL inside its loops over large arrays and the compiled apex solver
releases it altogether, so independent parts of a stage overlap on a machine with several
cores. Every part computes what it computes alone: results do not depend on the number of
threads.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor

from .errors import ParameterError

__all__ = ["thread_map", "threads"]


def threads() -> int:
    """Threads a stage may use: the CPUs this process may run on, or ``FILLETFOLD_THREADS``
    (1 runs everything in the calling thread)."""
    env = os.environ.get("FILLETFOLD_THREADS", "").strip()
    if env:
        try:
            return max(1, int(env))
        except ValueError:
            raise ParameterError(
                f"FILLETFOLD_THREADS must be a whole number of threads, got {env!r}",
                name="FILLETFOLD_THREADS",
            ) from None
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


@functools.cache
def pool(name: str) -> ThreadPoolExecutor:
    """The threads of one kind of work (``"stage"``: slices of a stage; ``"kernel"``: parts of
    a solver batch, submitted from stage threads: a pool of its own, so they never wait for
    each other)."""
    return ThreadPoolExecutor(max_workers=threads(), thread_name_prefix=f"filletfold-{name}")


def thread_map(fn: Callable, items: Iterable, name: str = "stage") -> Iterator:
    """``map(fn, items)``, the calls running in up to :func:`threads` threads at once; results
    in the order of ``items``, each as soon as it and those before it are done."""
    items = list(items)
    if threads() == 1 or len(items) < 2:
        return map(fn, items)
    return pool(name).map(fn, items)
