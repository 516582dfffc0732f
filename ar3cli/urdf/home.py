"""The home pose: where every command puts a robot before it looks at it, read from the URDF alone.

A 1-DOF joint's home is 0, or the middle of its range where 0 is outside its limits (MoveIt's
convention; a gripper finger limited to [0.01, 0.04] cannot be at 0). A joint's range is its
``<limit lower upper>`` as PyBullet reads it: a missing ``lower`` is 0 and a missing ``upper`` is -1
(PyBullet's defaults, not URDF's 0), and a range with ``lower > upper`` or a continuous joint is
unlimited, sampled in [-pi, pi) (a prismatic joint in [-1, 1]). Mimic joints follow their leader.

sample-collisions, render, fk-verify, the torque check and ``lint-urdf --sim`` compute the same pose
from the loaded PyBullet body (:meth:`ar3cli.sim.session.JointRecord.home` calls :func:`home_value`);
this module gives it without PyBullet, for a page that says which joints are not at 0 and a viewer's
"home" button.
"""

from __future__ import annotations

import math

from ar3cli.urdf.model import ACTUATED_JOINT_TYPES, Joint, Model

PYBULLET_DEFAULT_LOWER = 0.0
PYBULLET_DEFAULT_UPPER = -1.0
"""What PyBullet takes for a missing ``lower`` / ``upper`` (measured: ``<limit effort velocity/>``
gives ``getJointInfo`` limits (0, -1), an unlimited joint)."""


def sample_range(joint_type: str, lower: float | None, upper: float | None) -> tuple[float, float]:
    """Where a joint is sampled: its limits, or [-pi, pi) (prismatic [-1, 1]) without usable ones."""
    if lower is not None and upper is not None:
        return lower, upper
    if joint_type == "prismatic":
        return -1.0, 1.0
    return -math.pi, math.pi


def home_value(lower: float, upper: float) -> float:
    """0, or mid-range when 0 is outside [``lower``, ``upper``]."""
    return 0.0 if lower <= 0.0 <= upper else (lower + upper) / 2.0


def pybullet_limits(joint: Joint) -> tuple[float | None, float | None]:
    """``(lower, upper)`` as PyBullet reads them, (None, None) for an unlimited joint."""
    if joint.type == "continuous":
        return None, None
    limit = joint.limit
    lower = PYBULLET_DEFAULT_LOWER if limit is None or limit.lower is None else limit.lower
    upper = PYBULLET_DEFAULT_UPPER if limit is None or limit.upper is None else limit.upper
    if not (math.isfinite(lower) and math.isfinite(upper)) or lower > upper:
        return None, None
    return lower, upper


def home_pose(model: Model) -> dict[str, float]:
    """Every 1-DOF joint (revolute, continuous, prismatic) at home, in file order; a mimic joint at
    its leader's home times its multiplier plus its offset (chains followed; a cycle is a UserError)."""
    from ar3cli.urdf.mimic import driven_values

    leaders = {joint.name: home_value(*sample_range(joint.type, *pybullet_limits(joint)))
               for joint in model.joints if joint.type in ACTUATED_JOINT_TYPES}
    driven = driven_values(model, {name: [value] for name, value in leaders.items()}, 1)
    return {name: float(values[0]) for name, values in driven.items()}
