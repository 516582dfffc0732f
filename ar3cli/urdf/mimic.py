"""Mimic joints: every movable joint's value from the driving joints' values.

PyBullet does not couple ``<mimic>`` joints, so whoever sets a configuration (the samplers, FK,
render) computes the followers here, the one place that follows mimic chains.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.urdf.model import ACTUATED_JOINT_TYPES, Joint, Model


def driven_values(model: Model, positions: Mapping[str, np.ndarray], count: int) -> dict[str, np.ndarray]:
    """Every movable joint's value: given ones as they are, mimic joints computed, the rest zero.

    A mimic chain (a mimic of a mimic) is followed; a cycle is a UserError.
    """
    values: dict[str, np.ndarray] = {}

    def value_of(joint: Joint, seen: tuple[str, ...] = ()) -> np.ndarray:
        if joint.name in values:
            return values[joint.name]
        if joint.mimic is not None and model.joint(joint.mimic.joint) is not None:
            if joint.name in seen:
                raise UserError(f"mimic joints form a cycle: {listed((*seen, joint.name), separator=' -> ')}")
            source = value_of(model.joint(joint.mimic.joint), (*seen, joint.name))  # type: ignore[arg-type]
            result = joint.mimic.multiplier * source + joint.mimic.offset
        else:
            result = np.asarray(positions.get(joint.name, np.zeros(count)), dtype=float)
        values[joint.name] = result
        return result

    for joint in model.joints:
        if joint.type in ACTUATED_JOINT_TYPES:
            value_of(joint)
    return values
