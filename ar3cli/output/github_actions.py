"""GitHub Actions: workflow-command annotations (``::error file=...::``) and the run's step summary
(``$GITHUB_STEP_SUMMARY``).

Every annotation is built by :func:`workflow_command`, whose properties and message go through
:func:`~ar3cli.output.escape.github_property` / :func:`~ar3cli.output.escape.github_data`: a link
named with a newline cannot start a line of its own (a forged ``::stop-commands::``), an escape
sequence cannot repaint the CI log.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

from ar3cli.findings import Severity
from ar3cli.output.escape import github_data, github_property

COMMANDS = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "notice"}

ANNOTATIONS_PER_RUN = 50
"""Annotations one run writes at most; the rest are counted in one last notice. GitHub shows 10 of
each kind per step and 50 per job, so more would only fill the log (5,000 S005 findings once wrote
170 MB of them)."""

STEP_SUMMARY_LIMIT = 1024 * 1024
"""Bytes GitHub accepts in one step's summary (``$GITHUB_STEP_SUMMARY``): a larger file is not
shown at all, and the step gets an error annotation instead."""


def workflow_command(kind: str, message: str | Sequence[str], *, file: str = "", line: int = 0, column: int = 0,
                     title: str = "") -> str:
    """``::KIND file=F,line=L,col=C,title=T::MESSAGE``, each part escaped for its place. ``message`` is
    one line, or a sequence of lines that GitHub shows as the lines of one annotation (joined by an
    encoded newline; a newline inside a line is shown as ``\\x0a``, as everywhere)."""
    properties = []
    if file:
        properties.append(f"file={github_property(file)}")
        if line:
            properties.append(f"line={int(line)}")
            if column:
                properties.append(f"col={int(column)}")
    if title:
        properties.append(f"title={github_property(title)}")
    text = github_data(message) if isinstance(message, str) else "%0A".join(map(github_data, message))
    return f"::{kind}{' ' + ','.join(properties) if properties else ''}::{text}"


def capped_annotations(lines: list[str], what: str = "findings") -> str:
    """``lines`` (one annotation each), at most :data:`ANNOTATIONS_PER_RUN`, the rest counted in one notice."""
    shown = lines[:ANNOTATIONS_PER_RUN]
    if len(lines) > len(shown):
        shown.append(workflow_command(
            "notice", f"{len(lines) - len(shown)} more annotations of {what} left out (GitHub shows the first 10 "
                      "of each kind per step): the step summary and --format json list them all",
            title="ar3cli"))
    return "".join(line + "\n" for line in shown)


def append_step_summary(markdown: str) -> str | None:
    """Append ``markdown`` to the file ``$GITHUB_STEP_SUMMARY`` names (GitHub Actions shows it on the
    run's summary page); nothing when the variable is unset or empty. Past
    :data:`STEP_SUMMARY_LIMIT`, the text is cut at a line and says so.

    Returns None, or the one-line error when the file cannot be written (for ``Report.errors``:
    the annotations are still printed, and the exit code says something went wrong).
    """
    path = os.environ.get("GITHUB_STEP_SUMMARY")
    if not path:
        return None
    data = markdown.encode("utf-8", "backslashreplace")
    if len(data) > STEP_SUMMARY_LIMIT - 4096:
        cut = data.rfind(b"\n", 0, STEP_SUMMARY_LIMIT - 4096) + 1
        data = data[:cut] + (f"\n_(cut at {cut:,} bytes: GitHub shows at most 1 MiB per step; --format json lists "
                             "every finding)_\n").encode()
    try:
        with open(path, "ab") as handle:
            handle.write(data)
    except OSError as exc:
        return f"cannot append to $GITHUB_STEP_SUMMARY ({path}): {exc.strerror or exc}"
    return None
