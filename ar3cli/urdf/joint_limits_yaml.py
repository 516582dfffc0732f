"""MoveIt's ``joint_limits.yaml``: the joint limits a robot's MoveIt config states.

Read by ``fix-continuous --limits-from`` (joints with hard stops become revolute with these
limits) and ``fix-joints --limits-from`` (a ``<limit>`` without effort or velocity gets them).
A value counts only where its ``has_*_limits`` flag is true, as MoveIt reads it; every problem is
a one-line :class:`~ar3cli.errors.UserError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ar3cli.errors import UserError


@dataclass(frozen=True)
class YamlLimits:
    """One joint of a MoveIt joint_limits.yaml (None where has_* is false or the value absent)."""

    lower: float | None
    upper: float | None
    velocity: float | None
    effort: float | None


def read_joint_limits(path: Path) -> dict[str, YamlLimits]:
    """Parse MoveIt's ``joint_limits.yaml`` (top key ``joint_limits``); errors are one-line UserErrors."""
    from ar3cli.urdf.yamlfile import load_yaml

    data = load_yaml(path, "joint limits file")
    if not isinstance(data, dict) or not isinstance(data.get("joint_limits"), dict):
        raise UserError(f"{path}: expected MoveIt's format with a top-level 'joint_limits:' mapping")
    limits: dict[str, YamlLimits] = {}
    for name, entry in data["joint_limits"].items():
        if not isinstance(entry, dict):
            raise UserError(f"{path}: joint_limits.{name} is not a mapping")
        limits[str(name)] = YamlLimits(
            _yaml_number(path, name, entry, "min_position", "has_position_limits"),
            _yaml_number(path, name, entry, "max_position", "has_position_limits"),
            _yaml_number(path, name, entry, "max_velocity", "has_velocity_limits"),
            _yaml_number(path, name, entry, "max_effort", "has_effort_limits"))
        _check_position_limits(path, str(name), entry, limits[str(name)])
    return limits


def _check_position_limits(path: Path, joint: str, entry: dict, limits: YamlLimits) -> None:
    """A joint that claims position limits must give both, in order (else the fix would be wrong)."""
    if entry.get("has_position_limits") is not True:
        return
    if limits.lower is None or limits.upper is None:
        raise UserError(f"{path}: joint_limits.{joint} has has_position_limits: true but no min_position/max_position")
    if limits.lower > limits.upper:
        raise UserError(f"{path}: joint_limits.{joint}: min_position {limits.lower} is above max_position "
                        f"{limits.upper}")


def _yaml_number(path: Path, joint: str, entry: dict, key: str, flag: str) -> float | None:
    if entry.get(flag) is not True or key not in entry:
        return None
    value = entry[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise UserError(f"{path}: joint_limits.{joint}.{key} is {value!r}, expected a number")
    return float(value)
