"""The CLI shell: help, version, exit codes, one-line errors."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


def test_help_lists_commands(cli):
    result = cli("--help")
    assert result.code == 0
    assert "install-check" in result.stdout


def test_version(cli):
    result = cli("--version")
    assert result.code == 0 and result.stdout.startswith("ar3cli ")


def test_usage_errors_are_one_line_with_exit_2(cli):
    for args in (["no-such-command"], ["lint-urdf"], ["lint-urdf", "x.urdf", "--format", "xml"],
                 ["sample-collisions", "x.urdf", "--samples", "0"], ["lint-urdf", "--bogus", "x.urdf"]):
        result = cli(*args)
        assert result.code == 2, args
        assert result.stdout == ""
        (line,) = result.stderr.strip().splitlines()
        assert line.startswith("ar3cli: error: ") and "--help" in line and "Value error" not in line


def test_an_option_without_its_value_names_the_commands_own_help(cli):
    """click raises this one before the command's context exists: it pointed at 'ar3cli --help'."""
    result = cli("render", "robot.urdf", "--output")
    assert result.code == 2
    assert result.stderr.strip() == "ar3cli: error: Option '--output' requires an argument. (see 'ar3cli render --help')"


def test_no_arguments_shows_help(cli):
    result = cli()
    assert result.code == 2 and "Usage:" in result.stdout and "lint-urdf" in result.stdout


def test_help_texts_survive_markdown_rendering():
    """Help is rendered as Markdown: a bare <tag> vanishes as HTML, so tags must be in backticks."""
    import re

    import typer.main

    from ar3cli.cli import application

    app = application([])
    bare_tag = re.compile(r"(?<!`)<[a-zA-Z_]+>(?!`)")
    for name, command in typer.main.get_command(app).commands.items():
        texts = [command.help or ""] + [getattr(param, "help", None) or "" for param in command.params]
        for text in texts:
            assert not bare_tag.search(text), f"ar3cli {name}: help text {text!r} has a bare <tag>"


def shell(command: str) -> subprocess.CompletedProcess[bytes]:
    """Run ``python -m ar3cli COMMAND`` through the shell (for redirections such as ``>&-``)."""
    from tests.conftest import REPO

    return subprocess.run(f"{sys.executable} -m ar3cli {command}", shell=True, capture_output=True, cwd=REPO,
                          env={**os.environ, "PYTHONPATH": str(REPO), "NO_COLOR": "1"}, timeout=300)


def test_an_unexpected_os_error_is_one_line_internal_error(monkeypatch, capsys):
    """Only a failure to write the output is a user error; any other OSError escaping a command is
    a bug in ar3cli, reported in one line with exit 3 (never a traceback)."""
    import pytest

    from ar3cli import cli

    def broken(**_kwargs):
        raise PermissionError(13, "Permission denied", "/somewhere")

    monkeypatch.setattr(cli, "application", lambda argv=None: broken)
    monkeypatch.delenv("AR3CLI_DEBUG", raising=False)
    with pytest.raises(SystemExit) as exit_:
        cli.main(["lint-urdf", "x.urdf"])
    (line,) = capsys.readouterr().err.splitlines()
    assert exit_.value.code == 3 and line.startswith("ar3cli: internal error: PermissionError")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="uses /dev/full and shell redirections")
def test_closed_or_full_standard_streams():
    """stderr closed with --sim (pybullet's C output is captured by duplicating descriptors 1 and
    2), stdout closed, stdout on a full disk: clean JSON, an exit code, one line, no traceback."""
    import json

    no_stderr = shell("lint-urdf --sim --format json assets/ar3/ar3.urdf 2>&-")
    assert no_stderr.returncode == 0 and json.loads(no_stderr.stdout)["summary"]["files"] == 1
    no_stdout = shell("lint-urdf --format json assets/examples/ar3_no_inertia.urdf >&-")
    assert no_stdout.returncode == 1 and no_stdout.stderr == b""
    full = shell("lint-urdf --format json assets/ar3/ar3.urdf > /dev/full")
    assert full.returncode == 2
    assert full.stderr.decode().splitlines() == ["ar3cli: error: cannot write the output: No space left on device"]
