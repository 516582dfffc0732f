"""The fixer protocol of docs/architecture.md: a fixer is one module, ``fix/NAME_plan.py``, exporting
one ``Fixer``; ``cli.COMMANDS`` finds it by its file name and ``commands.fixer_options.fixer_command``
builds its command, with the fixer's own options and the shared ones (the same options, the same order)."""

from __future__ import annotations

import dataclasses
import importlib
from pathlib import Path

import pytest

from ar3cli.cli import COMMANDS

PLANS = sorted(path.stem for path in (Path(__file__).resolve().parents[1] / "ar3cli" / "fix").glob("*_plan.py"))
SHARED = ["--diff", "--check", "--output", "--follow-symlinks", "--package-path", "--xacro-arg", "--xacro",
          "--xacro-env", "--format"]


@pytest.mark.parametrize("plan", PLANS)
def test_every_plan_module_exports_the_fixer_of_its_command(plan):
    from ar3cli.fix.driver import Fixer

    fixer = importlib.import_module(f"ar3cli.fix.{plan}").FIXER
    assert isinstance(fixer, Fixer) and dataclasses.is_dataclass(fixer.options) and fixer.help
    assert fixer.name == "fix-" + plan.removesuffix("_plan").replace("_", "-")
    assert COMMANDS[fixer.name] == f"ar3cli.fix.{plan}:FIXER"


def test_every_fixer_command_has_its_own_options_then_the_shared_ones_in_order():
    import typer

    from ar3cli.cli import application
    from ar3cli.fix.settings import settings_of

    group = typer.main.get_command(application([]))
    fixers = [name for name in COMMANDS if name.startswith("fix-")]
    assert len(fixers) == len(PLANS)
    for name in fixers:
        module, _, _ = COMMANDS[name].partition(":")
        fixer = importlib.import_module(module).FIXER
        params = group.commands[name].params
        assert params[0].name == "paths", name
        options = [param.opts[0] for param in params[1:]]
        if fixer.timeout is not None:
            assert options.pop() == "--timeout" and params[-1].default == fixer.timeout, name
        assert options[-len(SHARED):] == SHARED and "--timeout" not in options, name
        own = [item.name for item in settings_of(fixer.options)]
        assert [param.name for param in params[1:1 + len(own)]] == own, name


def test_a_new_plan_module_is_a_new_command(tmp_path, monkeypatch):
    """One file makes a fixer: a ``fix/NAME_plan.py`` exporting ``FIXER`` is listed, parsed and run."""
    from dataclasses import dataclass

    from typer.testing import CliRunner

    import ar3cli.cli as cli
    from ar3cli.fix.driver import Fixer, FixPlan
    from ar3cli.fix.settings import setting

    @dataclass
    class ShoutOptions:
        level: int = setting("--level", default=1, minimum=1, maximum=3, help="How loud.")
        ratio: float = setting("--ratio", default=0.5, help="A share.")

    seen = []

    def plan(model, document, options):
        seen.append((model.name, options.level, options.ratio))
        return FixPlan()

    module = type(cli)("ar3cli.fix.shout_plan")
    module.FIXER = Fixer("fix-shout", plan, options=ShoutOptions, help="Shout at the robot.\n\nNothing is changed.")
    monkeypatch.setitem(importlib.sys.modules, "ar3cli.fix.shout_plan", module)
    monkeypatch.setitem(cli.COMMANDS, "fix-shout", "ar3cli.fix.shout_plan:FIXER")
    monkeypatch.setattr(cli.app, "registered_commands", list(cli.app.registered_commands))  # unregistered after
    robot = tmp_path / "one.urdf"
    robot.write_text('<robot name="one"><link name="base"/></robot>')
    runner = CliRunner()
    result = runner.invoke(cli.application(["fix-shout"]), ["fix-shout", str(robot), "--level", "3", "--ratio", "0.25"])
    assert result.exit_code == 0, result.output
    assert seen == [("one", 3, 0.25)]
    for bad in (["--level", "4"], ["--ratio", "nan"]):
        assert runner.invoke(cli.application(["fix-shout"]), ["fix-shout", str(robot), *bad]).exit_code == 2
    assert "Shout at the robot." in runner.invoke(cli.application(["fix-shout"]), ["fix-shout", "--help"]).output


def test_fix_inertia_leaves_alone_what_the_implausible_rule_flags():
    """``IMPLAUSIBLE_CODES`` is written out (the lint rules are imported when a plan runs, not for
    ``--help``); it must stay the code of the rule it names."""
    from ar3cli.fix.inertia_plan import IMPLAUSIBLE_CODES
    from ar3cli.lint.rules.inertia import inertia_implausible

    assert {inertia_implausible.code} == IMPLAUSIBLE_CODES


@pytest.mark.parametrize("spelling", ["optional", "union"])
def test_an_optional_float_setting_is_finite_however_it_is_spelt(spelling):
    """``Optional[float]`` (how the old command modules wrote it) is ``float | None``: finite too."""
    from dataclasses import make_dataclass
    from typing import Optional

    from ar3cli.commands.fixer_options import _own_option
    from ar3cli.commands.options import FiniteFloat
    from ar3cli.fix.settings import setting, settings_of

    annotation = Optional[float] if spelling == "optional" else float | None  # noqa: UP007 - the point of the test
    options = make_dataclass("Options", [("effort", annotation, setting("--effort", default=None, help="N*m."))])
    (item,) = settings_of(options)
    info = _own_option(item).annotation.__metadata__[0]
    assert isinstance(info.click_type, FiniteFloat)
