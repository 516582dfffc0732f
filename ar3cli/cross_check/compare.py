"""PyBullet against MuJoCo, quantity by quantity: rows of differences, each against its own tolerance,
with a diagnosis where the cause is known.

Tolerances scale with the quantity, as fk-verify's do: ``max(floor, k * float32 epsilon * magnitude)``.
Measured on pybullet_data's kuka_iiwa (home + 5 samples): frames agree to 8e-8 m (PyBullet's float32
link states) and to 1e-7 rad once the angle is taken from the quaternion difference (the arccos of a
float32 dot product reads 3.7e-4 rad of rounding); mass matrices to 5e-15 and gravity torques to
4e-14 (both engines compute these in double).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ar3cli.cross_check.measure import EngineData, Plan
from ar3cli.findings import listed
from ar3cli.urdf.model import Model

FLOAT32_EPSILON = 2.0 ** -23
"""PyBullet reports link frames in single precision (see fk-verify's tolerance)."""
EPSILONS = 4.0
"""k in ``max(floor, k * FLOAT32_EPSILON * magnitude)`` for every quantity."""
POSITION_FLOOR = 1e-6
"""m: frames and centres of mass."""
ANGLE_FLOOR = 1e-5
"""rad: link orientations (float32 quaternions give ~1e-7 rad)."""
MASS_FLOOR = 1e-9
"""kg, kg m^2 and N m: masses, mass-matrix entries and gravity torques."""
CONSTRAINT_SHARE = 0.25
"""A follower moves differently under the constraint probe when the engines disagree by more than this
share of the leader's step: a mimic follower moves by the whole step (times its multiplier) in the
engine that enforces it, by nothing in the other."""


@dataclass(frozen=True)
class Row:
    """One compared value: where, both engines' values, the difference, its tolerance, and a diagnosis."""

    quantity: str
    where: str
    pybullet: float
    mujoco: float
    difference: float
    tolerance: float
    diagnosis: str = ""

    @property
    def ratio(self) -> float:
        return self.difference / self.tolerance if self.tolerance > 0 else math.inf

    @property
    def agrees(self) -> bool:
        return self.difference <= self.tolerance

    def to_dict(self) -> dict[str, Any]:
        return {"quantity": self.quantity, "where": self.where, "pybullet": self.pybullet, "mujoco": self.mujoco,
                "difference": self.difference, "tolerance": self.tolerance, "agrees": self.agrees,
                "diagnosis": self.diagnosis}


def scaled(floor: float, magnitude: float) -> float:
    return max(floor, EPSILONS * FLOAT32_EPSILON * abs(magnitude))


def compare(model: Model, plan: Plan, pb: EngineData, mj: EngineData) -> list[Row]:
    """Every compared value (the worst per quantity and place), worst first by how far past its tolerance."""
    rows = [*_frames(plan, pb, mj), *_masses(model, pb, mj), *_dynamics(model, plan, pb, mj),
            *_constraints(model, plan, pb, mj)]
    return sorted(_consequences(rows), key=lambda row: -row.ratio)


def _consequences(rows: list[Row]) -> list[Row]:
    """Undiagnosed mass, centre-of-mass and dynamics rows that follow from a link mass the engines disagree on."""
    import dataclasses

    links = [row.where for row in rows if row.quantity == "link mass (kg)" and not row.agrees]
    if not links:
        return rows
    cause = "follows from the link masses the engines disagree on (" + ", ".join(links[:3]) + \
        (" ..." if len(links) > 3 else "") + ")"
    following = ("total mass (kg)", "centre of mass (m)", "mass matrix entry", "gravity torque (N m)")
    return [dataclasses.replace(row, diagnosis=cause) if row.quantity in following and not row.agrees
            and not row.diagnosis else row for row in rows]


def _angle(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    """Geodesic angle between two xyzw quaternions, from their difference (well conditioned near 0)."""
    sign = 1.0 if sum(x * y for x, y in zip(a, b)) >= 0 else -1.0
    chord = math.sqrt(sum((x - sign * y) ** 2 for x, y in zip(a, b)))
    return 4.0 * math.asin(min(1.0, chord / 2.0))


def _frames(plan: Plan, pb: EngineData, mj: EngineData) -> list[Row]:
    worst: dict[str, tuple[Row, Row]] = {}
    for (label, _), frames_pb, frames_mj in zip(plan.configurations, pb.frames, mj.frames):
        for link, (position, orientation) in frames_pb.items():
            if link not in frames_mj:
                continue
            other_position, other_orientation = frames_mj[link]
            distance = math.dist(position, other_position)
            reach = max(math.hypot(*position), math.hypot(*other_position))
            where = f"link '{link}' at {label}"
            pos = Row("frame position (m)", where, math.hypot(*position), math.hypot(*other_position), distance,
                      scaled(POSITION_FLOOR, reach))
            ang = Row("frame orientation (rad)", where, 0.0, 0.0, _angle(orientation, other_orientation), ANGLE_FLOOR)
            best = worst.get(link)
            worst[link] = (pos if best is None or pos.ratio > best[0].ratio else best[0],
                           ang if best is None or ang.ratio > best[1].ratio else best[1])
    return [row for pair in worst.values() for row in pair]


def _masses(model: Model, pb: EngineData, mj: EngineData) -> list[Row]:
    rows = [Row("total mass (kg)", "robot", pb.mass, mj.mass, abs(pb.mass - mj.mass), scaled(MASS_FLOOR, pb.mass))]
    for link, mass in pb.link_masses.items():
        if link in mj.link_masses:
            other = mj.link_masses[link]
            rows.append(Row("link mass (kg)", f"link '{link}'", mass, other, abs(mass - other),
                            scaled(MASS_FLOOR, max(mass, other)), _mass_diagnosis(model, link, mass, other)))
    for (label, _), com_pb, com_mj in zip([("home", None)] + [(f"sample {i}", None) for i in range(1, len(pb.com))],
                                          pb.com, mj.com):
        rows.append(Row("centre of mass (m)", f"robot at {label}", math.hypot(*com_pb), math.hypot(*com_mj),
                        math.dist(com_pb, com_mj), scaled(POSITION_FLOOR, math.hypot(*com_pb))))
    return rows


def _mass_diagnosis(model: Model, link: str, mass_pb: float, mass_mj: float) -> str:
    found = model.link(link)
    if found is not None and found.inertial is None:
        mujoco = (f"MuJoCo computes {mass_mj:.4g} kg from its collision geometry at 1000 kg/m3" if mass_mj > 0 else
                  "MuJoCo gives it none (no collision geometry; allowed on a body that moves with its parent)")
        return f"link '{link}' has no <inertial>: PyBullet gives it {mass_pb:g} kg, {mujoco}; give it an <inertial>"
    return ""


def _dynamics(model: Model, plan: Plan, pb: EngineData, mj: EngineData) -> list[Row]:
    import numpy as np

    index = [pb.joints.index(name) for name in mj.joints]
    if not index or not any(pb.mass_matrix):
        return []
    rows = []
    armature = {n: a for n, a in mj.extra.get("armature", {}).items() if a}
    hint = ("MuJoCo adds joint armature (" + listed(f"'{n}' {a:g}" for n, a in armature.items())
            + ") to the mass matrix; PyBullet has none") if armature else ""
    for (label, _), m_pb, m_mj, g_pb, g_mj in zip(plan.configurations, pb.mass_matrix, mj.mass_matrix,
                                                  pb.gravity, mj.gravity):
        a = np.asarray(m_pb, dtype=float)[np.ix_(index, index)]
        b = np.asarray(m_mj, dtype=float)
        difference = np.abs(a - b)
        i, j = np.unravel_index(int(np.argmax(difference)), difference.shape)
        rows.append(Row("mass matrix entry", f"({mj.joints[i]}, {mj.joints[j]}) at {label}", float(a[i, j]),
                        float(b[i, j]), float(difference[i, j]), scaled(MASS_FLOOR, float(np.abs(a).max())),
                        hint or _inertia_hint(model)))
        ga, gb = np.asarray(g_pb, dtype=float)[index], np.asarray(g_mj, dtype=float)
        k = int(np.argmax(np.abs(ga - gb)))
        rows.append(Row("gravity torque (N m)", f"joint '{mj.joints[k]}' at {label}", float(ga[k]), float(gb[k]),
                        float(abs(ga[k] - gb[k])), scaled(MASS_FLOOR, float(np.abs(ga).max())), _inertia_hint(model)))
    return rows


def _inertia_hint(model: Model) -> str:
    """Links whose inertial frame is rotated: the first place two engines read an inertia differently."""
    rotated = [link.name for link in model.links if link.inertial is not None and any(link.inertial.origin.rpy)]
    if not rotated:
        return ""
    return ("inertia frame read differently? links with a rotated <inertial><origin rpy>: "
            + ", ".join(f"'{name}'" for name in rotated[:3]) + (" ..." if len(rotated) > 3 else ""))


def _constraints(model: Model, plan: Plan, pb: EngineData, mj: EngineData) -> list[Row]:
    rows = []
    for leader, step in plan.steps.items():
        moved_pb, moved_mj = pb.driven.get(leader, {}), mj.driven.get(leader)
        if moved_mj is None:
            continue
        for joint in mj.joints:
            if joint == leader or joint not in plan.followers:
                continue  # held at home by the probe in both engines: only the kinematic coupling is compared
            a, b = moved_pb.get(joint, 0.0), moved_mj.get(joint, 0.0)
            rows.append(Row("constraint: joint moved when driving", f"'{joint}' when '{leader}' moves {step:+g}",
                            a, b, abs(a - b), CONSTRAINT_SHARE * abs(step), _mimic_diagnosis(model, joint, a, b)))
    return rows


def _mimic_diagnosis(model: Model, joint: str, moved_pb: float, moved_mj: float) -> str:
    found = model.joint(joint)
    if found is None or found.mimic is None:
        return ""
    enforcing, ignoring = ("MuJoCo", "PyBullet") if abs(moved_mj) > abs(moved_pb) else ("PyBullet", "MuJoCo")
    return (f"joint '{joint}' mimics '{found.mimic.joint}' (<mimic> at line {found.mimic.element.sourceline}): "
            f"{enforcing} enforces it (equality constraint), {ignoring} ignores it (the follower stays free)")
