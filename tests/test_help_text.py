"""Every help text reaches the user as written: nothing in square brackets is taken for
markup and dropped (``pip install 'filletfold[app]'`` once lost its ``[app]``)."""

from __future__ import annotations

import re

import typer.main
from typer.testing import CliRunner

from filletfold.cli import app


def _words(text: str) -> str:
    return " ".join(text.split())


def _commands():
    group = typer.main.get_command(app)
    yield [], group
    for name, command in group.commands.items():
        yield [name], command


def test_every_bracketed_help_text_is_printed():
    runner = CliRunner()
    seen = 0
    for path, command in _commands():
        out = runner.invoke(app, [*path, "--help"], env={"COLUMNS": "120"}).output
        texts = [command.help or ""] + [getattr(p, "help", None) or "" for p in command.params]
        for text in texts:
            for bracketed in re.findall(r"\[[^\]\s][^\]]*\]", text.split("\n\n")[0]):
                seen += 1
                assert _words(bracketed) in _words(out), (path, bracketed)
    assert seen >= 2  # the app's extra and the output folder's default at least
