"""Findings: plain data that every checker produces and the output layer renders."""

from __future__ import annotations

import enum
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
