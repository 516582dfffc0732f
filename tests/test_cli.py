"""The CLI shell: help, version, exit codes, one-line errors."""

from __future__ import annotations


def test_help_lists_commands(cli):
    result = cli("--help")
    assert result.code == 0
    assert "install-check" in result.stdout


def test_version(cli):
    result = cli("--version")
    assert result.code == 0 and result.stdout.startswith("ar3cli ")


def test_unknown_command_is_usage_error(cli):
    result = cli("no-such-command")
    assert result.code == 2
    assert "Traceback" not in result.stderr
