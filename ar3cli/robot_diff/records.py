"""The plain data a robot diff produces: one :class:`Change` per semantic difference, the end
effectors' displacements, the lint findings that came and went, and the :class:`RobotDiff` holding them."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

SECTIONS = ("structure", "kinematics", "dynamics", "limits", "geometry")
"""The kinds of change, in the order they are reported."""


def finite_or_none(value: float | None) -> float | None:
    """``value`` when it is a finite number, else None: NaN and inf never reach the output."""
    return value if value is not None and math.isfinite(value) else None


def show(value: Any) -> str:
    """A value for a table cell: numbers with up to 9 significant digits (NaN and inf as ``(not a number)``),
    tuples space-separated, None as ``-``."""
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.9g}" if math.isfinite(value) else "(not a number)"
    if isinstance(value, (tuple, list)):
        return " ".join(show(item) for item in value)
    return str(value)


@dataclass(frozen=True)
class Change:
    """One semantic difference between OLD and NEW, beyond the tolerance.

    ``element`` names it (``joint 'j2'``); ``what`` says which property (``added``, ``origin``,
    ``mass``...); ``old``/``new`` are the values as text; ``amount`` is the size of the change in SI
    units (m, rad) or relative (masses, inertias), when it has one. ``file``/``line`` say where NEW
    writes the element (a removed element: where NEW would have it, its parent, or nothing).
    """

    section: str
    element: str
    what: str
    old: str = ""
    new: str = ""
    amount: float | None = None
    unit: str = ""
    file: str = ""
    line: int = 0

    @property
    def summary(self) -> str:
        """One line: ``joint 'j2' origin: 0 0 0.1 -> 0 0 0.14 (0.04 m)``."""
        text = f"{self.element} {self.what}"
        if self.old or self.new:
            text += f": {self.old or '-'} -> {self.new or '-'}"
        if finite_or_none(self.amount) is not None:
            text += f" ({self.amount:.4g}{' ' + self.unit if self.unit else ''})"
        return text

    def to_dict(self) -> dict[str, Any]:
        return {"section": self.section, "element": self.element, "what": self.what, "old": self.old,
                "new": self.new, "amount": finite_or_none(self.amount), "unit": self.unit,
                "file": self.file, "line": self.line}


@dataclass(frozen=True)
class Displacement:
    """How far an end effector (a leaf link) of NEW is from where OLD puts it, over the same joint values."""

    link: str
    home_m: float | None
    home_rad: float | None
    max_m: float | None
    mean_m: float | None
    max_rad: float | None
    mean_rad: float | None
    """Metres and radians; None where a value of the file is not a number (NaN never reaches the output)."""
    cause: str
    """The first joint on the path from the root whose origin, axis or type changed, and what; or ``-``."""
    file: str = ""
    line: int = 0

    def to_dict(self) -> dict[str, Any]:
        return {"link": self.link, "cause": self.cause, "file": self.file, "line": self.line,
                **{name: finite_or_none(getattr(self, name))
                   for name in ("home_m", "home_rad", "max_m", "mean_m", "max_rad", "mean_rad")}}


@dataclass(frozen=True)
class FindingChange:
    """A lint finding that is new in NEW or fixed since OLD (matched by rule code and element name)."""

    status: str  # "new" or "fixed"
    rule: str
    severity: str
    message: str
    file: str
    line: int

    def to_dict(self) -> dict[str, Any]:
        return {"status": self.status, "rule": self.rule, "severity": self.severity, "message": self.message,
                "file": self.file, "line": self.line}


@dataclass
class RobotDiff:
    """Everything one OLD/NEW pair differs in. ``changed`` counts only semantic changes beyond the
    tolerance; lint findings are reported beside them and do not make a change on their own."""

    old: str
    new: str
    changes: list[Change] = field(default_factory=list)
    displacements: list[Displacement] = field(default_factory=list)
    findings: list[FindingChange] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    """What could not be compared and why (forward kinematics of a floating joint, ...)."""
    totals: dict[str, Any] = field(default_factory=dict)

    @property
    def changed(self) -> bool:
        return bool(self.changes or self.displacements)

    def to_dict(self) -> dict[str, Any]:
        return {"old": self.old, "new": self.new, "changed": self.changed,
                "changes": [change.to_dict() for change in self.changes],
                "kinematics": [moved.to_dict() for moved in self.displacements],
                "dynamics_totals": self.totals,
                "findings": [finding.to_dict() for finding in self.findings], "notes": self.notes}
