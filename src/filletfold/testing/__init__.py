"""Test support for filletfold and for code built on it (in the spirit of ``numpy.testing``).

:mod:`filletfold.testing.fuzz` makes reproducible robustness cases (meshes as users bring
them, and files that are not meshes at all) and runs them through
:func:`filletfold.round_mesh`.
"""

from __future__ import annotations

from .fuzz import (
    ARRAY_KINDS,
    FILE_KINDS,
    GARBAGE_KINDS,
    KINDS,
    OUTCOMES,
    FuzzCase,
    Outcome,
    case_by_name,
    fuzz_case,
    fuzz_cases,
    run_case,
)

__all__ = [
    "ARRAY_KINDS",
    "FILE_KINDS",
    "GARBAGE_KINDS",
    "KINDS",
    "OUTCOMES",
    "FuzzCase",
    "Outcome",
    "case_by_name",
    "fuzz_case",
    "fuzz_cases",
    "run_case",
]
