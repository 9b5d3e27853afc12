"""Exporters: one module per format, each a function from a crease pattern to text.

Writing goes through :func:`~filletfold.export.folder.write_design_folder` (a design's
folder, replaced whole), :func:`write_outputs` (files added, all or none) or
:func:`write_file_atomic`.
"""

from __future__ import annotations

from ..surface.validate import validate_pattern
from .atomic import write_file_atomic, write_outputs
from .cutfiles import cut_files, parse_formats
from .dxf import pattern_dxf
from .fold import fold_document, fold_json, fold_json_chunks
from .fold_read import read_fold
from .obj import folded_obj
from .pdf import pattern_pdf
from .png import pattern_png, preview_png
from .report import report_json
from .svg import pattern_svg

__all__ = [
    "cut_files",
    "fold_document",
    "fold_json",
    "fold_json_chunks",
    "folded_obj",
    "parse_formats",
    "pattern_dxf",
    "pattern_pdf",
    "pattern_png",
    "pattern_svg",
    "preview_png",
    "read_fold",
    "report_json",
    "validate_pattern",
    "write_file_atomic",
    "write_outputs",
]
