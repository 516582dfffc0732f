"""Joint-space sampling shared by sample-collisions and fk-verify.

A configuration is one value per 1-DOF joint of a loaded :class:`~ar3cli.sim.session.Body`, in
:attr:`~ar3cli.sim.session.Body.actuated_joints` order (what :meth:`~ar3cli.sim.session.Body.set_positions` and
``resetJointStatesMultiDof`` take). Only the *driving* joints are free: a joint with a
``<mimic>`` of an existing joint is computed from its source (``multiplier * q + offset``, chains
followed, by :func:`ar3cli.urdf.mimic.driven_values`), because PyBullet does not couple mimic
joints and a configuration with the two fingers of a gripper at unrelated positions is one the
robot can never reach.

- Ranges: :meth:`~ar3cli.sim.session.JointRecord.sample_range` (the URDF limits; continuous and unlimited
  revolute joints in [-pi, pi)).
- Uniform samples: ``numpy.random.default_rng(seed).uniform(lower, upper, size=(N, driving))``,
  the driving joints in body order. Without mimic joints that is exactly the draw both commands
  made before this module existed, so a seed gives the same configurations as before.
- Home: :meth:`~ar3cli.sim.session.JointRecord.home` for each driving joint (0, or mid-range where 0 is
  outside the limits), mimic joints following.
- Limit configurations: the home pose, each limited driving joint at its lower and at its upper
  limit (the others at home), all limited driving joints at lower, all at upper; mimic joints
  follow every time; continuous joints stay at home (-pi and pi are one pose, not a limit).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ar3cli.errors import UserError
from ar3cli.urdf.mimic import driven_values
from ar3cli.urdf.model import Model


@dataclass(frozen=True)
class JointSpace:
    """The 1-DOF joints of a body and which of them are sampled.

    ``names`` are all columns of a configuration; ``driving`` the indices (into ``names``) of the
    joints drawn independently. ``lower``, ``upper`` and ``continuous`` describe the driving
    joints; ``home`` is a full configuration.
    """

    names: tuple[str, ...]
    driving: tuple[int, ...]
    lower: np.ndarray
    upper: np.ndarray
    continuous: tuple[bool, ...]
    home: np.ndarray
    model: Model = field(repr=False, compare=False)

    @property
    def dof(self) -> int:
        """Degrees of freedom: the number of driving joints."""
        return len(self.driving)

    @property
    def driving_names(self) -> tuple[str, ...]:
        return tuple(self.names[index] for index in self.driving)

    @property
    def mimic_names(self) -> tuple[str, ...]:
        """The joints computed from another joint, in body order."""
        driving = set(self.driving)
        return tuple(name for index, name in enumerate(self.names) if index not in driving)

    def fill(self, driving_values: np.ndarray) -> np.ndarray:
        """Full configurations (N, len(names)) from driving values (N, dof): mimic joints computed."""
        driving_values = np.asarray(driving_values, dtype=float)
        if driving_values.ndim == 1:
            driving_values = driving_values.reshape(1, -1)
        count = driving_values.shape[0]
        given = {name: driving_values[:, i] for i, name in enumerate(self.driving_names)}
        if len(self.driving) == len(self.names):
            return driving_values.copy()
        values = driven_values(self.model, given, count)
        columns = [values.get(name, given.get(name, np.zeros(count))) for name in self.names]
        return np.stack(columns, axis=1)

    def as_dict(self, configuration: np.ndarray) -> dict[str, float]:
        """One full configuration as {joint: value}."""
        return {name: float(value) for name, value in zip(self.names, configuration)}


def is_mimic(joint: Any, model: Model) -> bool:
    """A :class:`~ar3cli.sim.session.JointRecord` whose URDF joint mimics a joint that exists."""
    return joint.urdf is not None and joint.urdf.mimic is not None and model.joint(joint.urdf.mimic.joint) is not None


def joint_space(body: Any) -> JointSpace:
    """The joint space of a loaded :class:`~ar3cli.sim.session.Body` (its ``model`` gives the mimic couplings)."""
    joints = body.actuated_joints
    driving = tuple(i for i, joint in enumerate(joints) if not is_mimic(joint, body.model))
    ranges = np.array([joints[i].sample_range() for i in driving], dtype=float).reshape(-1, 2)
    for i, (lower, upper) in zip(driving, ranges):
        if not (np.isfinite(lower) and np.isfinite(upper)):
            where = f"{body.model.path}:{joints[i].urdf.line}" if joints[i].urdf is not None else str(body.model.path)
            raise UserError(f"{where}: joint '{joints[i].name}' has limits ({lower}, {upper}) that cannot be "
                            "sampled; give finite numbers (lint-urdf reports this as F007)")
    partial = JointSpace(
        names=tuple(joint.name for joint in joints), driving=driving,
        lower=ranges[:, 0].copy(), upper=ranges[:, 1].copy(),
        continuous=tuple(joints[i].continuous for i in driving),
        home=np.zeros(len(joints)), model=body.model,
    )
    home = partial.fill(np.array([[joints[i].home() for i in driving]], dtype=float))[0]
    return JointSpace(partial.names, driving, partial.lower, partial.upper, partial.continuous, home, body.model)


def sample_driving(space: JointSpace, count: int, seed: int) -> np.ndarray:
    """``count`` x dof uniform values of the driving joints; the same seed gives the same matrix."""
    rng = np.random.default_rng(seed)
    return rng.uniform(space.lower, space.upper, size=(count, space.dof))


def sample_configurations(space: JointSpace, count: int, seed: int) -> np.ndarray:
    """``count`` full uniform configurations (rows), mimic joints following their source."""
    return space.fill(sample_driving(space, count, seed))


def home_positions(body: Any) -> dict[str, float]:
    """The home pose of a loaded body as {joint: value}, mimic joints following."""
    space = joint_space(body)
    return space.as_dict(space.home)


def limit_configurations(space: JointSpace) -> list[tuple[str, np.ndarray]]:
    """The home pose, each limited driving joint at its lower and upper limit (others at home), then
    all limited driving joints at lower and all at upper; mimic joints follow; duplicates of an
    earlier configuration are dropped. Labels: ``home``, ``<joint> at lower``, ``all at upper``.
    """
    home = space.home[list(space.driving)]
    candidates: list[tuple[str, np.ndarray]] = [("home", home.copy())]
    limited = [index for index in range(space.dof) if not space.continuous[index]]
    names = space.driving_names
    for index in limited:
        for label, bound in (("lower", space.lower), ("upper", space.upper)):
            q = home.copy()
            q[index] = bound[index]
            candidates.append((f"{names[index]} at {label}", q))
    for label, bound in (("lower", space.lower), ("upper", space.upper)):
        q = home.copy()
        q[limited] = bound[limited]
        candidates.append((f"all at {label}", q))
    seen: set[tuple[float, ...]] = set()
    unique = []
    for label, q in candidates:
        key = tuple(q.tolist())
        if key not in seen:
            seen.add(key)
            unique.append((label, q))
    if not unique:
        return []
    full = space.fill(np.array([q for _, q in unique]))
    return [(label, row) for (label, _), row in zip(unique, full)]
