"""FOLD interoperability: Rabbit Ear (JavaScript) loads and validates our design.fold.

Runs ``tests/interop/rabbit_ear_load.mjs`` with node. Skipped when node is missing or the
``rabbit-ear`` module is not installed in ``tests/interop/node_modules`` (``.ci/run`` installs
the version pinned in ``tests/interop/package.json``).
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import filletfold
from filletfold.export import fold_document, fold_json
from filletfold.surface.pattern import Annotations, CreasePattern, Label

INTEROP = Path(__file__).parent / "interop"
SCRIPT = INTEROP / "rabbit_ear_load.mjs"
NODE = shutil.which("node")

pytestmark = [
    pytest.mark.skipif(NODE is None, reason="node is not installed"),
    pytest.mark.skipif(
        not (INTEROP / "node_modules" / "rabbit-ear" / "package.json").is_file(),
        reason="rabbit-ear is not installed: run "
        "'cd tests/interop && npm install --no-audit --no-fund' (as .ci/run does)",
    ),
]


def load_with_rabbit_ear(path: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [NODE, str(SCRIPT), str(path)],
        cwd=INTEROP,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


def two_squares() -> CreasePattern:
    """Two squares folded along their diagonals (valley and mountain), with annotations."""
    v2 = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [3, 0], [3, 1], [2, 1]], dtype=float)
    v3 = np.c_[v2, np.zeros(8)]
    v3[3] = [0.5, 0.5, np.sqrt(0.5)]
    v3[7] = [2.5, 0.5, -np.sqrt(0.5)]
    faces = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]
    ann = Annotations(labels=[Label(np.array([0.5, 0.3]), "P1")], sheets=np.array([[0, 0, 3, 1]]))
    return CreasePattern(
        v2, v3, faces, ["cone 0", "face 0", "cone 1", "face 1"], [0, 0, 1, 1], [0, 1],
        annotations=ann,
    )  # fmt: skip


@pytest.mark.parametrize("name", ["icosahedron", "two_squares"])
def test_rabbit_ear_loads_our_fold(name, tmp_path):
    pattern = filletfold.round_mesh(name).pattern if name == "icosahedron" else two_squares()
    path = tmp_path / "design.fold"
    path.write_text(fold_json(fold_document(pattern)))
    run = load_with_rabbit_ear(path)
    assert run.returncode == 0, run.stderr
    summary = json.loads(run.stdout)
    counts = {
        "vertices": len(pattern.vertices_2d),
        "edges": len(pattern.edges),
        "faces": len(pattern.faces),
    }
    assert {k: summary["key"][k] for k in counts} == counts
    assert len(summary["frames"]) == 1  # the folded form, read as a 3D graph
    assert {k: summary["frames"][0][k] for k in counts} == counts
    assert summary["key"]["assignments"] == sorted(set(pattern.edge_assignment.tolist()))


def test_rabbit_ear_script_fails_on_a_non_fold_file(tmp_path):
    path = tmp_path / "bad.fold"
    path.write_text('{"file_spec": 1.2}')
    run = load_with_rabbit_ear(path)
    assert run.returncode != 0
    assert "no vertices_coords" in run.stderr
