"""Capture what C code writes to file descriptors 1 and 2.

pybullet prints from C (``printf``/``fprintf``): its build banner to stderr at import, b3Warning
and b3Error lines to stdout during loads. ``contextlib.redirect_stdout`` only swaps the Python
object and misses all of it, so JSON on stdout would be corrupted. :func:`capture_fds` swaps the
descriptors themselves for a temporary file, and returns what was written as text.
"""

from __future__ import annotations

import contextlib
import re
from collections.abc import Iterator
from dataclasses import dataclass, field

from ar3cli.infra.fd_capture import redirected_fds


@dataclass
class Captured:
    """Text written to fds 1 and 2 inside a :func:`capture_fds` block (filled in on exit)."""

    text: str = ""
    messages: list[str] = field(default_factory=list)


@contextlib.contextmanager
def capture_fds() -> Iterator[Captured]:
    """Redirect fds 1 and 2 to a temp file for the block (:func:`~ar3cli.infra.fd_capture.redirected_fds`);
    safe to nest and exception-safe; the text is split into pybullet's messages."""
    captured = Captured()
    redirected = None
    try:
        with redirected_fds((1, 2)) as redirected:
            yield captured
    finally:
        if redirected is not None:  # filled in whatever ended the block
            captured.text = redirected.text
            captured.messages = split_bullet_messages(captured.text)


_MARKER = re.compile(r"b3(?:Warning|Error|Printf)\[[^\]]*\]:\s*")
_NEEDS_NAME = ("No inertial data for link", "Could not parse collision element for Link",
               "Could not parse visual element for Link", "failed to parse link")


def split_bullet_messages(text: str) -> list[str]:
    """Turn pybullet's run-together C output into one clean message per item.

    pybullet prints ``b3Warning[file,line]:\\n<message>`` with no newline after the message, and
    some messages come in two parts (a sentence, then the link name in a second warning). Those
    are joined back: ``No inertial data for link 'b', using mass=1, ...``.
    """
    pieces = [piece.strip() for piece in _MARKER.split(text)]
    lines: list[str] = []
    for piece in pieces:
        lines.extend(line.strip() for line in piece.splitlines() if line.strip())
    messages: list[str] = []
    index = 0
    while index < len(lines):
        line = lines[index]
        if line.startswith("pybullet build time"):
            index += 1
            continue
        head = next((prefix for prefix in _NEEDS_NAME if line.startswith(prefix)), None)
        if head and index + 1 < len(lines) and _looks_like_name(lines[index + 1]):
            name = lines[index + 1]
            rest = line[len(head):].lstrip(":").strip()
            line = f"{head} '{name}'" + (f", {rest.lstrip(', ')}" if rest else "")
            index += 1
        messages.append(line)
        index += 1
    return messages


def _looks_like_name(text: str) -> bool:
    return " " not in text and not text.startswith(("b3", "urdfdom"))
