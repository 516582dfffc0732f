"""GitHub Actions: workflow-command annotations (``::error file=...::``) and the run's step summary
(``$GITHUB_STEP_SUMMARY``).

Paths, messages and hints go through :func:`~ar3cli.output.report.printable` first: a link named
with an escape sequence must not repaint the CI log.
"""

from __future__ import annotations

import os

from ar3cli.findings import Finding, Severity
from ar3cli.output.report import printable

COMMANDS = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "notice"}


def escape_data(text: str) -> str:
    """Escape a command's message (workflow-commands spec: %, CR, LF)."""
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def escape_property(text: str) -> str:
    """Escape a property value: the message escapes plus ``:`` and ``,``."""
    return escape_data(text).replace(":", "%3A").replace(",", "%2C")


def annotation(finding: Finding) -> str:
    """``::error file=PATH,line=L,col=C,title=CODE::message (fix: hint)``."""
    properties = [f"file={escape_property(printable(finding.path))}"]
    if finding.line:
        properties += [f"line={finding.line}", f"col={max(finding.column, 1)}"]
    properties.append(f"title={escape_property(printable(finding.rule))}")
    message = finding.message + (f" (fix: {finding.hint})" if finding.hint else "")
    return f"::{COMMANDS[finding.severity]} {','.join(properties)}::{escape_data(printable(message))}"


def append_step_summary(markdown: str) -> str | None:
    """Append ``markdown`` to the file ``$GITHUB_STEP_SUMMARY`` names (GitHub Actions shows it on the
    run's summary page); nothing when the variable is unset or empty.

    Returns None, or the one-line error when the file cannot be written (for ``Report.errors``:
    the annotations are still printed, and the exit code says something went wrong).
    """
    path = os.environ.get("GITHUB_STEP_SUMMARY")
    if not path:
        return None
    try:
        with open(path, "a", encoding="utf-8") as handle:
            handle.write(markdown)
    except OSError as exc:
        return f"cannot append to $GITHUB_STEP_SUMMARY ({path}): {exc.strerror or exc}"
    return None
