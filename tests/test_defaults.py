"""The one set of default parameters: the API, the command line and the app read it."""

import inspect

import typer.main

from filletfold import defaults
from filletfold.app.session import AppSession
from filletfold.cli import app
from filletfold.parameters import Parameters

NAMES = {"radius": "DEFAULT_RADIUS", "depth": "DEFAULT_DEPTH", "samples": "DEFAULT_SAMPLES",
         "arc_step": "DEFAULT_ARC_STEP"}  # fmt: skip


def test_the_parameters_and_the_app_default_to_the_shared_values():
    params = inspect.signature(AppSession.__init__).parameters
    for name, const in NAMES.items():
        assert getattr(Parameters(), name) == getattr(defaults, const), name
        assert params[name].default == getattr(defaults, const), name


def test_the_round_command_defaults_to_the_shared_values():
    command = typer.main.get_command(app)
    options = {p.name: p for p in command.commands["round"].params}
    for name, const in NAMES.items():
        assert options[name].default == getattr(defaults, const), name


def test_the_defaults_are_valid_parameters():
    assert defaults.DEFAULT_RADIUS.endswith("%") and float(defaults.DEFAULT_RADIUS[:-1]) > 0
    assert defaults.DEFAULT_DEPTH.endswith("%") and float(defaults.DEFAULT_DEPTH[:-1]) > 0
    assert isinstance(defaults.DEFAULT_SAMPLES, int) and defaults.DEFAULT_SAMPLES >= 3
    assert 0 <= defaults.DEFAULT_ARC_STEP < 90
    tol = defaults.DEFAULT_CHORD_TOL
    assert tol.endswith("%") and float(tol[:-1]) > 0


def test_the_chord_tolerance_defaults_alike_in_the_api_and_the_command_line():
    assert Parameters().chord_tol == defaults.DEFAULT_CHORD_TOL
    command = typer.main.get_command(app)
    options = {p.name: p for p in command.commands["round"].params}
    assert options["chord_tol"].default == defaults.DEFAULT_CHORD_TOL
