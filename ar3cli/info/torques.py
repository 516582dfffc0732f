"""``ar3cli info --torques``: can the robot hold itself up?

For each actuated joint, the torque (N m; N for a prismatic joint) it needs to hold the robot still
against gravity at the worst of the checked configurations, against the ``<limit effort>`` the file
declares. The torques are PyBullet's inverse dynamics (``calculateInverseDynamics``) with zero
velocity and acceleration under gravity -9.81 m/s^2 along the base's z axis, the base fixed, the
masses and inertias from the file (``URDF_USE_INERTIA_FROM_FILE``): at rest, what a joint must
exert is exactly its share of the weight of everything it carries.

Configurations (:mod:`ar3cli.sim.sampling`): the home pose and the limit configurations (each
limited driving joint at its lower and upper limit, all at lower, all at upper), then ``samples``
uniform configurations from ``numpy.random.default_rng(seed)``; continuous joints are drawn in
[-pi, pi); ``<mimic>`` joints are set as their source says. The torque of a mimic joint is what
that joint itself must exert (its mechanism or motor carries it), reported like any other.

Everything pybullet does runs in a forked child (:func:`ar3cli.sim.session.run_pybullet`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.sim.capture import capture_fds
from ar3cli.urdf.model import Model

GRAVITY = -9.81
"""m/s^2 along the world z axis (the base frame's z: the base is loaded upright at the origin)."""
DEFAULT_SAMPLES = 200
"""Uniform samples on top of the home and limit configurations (the AR3: ~0.1 s of inverse dynamics)."""
NEGLIGIBLE = 1e-9
"""N m (or N): a needed torque below this is numerical noise (a vertical axis under gravity reads
~1e-16): it counts as 0, so the margin is not a meaningless huge number."""

TIE = 1e-9
"""Relative: torques this close to the largest are the same torque (inverse dynamics rounding)."""
ANY = "any"
"""The configuration label of a joint that needs no torque anywhere (its configuration is home)."""
OK = "ok"
TOO_WEAK = "too weak"
NO_EFFORT = "no effort declared"


@dataclass
class JointTorque:
    """One actuated joint: the largest |torque| it needs, where, and its declared effort."""

    name: str
    type: str
    needed: float
    """max |torque| over the configurations (N m, or N for prismatic)."""
    at: str
    """Label of the configuration where it is needed: ``home``, ``joint_2 at upper``, ``sample 17``."""
    at_configuration: dict[str, float]
    effort: float | None
    """The ``<limit effort>``; None when missing, 0 or not a finite number."""
    mimic_of: str | None = None

    @property
    def unit(self) -> str:
        return "N" if self.type == "prismatic" else "N m"

    @property
    def margin(self) -> float | None:
        """effort / needed; None without an effort or when nothing is needed."""
        if self.effort is None or self.needed < NEGLIGIBLE:
            return None
        return self.effort / self.needed

    @property
    def status(self) -> str:
        if self.effort is None:
            return NO_EFFORT
        return TOO_WEAK if self.effort < self.needed else OK

    def to_dict(self) -> dict[str, Any]:
        return {"joint": self.name, "type": self.type, "unit": self.unit, "needed": self.needed, "at": self.at,
                "at_configuration": self.at_configuration, "effort": self.effort, "margin": self.margin,
                "status": self.status, "mimic_of": self.mimic_of}


@dataclass
class TorqueCheck:
    samples: int
    seed: int
    limit_configurations: int
    joints: list[JointTorque] = field(default_factory=list)

    @property
    def configurations(self) -> int:
        return self.samples + self.limit_configurations

    @property
    def too_weak(self) -> list[JointTorque]:
        return [joint for joint in self.joints if joint.status == TOO_WEAK]

    @property
    def without_effort(self) -> list[JointTorque]:
        return [joint for joint in self.joints if joint.status == NO_EFFORT]

    def to_dict(self) -> dict[str, Any]:
        return {"gravity_m_s2": GRAVITY, "samples": self.samples, "seed": self.seed,
                "limit_configurations": self.limit_configurations, "configurations": self.configurations,
                "too_weak": [joint.name for joint in self.too_weak],
                "no_effort": [joint.name for joint in self.without_effort],
                "joints": [joint.to_dict() for joint in self.joints]}


@dataclass
class _Needed:
    """What the pybullet child sends back (plain data: it is pickled)."""

    names: list[str]
    types: list[str]
    at: list[str]
    """Per joint, the label of the configuration with the largest |torque|."""
    at_configuration: list[list[float]]
    """Per joint, that configuration (every actuated joint's value)."""
    needed: list[float]
    limit_configurations: int


def gravity_torques(model: Model, samples: int = DEFAULT_SAMPLES, seed: int = 0) -> TorqueCheck:
    """The torque check of ``model`` (see the module doc); UserError for what it cannot handle. A collision
    mesh pybullet cannot load (a file not found) is left out with one warning line: the masses come from
    the file's ``<inertial>`` elements, not from meshes."""
    from ar3cli.output.report import log
    from ar3cli.sim.loadable_copy import left_out_summary, unloadable_shapes
    from ar3cli.sim.session import run_pybullet

    left_out = unloadable_shapes(model, roles=("collision",))
    if left_out:
        log(f"info: warning: {model.path}: {left_out_summary(left_out)}: pybullet cannot load it; "
            "gravity torques do not depend on meshes (the masses are the file's <inertial>)")
    result = run_pybullet(lambda: _compute(model, samples, seed), model)
    check = TorqueCheck(samples=samples if result.names else 0, seed=seed,
                        limit_configurations=result.limit_configurations)
    for i, name in enumerate(result.names):
        joint = model.joint(name)
        effort = joint.limit.effort if joint is not None and joint.limit is not None else None
        if effort is not None and not (math.isfinite(effort) and effort > 0):
            effort = None
        mimic = joint.mimic.joint if joint is not None and joint.mimic is not None else None
        check.joints.append(JointTorque(
            name=name, type=result.types[i], needed=result.needed[i], at=result.at[i],
            at_configuration=dict(zip(result.names, result.at_configuration[i])), effort=effort, mimic_of=mimic))
    return check


def _compute(model: Model, samples: int, seed: int) -> _Needed:
    """In the pybullet child: the inverse dynamics at every configuration."""
    import numpy as np

    from ar3cli.sim.sampling import joint_space, limit_configurations, sample_configurations
    from ar3cli.sim.session import Session

    with Session(gravity=GRAVITY) as session:
        body = session.load(model, fixed_base=True, visuals=False, leave_out_unloadable=True)
        p, client = session.p, session.client
        multi = [joint.name for joint in body.joints if joint.urdf_type in ("spherical", "planar", "floating")
                 and p.getJointInfo(body.id, joint.index, physicsClientId=client)[2] != p.JOINT_FIXED]
        if multi:
            raise UserError(f"{model.path}: --torques handles 1-DOF joints only; pybullet moves "
                            f"{listed(multi)} with several degrees of freedom")
        joints = body.actuated_joints
        if not joints:
            return _Needed([], [], [], [], [], 0)
        space = joint_space(body)
        limits = limit_configurations(space)
        labels = [label for label, _ in limits] + [f"sample {i}" for i in range(samples)]
        rows = [row for _, row in limits]
        if samples:
            rows += list(sample_configurations(space, samples, seed))
        configurations = np.asarray(rows, dtype=float)
        zeros = [0.0] * len(joints)
        torques = np.empty_like(configurations)
        with capture_fds():  # pybullet's inverse dynamics prints a b3Warning per non-unit axis, per call
            for k, q in enumerate(configurations):
                try:
                    tau = p.calculateInverseDynamics(body.id, [float(v) for v in q], zeros, zeros,
                                                     physicsClientId=client)
                except (p.error, SystemError) as exc:  # SystemError: pybullet's C code on absurd masses (1e30 kg)
                    raise UserError(f"{model.path}: pybullet's inverse dynamics failed ({exc})") from None
                torques[k] = tau
        magnitude = np.abs(torques)
        needed = magnitude.max(axis=0)
        needed[needed < NEGLIGIBLE] = 0.0
        # The first configuration within TIE of the largest wins: home comes first, so a torque that
        # is the same everywhere (a vertical prismatic joint) is reported at home, not at float noise.
        worst = (magnitude >= needed * (1.0 - TIE)).argmax(axis=0)
        at = [labels[i] if needed[j] > 0 else ANY for j, i in enumerate(worst)]
        worst[needed == 0] = 0
        return _Needed(
            names=[joint.name for joint in joints], types=[joint.urdf_type for joint in joints],
            at=at, at_configuration=[configurations[i].tolist() for i in worst],
            needed=[float(v) for v in needed], limit_configurations=len(limits))
