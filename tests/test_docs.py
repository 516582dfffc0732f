"""The docs cannot drift: every ``ar3cli COMMAND --option`` they mention exists in the real CLI."""

from __future__ import annotations

import re
import shlex

import pytest
import typer.main

from ar3cli.cli import application
from tests.conftest import REPO

DOC_FILES = sorted([REPO / "README.md", *(REPO / "docs").rglob("*.md")])
CODE = re.compile(r"```[^\n]*\n(.*?)```|`([^`\n]+)`", re.DOTALL)
INVOCATION = re.compile(r"(?<![\w/.-])ar3cli ([a-z][a-z-]+)(?![\w:-])([^\n`|]*)")
"""``ar3cli COMMAND ...``; not ``ar3cli sample-collisions:`` (the marker comment a merged SRDF carries)."""


def _commands() -> dict:
    """Command name -> click-style command object (typer may vendor click; only duck typing is used)."""
    return dict(typer.main.get_command(application([])).commands)


def _options(command) -> set[str]:
    names = {"--help", "-h"}
    for parameter in command.params:
        names.update(getattr(parameter, "opts", []))
        names.update(getattr(parameter, "secondary_opts", []))
    return names


def _mentions():
    for path in DOC_FILES:
        text = path.read_text(encoding="utf-8")
        for code in CODE.finditer(text):
            start = code.start(1) if code.group(1) is not None else code.start(2)
            snippet = (code.group(1) if code.group(1) is not None else code.group(2)).replace("\\\n", " ")
            for match in INVOCATION.finditer(snippet):
                line = text.count("\n", 0, start + match.start()) + 1
                yield path.relative_to(REPO).as_posix(), line, match.group(1), match.group(2)


def test_docs_exist():
    assert (REPO / "docs" / "pybullet-facts.md").is_file()
    assert len(DOC_FILES) >= 3


@pytest.mark.parametrize(("doc", "line", "command", "rest"), list(_mentions()),
                         ids=lambda value: value if isinstance(value, str) and "/" in value else None)
def test_every_mentioned_command_and_option_exists(doc, line, command, rest):
    commands = _commands()
    assert command in commands, f"{doc}:{line}: `ar3cli {command}` is not a command ({', '.join(commands)})"
    try:
        words = shlex.split(rest.split("#")[0], posix=True)
    except ValueError:
        words = rest.split()
    options = _options(commands[command])
    for word in words:
        if word in ("|", ">", "&&", ";", "||"):
            break
        if word.startswith("-") and not re.fullmatch(r"-?\d+(\.\d+)?", word):
            flag = word.split("=")[0]
            assert flag in options, f"{doc}:{line}: `ar3cli {command}` has no option {flag}"


def test_readme_rule_count_matches_the_registry():
    from ar3cli.lint.rules import REGISTRY

    counts = re.findall(r"\| (\d+) rules \(", (REPO / "README.md").read_text(encoding="utf-8"))
    assert counts == [str(len(REGISTRY))]
