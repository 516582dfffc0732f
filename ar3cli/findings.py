"""Findings: plain data that every checker produces and the output layer renders, and :func:`listed`,
the one way a message lists names."""

from __future__ import annotations

import enum
from collections.abc import Iterable
from dataclasses import dataclass


class Severity(str, enum.Enum):
    """How bad a finding is; ordered so that ``severity >= threshold`` works."""

    INFO = "info"
    WARNING = "warning"
    ERROR = "error"

    @property
    def rank(self) -> int:
        return _RANK[self]

    def __ge__(self, other: object) -> bool:  # type: ignore[override]
        if not isinstance(other, Severity):
            return NotImplemented
        return self.rank >= other.rank

    def __gt__(self, other: object) -> bool:  # type: ignore[override]
        if not isinstance(other, Severity):
            return NotImplemented
        return self.rank > other.rank

    def __le__(self, other: object) -> bool:  # type: ignore[override]
        if not isinstance(other, Severity):
            return NotImplemented
        return self.rank <= other.rank

    def __lt__(self, other: object) -> bool:  # type: ignore[override]
        if not isinstance(other, Severity):
            return NotImplemented
        return self.rank < other.rank


_RANK = {Severity.INFO: 0, Severity.WARNING: 1, Severity.ERROR: 2}


@dataclass(frozen=True)
class Finding:
    """One problem found in one file.

    ``line``/``column`` are 1-based and 0 when unknown (e.g. a file that cannot be read).
    ``hint`` says how to fix it, in one line.
    """

    rule: str
    severity: Severity
    message: str
    path: str
    line: int = 0
    column: int = 0
    hint: str = ""

    def to_dict(self) -> dict:
        # spelled out: dataclasses.asdict deep-copies every field (a third of a 95-file lint's reporting)
        return {"rule": self.rule, "severity": self.severity.value, "message": self.message, "path": self.path,
                "line": self.line, "column": self.column, "hint": self.hint}

    @property
    def location(self) -> str:
        """``path:line:col`` as editors and terminals link it."""
        if self.line:
            return f"{self.path}:{self.line}:{self.column or 1}"
        return self.path


LIST_ITEMS = 10
"""Items a message names at most, then "and N more"."""


def listed(items: Iterable[object], most: int = LIST_ITEMS, separator: str = ", ") -> str:
    """``a, b, c``, or the first ``most`` items and ``and N more``: how every message (a finding, an
    error, a note) lists names. A robot file decides how many links it has, so a message naming all
    of them grows with the file, and one such message per link with its square: S005 once listed all
    5,000 roots of a file in each of its 4,999 findings (170 MB of GitHub annotations)."""
    shown: list[str] = []
    left = 0
    for item in items:
        if len(shown) < most:
            shown.append(str(item))
        else:
            left += 1
    return separator.join(shown) + (f" and {left:,} more" if left else "")
