"""Helpers for the fixer tests: inject defects into real files, and check what a fix touched."""

from __future__ import annotations

import difflib
import re
from pathlib import Path


def element_lines(text: str, start_pattern: str, end_tag: str) -> tuple[int, int]:
    """0-based first and last line of the first element matching ``start_pattern`` (a regex)."""
    match = re.search(start_pattern, text)
    assert match, start_pattern
    end = text.index(end_tag, match.start()) + len(end_tag)
    return text.count("\n", 0, match.start()), text.count("\n", 0, end)


def remove_inertial(text: str, link: str) -> str:
    """Drop the <inertial> block (whole lines) of ``link``."""
    start = re.search(rf'<link\s+name="{link}"', text).start()
    inertial = text.index("<inertial>", start)
    line_start = text.rfind("\n", 0, inertial) + 1
    end = text.index("</inertial>", inertial) + len("</inertial>")
    line_end = text.index("\n", end) + 1
    return text[:line_start] + text[line_end:]


def replace_in_link(text: str, link: str, old: str, new: str) -> str:
    """Replace the first ``old`` after ``<link name="link"``."""
    start = re.search(rf'<link\s+name="{link}"', text).start()
    index = text.index(old, start)
    return text[:index] + new + text[index + len(old):]


def changed_old_lines(old: str, new: str) -> list[int]:
    """0-based line numbers of ``old`` that were replaced or deleted, plus insertion points."""
    a, b = old.splitlines(keepends=True), new.splitlines(keepends=True)
    lines: list[int] = []
    for tag, i1, i2, _, _ in difflib.SequenceMatcher(a=a, b=b, autojunk=False).get_opcodes():
        if tag != "equal":
            lines.extend(range(i1, max(i2, i1 + 1)) if tag != "insert" else [i1 - 1])
    return lines


def only_within(old: str, new: str, ranges: list[tuple[int, int]]) -> bool:
    """True when every changed line of ``old`` lies in one of the (first, last) line ranges."""
    return all(any(first <= line <= last for first, last in ranges) for line in changed_old_lines(old, new))


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def lint_findings(cli, path: Path, select: str, *extra: str) -> list[dict]:
    """Findings of the real ``ar3cli lint-urdf --select SELECT`` on ``path``."""
    import json

    result = cli("lint-urdf", str(path), "--select", select, "--format", "json", *extra)
    assert result.code in (0, 1), result.stderr
    return json.loads(result.stdout)["findings"]
