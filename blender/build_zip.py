"""Build the Blender extension's installable zip: ``make blender-zip``.

Writes ``<out>/filletfold_blender-<version>.zip`` with ``blender_manifest.toml`` at its root and
the extension's Python files beside it, as ``blender --command extension build`` lays it out
(install it in Blender 4.2+: Edit > Preferences > Get Extensions > Install from Disk). Every
entry is dated 2000-01-01, so the same files give the same bytes.
"""

from __future__ import annotations

import argparse
import re
import sys
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "filletfold_blender"


def version() -> str:
    text = (SOURCE / "blender_manifest.toml").read_text(encoding="utf-8")
    return re.search(r'^version\s*=\s*"([^"]+)"', text, re.M).group(1)


def build(out: Path) -> Path:
    """The zip of the extension in ``out``; returns its path."""
    out.mkdir(parents=True, exist_ok=True)
    target = out / f"filletfold_blender-{version()}.zip"
    files = sorted(p for p in SOURCE.rglob("*") if p.is_file() and "__pycache__" not in p.parts)
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as zf:
        for path in files:
            info = zipfile.ZipInfo(path.relative_to(SOURCE).as_posix(), (2000, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            zf.writestr(info, path.read_bytes())
    return target


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out", help="folder of the zip (default: out)")
    args = parser.parse_args(argv)
    print(build(Path(args.out)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
