"""Exporters: one module per format, each a function from a crease pattern to text.

Writing goes through :func:`write_outputs` (all files or none) or :func:`write_file_atomic`.
"""

from __future__ import annotations

from .atomic import write_file_atomic, write_outputs
from .fold import fold_document, fold_json, validate_pattern
from .obj import folded_obj
from .report import report_json
from .svg import pattern_svg

__all__ = [
    "fold_document",
    "fold_json",
    "folded_obj",
    "pattern_svg",
    "report_json",
    "validate_pattern",
    "write_file_atomic",
    "write_outputs",
]
