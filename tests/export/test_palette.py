"""One palette (:mod:`filletfold.export.palette`) for the PDF and PNG drawings; the SVG follows
its cutter preset."""

from __future__ import annotations

import re
import zlib

from filletfold.export import pattern_dxf, pattern_pdf, pattern_svg
from filletfold.export.palette import ASSIGNMENT_COLOR, TAB_HINGE_COLOR
from filletfold.export.presets import get_preset

SVG_NS = "{http://www.w3.org/2000/svg}"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- one palette


def pdf_stroke_colors(data: bytes) -> set[str]:
    """Stroke colours (``#rrggbb``) set in the content streams of a PDF."""
    colors = set()
    for raw in re.findall(rb"stream\r?\n(.*?)\r?\nendstream", data, flags=re.S):
        try:
            text = zlib.decompress(raw).decode("latin-1")
        except zlib.error:
            continue
        for rgb in re.findall(r"(?:([\d.]+) ([\d.]+) )?([\d.]+) (?:RG|G)\b", text):
            rgb = rgb if rgb[0] else (rgb[2],) * 3  # "x G" is grey x
            colors.add("#" + "".join(f"{round(float(c) * 255):02x}" for c in rgb))
    return colors


def test_pdf_draws_with_the_palette_and_svg_with_its_preset(cube):
    svg = pattern_svg(cube.pattern)
    pdf = pattern_pdf(cube.pattern, scale=20.0)
    present = set(cube.pattern.edge_assignment) - {"F"}
    assert {"M", "B"} <= present
    used = {ASSIGNMENT_COLOR[a] for a in present} | {TAB_HINGE_COLOR}
    assert used <= pdf_stroke_colors(pdf)
    preset = get_preset()  # the SVG's default: Origami Simulator's colours
    role = {"M": "mountain", "V": "valley", "B": "cut"}
    for a in present:
        assert f'stroke="{getattr(preset, role[a]).color}"' in svg, a
    assert f'stroke="{preset.tab.color}"' in svg
    assert f'fill="{preset.label.color}"' in svg


def test_pictures_and_rhino_draw_the_default_presets_colours():
    """PDF, PNG and 3dm use the palette; the SVG and DXF the default preset: one colour per
    role in all of them (a tab hinge green in one and magenta in another misleads)."""
    preset = get_preset()
    assert TAB_HINGE_COLOR == preset.tab.color
    for a, role in (("M", "mountain"), ("V", "valley"), ("B", "cut")):
        assert ASSIGNMENT_COLOR[a] == getattr(preset, role).color


def test_dxf_classes_are_sorted(cube):
    """ezdxf takes the classes from a set (ordered by the hash seed); the DXF sorts them."""
    text = pattern_dxf(cube.pattern, units="mm")
    section = text.split("\nCLASSES\n", 1)[1].split("\nENDSEC\n", 1)[0]
    names = re.findall(r"\n  0\nCLASS\n  1\n(\S+)\n  2\n(\S+)", "\n" + section)
    assert len(names) > 10
    assert names == sorted(names)
    assert {"LAYOUT", "ACDBPLACEHOLDER"} <= {n for n, _ in names}
