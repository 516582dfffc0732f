"""One scanned file as a row: its status, findings and key metrics, and how a row is judged.

Statuses, worst last in :data:`STATUSES`:

- ``clean``: loaded and checked, no finding at or above :data:`FAIL_ON` (what ``lint-urdf``'s
  summary calls clean with its default ``--fail-on``: a file with only warnings or info passes);
- ``findings``: loaded and checked, at least one finding at or above :data:`FAIL_ON`;
- ``error``: not loaded (its F001-F004 finding says why) or the check failed inside ar3cli;
- ``crash``: a crash in C code cut the check short (pybullet under ``--sim``, or the worker died);
- ``timeout``: the check took longer than the per-file limit and was stopped.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any

STATUSES = ("clean", "findings", "error", "crash", "timeout")
LOADED = ("clean", "findings")
"""Statuses of a file that loaded and whose check ran to the end."""
SEVERITIES = ("info", "warning", "error")
FAIL_ON = "error"
"""The severity from which a finding makes a file not clean: lint-urdf's default ``--fail-on``."""

JOINT_DOF = {"revolute": 1, "continuous": 1, "prismatic": 1, "planar": 3, "floating": 6, "spherical": 3}
"""Degrees of freedom per joint type, as ``ar3cli info`` counts them (a mimic joint adds none)."""


@dataclass
class Row:
    """What the store keeps of one file. ``findings`` are :meth:`Finding.to_dict` dictionaries."""

    path: str
    sha256: str
    settings: str
    status: str
    findings: list[dict[str, Any]] = field(default_factory=list)
    message: str = ""
    """Why the check did not finish (status error, crash or timeout); empty otherwise."""
    dof: int | None = None
    mass: float | None = None
    links: int | None = None
    joints: int | None = None
    load_seconds: float | None = None
    """Reading, expanding and parsing the file (ar3cli's Model): None when it did not load."""
    check_seconds: float | None = None
    """The whole per-file check, load included."""

    def counts(self) -> dict[str, int]:
        """Findings per severity: ``{"error": 1, "warning": 0, "info": 2}``."""
        return {level: sum(f["severity"] == level for f in self.findings) for level in SEVERITIES}

    def to_dict(self) -> dict[str, Any]:
        return {"path": self.path, "sha256": self.sha256, "settings": self.settings, "status": self.status,
                "message": self.message, "dof": self.dof, "mass": self.mass, "links": self.links,
                "joints": self.joints, "load_seconds": self.load_seconds, "check_seconds": self.check_seconds,
                **self.counts(), "findings": self.findings}

    def findings_json(self) -> str:
        return json.dumps(self.findings, separators=(",", ":"), allow_nan=False)


TIMINGS = ("load_seconds", "check_seconds")
"""Fields that differ from run to run (left out when two scans are compared)."""


def model_metrics(model) -> dict[str, Any]:
    """DOF, total mass (the finite ``<mass>`` values summed; None when no link has one), link and
    joint counts of a loaded :class:`~ar3cli.urdf.model.Model`."""
    from ar3cli.maths.tensor_math import exact_sum

    masses = [link.inertial.mass for link in model.links
              if link.inertial is not None and link.inertial.mass is not None and math.isfinite(link.inertial.mass)]
    dof = sum(JOINT_DOF.get(joint.type, 0) for joint in model.joints if joint.mimic is None)
    return {"dof": dof, "mass": exact_sum(masses) if masses else None, "links": len(model.links),
            "joints": len(model.joints)}


def status_of(loaded: bool, findings: list, error: str | None) -> str:
    """The status of a finished check (a timeout or a dead worker is decided by the pool)."""
    if error:
        return "crash"
    if not loaded:
        return "error"
    return "clean" if clean(findings) else "findings"


def clean(findings: list[dict[str, Any]]) -> bool:
    """No finding at or above :data:`FAIL_ON` (``findings`` are :meth:`Finding.to_dict` dictionaries)."""
    failing = SEVERITIES[SEVERITIES.index(FAIL_ON):]
    return not any(finding["severity"] in failing for finding in findings)


def severity_rank(row: Row) -> tuple:
    """Sort key, worst first when sorted descending: status, then errors, warnings, infos."""
    counts = row.counts()
    return STATUSES.index(row.status), counts["error"], counts["warning"], counts["info"]
