"""What an HTML page shows with each lint finding: the cited lines of the source file it names (for
a xacro, the xacro file the element came from) and the ar3cli command that fixes it. Used by
``report`` and ``lint-urdf --format html``; the renderer (:mod:`ar3cli.output.html`) reads no file.

Only the bytes ar3cli parsed are shown, and only of files it may show: the linter records each
such file with the digest of what it parsed (``LintResult.sources``: not a robot file that is a
symbolic link leading out of its folder, such as ``robot.urdf -> ~/.aws/credentials`` or
``/proc/self/environ``), and a file read again here is shown only when its bytes have that digest."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError

LONGEST_SOURCE_LINE = 240
"""Characters of a cited line shown (a one-line minified file must not copy itself per finding)."""


def finding_context(findings: Iterable, digests: Mapping[str, str]) -> dict[str, Any]:
    """What the page shows with each finding: the cited lines of its source file (the xacro file it
    came from; ``sources[path][line]``), for the files in ``digests`` (display path -> SHA-256 of the
    bytes parsed) whose bytes still have it, and the ar3cli command that fixes it (``fixes[index]``)."""
    import hashlib

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
        if name not in digests:
            continue
        try:
            data = read_bytes(Path(name))
        except UserError:
            continue
        if hashlib.sha256(data).hexdigest() != digests[name]:
            continue  # not the bytes that were linted (changed since, or another file now)
        text = data.decode("utf-8", errors="replace").splitlines()
        sources[name] = {n: text[n - 1][:LONGEST_SOURCE_LINE] for n in sorted(numbers) if 1 <= n <= len(text)}
    fixes = [(fix_commands(f.path, [f]) or [""])[0] for f in findings]
    return {"sources": sources, "fixes": fixes}
