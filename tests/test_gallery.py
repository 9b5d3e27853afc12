"""docs/gallery.md: every picture exists, is small, and has the one command that made it."""

from __future__ import annotations

import importlib.util
import re
import shlex
import sys
from pathlib import Path

from PIL import Image

ROOT = Path(__file__).resolve().parents[1]
GALLERY = ROOT / "docs" / "gallery.md"
PICTURE = re.compile(r"!\[[^\]]*\]\((gallery/[\w.-]+\.png)\)\n\n[^\n]*\n\n```\n([^\n]+)\n```")


def gallery_script():
    spec = importlib.util.spec_from_file_location(
        "gallery_script", ROOT / "benchmarks" / "gallery.py"
    )
    module = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
    return module


def test_gallery_page_is_the_scripts():
    """The page is what benchmarks/gallery.py writes: its commands are the ones run."""
    assert GALLERY.read_text(encoding="utf-8") == gallery_script().gallery_markdown()


def test_every_picture_exists_small_with_its_command():
    text = GALLERY.read_text(encoding="utf-8")
    found = PICTURE.findall(text)
    assert len(found) == text.count("![")
    figures = re.findall(r"^## Fig\. (\d+)", text, flags=re.M)
    assert figures == ["14", "17", "18", "19", "20"]
    for path, command in found:
        picture = GALLERY.parent / path
        assert picture.stat().st_size <= 300 * 1024, path
        with Image.open(picture) as img:
            assert img.format == "PNG" and img.size == (1000, 750), path
        words = shlex.split(command)
        assert words[:2] == ["filletfold", "round"], command
        assert "png" in words[words.index("--format") + 1].split(","), command
        assert words[-2:] == ["-o", f"out/gallery/{Path(path).stem}"], command
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "(docs/gallery.md)" in readme
    shown = re.findall(r'src="(docs/gallery/[\w.-]+\.png)"', readme)
    assert shown
    for path in shown:
        assert (ROOT / path).is_file(), path
