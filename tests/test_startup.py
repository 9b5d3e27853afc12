"""Start-up (issues 14, 27): ``import filletfold`` and ``filletfold --help`` load no heavy
library, and the default command on a small example loads only the libraries it uses.

Invariants, not timings (``benchmarks/startup.py`` times them): each check runs in a fresh
interpreter and lists which heavy libraries ended up in ``sys.modules``. The public API stays
whole: every name of ``filletfold.__all__`` is loaded on first use.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import filletfold

#: Imported where they are used, never by ``import filletfold`` or the command line's start.
HEAVY = (
    "scipy",
    "shapely",
    "trimesh",
    "meshio",
    "numba",
    "matplotlib",
    "ezdxf",
    "viser",
    "rhino3dm",
    "compas",
)

_REPORT = (
    "import json, sys\n"
    f"print(json.dumps(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r}))))"
)


def loaded_after(code: str) -> list[str]:
    """The heavy libraries in ``sys.modules`` after running ``code`` in a fresh interpreter."""
    out = subprocess.run(
        [sys.executable, "-c", f"{code}\n{_REPORT}"],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_import_filletfold_loads_no_heavy_library():
    assert loaded_after("import filletfold") == []


def test_import_filletfold_loads_no_numpy():
    """Not even numpy: the pipeline is imported on the first use of the API."""
    code = "import filletfold, sys; assert 'numpy' not in sys.modules, 'numpy'"
    assert loaded_after(code) == []


def test_building_the_command_line_loads_no_heavy_library():
    assert loaded_after("import filletfold.cli; filletfold.cli.app") == []


@pytest.mark.parametrize("command", [[], ["round"], ["export"], ["check"], ["app"], ["examples"]])
def test_help_loads_no_heavy_library(command):
    code = (
        "import contextlib, io\nfrom filletfold.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()) as out:\n"
        f"    code = main([*{command!r}, '--help'])\n"
        "assert code == 0 and 'Usage: filletfold' in out.getvalue(), (code, out.getvalue())"
    )
    assert loaded_after(code) == []


def test_version_loads_no_heavy_library():
    code = (
        "import contextlib, io\nfrom filletfold.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()) as out:\n"
        "    assert main(['--version']) == 0\n"
        "assert out.getvalue().strip() == 'filletfold ' + __import__('filletfold').__version__"
    )
    assert loaded_after(code) == []


def test_the_pipeline_loads_no_optional_or_export_library():
    """Rounding needs scipy and shapely; scipy.optimize (material loss, SLSQP, some
    tessellations), the cut files, the mesh reader and the solver's kernel load theirs when
    used."""
    code = (
        "import sys, filletfold; filletfold.round_mesh; import filletfold.export.outputs\n"
        "assert 'scipy.optimize' not in sys.modules, 'scipy.optimize: import it where used'"
    )
    assert set(loaded_after(code)) <= {"scipy", "shapely"}


#: Loaded only by the paths that need them: none by the default command on a small example.
ON_DEMAND = ("numba", "llvmlite", "scipy.optimize", "matplotlib", "ezdxf", "trimesh", "PIL")


def test_the_default_command_on_an_example_loads_no_solver_kernel(tmp_path):
    """Issue 27: ``filletfold round icosahedron`` (default formats and tabs; the cube too, in
    the same process) imports no numba: their vertices are all at their targets, no solver
    batch runs, and the kernel (0.4-0.6 s to import and load) is loaded by the first batch it
    solves, not before. Nor do they load the libraries of other paths (material loss, the
    other cut files, the mesh reader)."""
    runs = [["round", name, "-q", "-o", str(tmp_path / name)] for name in ("icosahedron", "cube")]
    code = (
        "import contextlib, io, sys\nfrom filletfold.cli import main\n"
        f"for argv in {runs!r}:\n"
        "    with contextlib.redirect_stdout(io.StringIO()):\n"
        "        assert main(argv) == 0, argv\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in "
        f"{ON_DEMAND!r} or m in {ON_DEMAND!r}))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    assert (tmp_path / "icosahedron" / "design.fold").is_file()
    assert (tmp_path / "cube" / "design.fold").is_file()
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_every_public_name_is_loaded_on_first_use():
    code = (
        "import filletfold\n"
        "for name in filletfold.__all__:\n"
        "    assert getattr(filletfold, name) is not None, name\n"
        "from filletfold import round_mesh, Design, CreasePattern, PolyMesh, load_mesh\n"
        "from filletfold import *\n"
        "import filletfold.design as d\n"
        "assert round_mesh is d.round_mesh and Design is d.Design"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_the_lazy_names_are_the_modules_objects():
    from filletfold.design import Design, round_mesh
    from filletfold.mesh import PolyMesh, example_names, load_mesh
    from filletfold.parameters import Parameters
    from filletfold.surface.pattern import CreasePattern

    assert filletfold.round_mesh is round_mesh
    assert filletfold.Design is Design and filletfold.Parameters is Parameters
    assert filletfold.PolyMesh is PolyMesh and filletfold.load_mesh is load_mesh
    assert filletfold.example_names is example_names
    assert filletfold.CreasePattern is CreasePattern
    assert set(filletfold.__all__) <= set(dir(filletfold))


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        filletfold.no_such_name  # noqa: B018
    assert not hasattr(filletfold, "_no_such_name")


def test_a_subpackage_is_an_attribute_once_used():
    """``filletfold.mesh`` after ``import filletfold`` works as when __init__ imported it."""
    code = "import filletfold\nassert 'cube' in filletfold.mesh.example_names()"
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_the_defaults_are_the_pipelines():
    """The command line shows the defaults without loading the pipeline: the same values."""
    from filletfold import defaults

    params = filletfold.Parameters()
    assert params.radius == defaults.DEFAULT_RADIUS
    assert params.depth == defaults.DEFAULT_DEPTH
    assert params.samples == defaults.DEFAULT_SAMPLES
    assert params.arc_step == defaults.DEFAULT_ARC_STEP
