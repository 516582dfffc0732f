"""What an HTML page shows with each lint finding: the cited lines of the source file it names (for
a xacro, the xacro file the element came from) and the ar3cli command that fixes it. Used by
``report`` and ``lint-urdf --format html``; the renderer (:mod:`ar3cli.output.html`) reads no file."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError

LONGEST_SOURCE_LINE = 240
"""Characters of a cited line shown (a one-line minified file must not copy itself per finding)."""


def finding_context(findings: Iterable) -> dict[str, Any]:
    """What the page shows with each finding: the cited lines of its source file (the xacro file it
    came from; ``sources[path][line]``) and the ar3cli command that fixes it (``fixes[index]``)."""
    from ar3cli.infra.safe_read import read_bytes
    from ar3cli.lint.fix_hints import fix_commands
    from ar3cli.output.html_page import SOURCE_CONTEXT

    findings = list(findings)
    wanted: dict[str, set[int]] = {}
    for finding in findings:
        if finding.line:
            wanted.setdefault(finding.path, set()).update(range(finding.line - SOURCE_CONTEXT,
                                                                finding.line + SOURCE_CONTEXT + 1))
    sources: dict[str, dict[int, str]] = {}
    for name, numbers in wanted.items():
        try:
            text = read_bytes(Path(name)).decode("utf-8", errors="replace").splitlines()
        except UserError:
            continue
        sources[name] = {n: text[n - 1][:LONGEST_SOURCE_LINE] for n in sorted(numbers) if 1 <= n <= len(text)}
    fixes = [(fix_commands(f.path, [f]) or [""])[0] for f in findings]
    return {"sources": sources, "fixes": fixes}
