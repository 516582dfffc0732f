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


def test_help_texts_survive_markdown_rendering():
    """Help is rendered as Markdown: a bare <tag> vanishes as HTML, so tags must be in backticks."""
    import re

    import typer.main

    from ar3cli.cli import app

    bare_tag = re.compile(r"(?<!`)<[a-zA-Z_]+>(?!`)")
    for name, command in typer.main.get_command(app).commands.items():
        texts = [command.help or ""] + [getattr(param, "help", None) or "" for param in command.params]
        for text in texts:
            assert not bare_tag.search(text), f"ar3cli {name}: help text {text!r} has a bare <tag>"
