"""The fixer protocol of docs/architecture.md: each ``fix/*_plan.py`` exports one ``Fixer``, each
``fix-*`` command gets the shared options from ``@fixer_command`` (the same options, the same order)."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

from ar3cli.cli import COMMANDS

PLANS = sorted(path.stem for path in (Path(__file__).resolve().parents[1] / "ar3cli" / "fix").glob("*_plan.py"))
SHARED = ["--diff", "--check", "--output", "--follow-symlinks", "--package-path", "--format"]


@pytest.mark.parametrize("plan", PLANS)
def test_every_plan_module_exports_one_fixer_of_a_command(plan):
    from ar3cli.fix.driver import Fixer

    fixer = importlib.import_module(f"ar3cli.fix.{plan}").FIXER
    assert isinstance(fixer, Fixer) and fixer.name in COMMANDS
    assert COMMANDS[fixer.name].startswith("ar3cli.commands.fix_")


def test_every_fixer_command_has_the_shared_options_in_order():
    import typer

    from ar3cli.cli import application

    group = typer.main.get_command(application([]))
    fixers = [name for name in COMMANDS if name.startswith("fix-")]
    assert len(fixers) == len(PLANS)
    for name in fixers:
        params = group.commands[name].params
        assert params[0].name == "paths", name
        options = [param.opts[0] for param in params[1:]]
        if options[-1] == "--timeout":  # the fixers that start a child process
            options.pop()
        assert options[-len(SHARED):] == SHARED and "--timeout" not in options, name
