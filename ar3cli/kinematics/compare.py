"""PyBullet's link frames against the independent URDF forward kinematics.

The configurations are set in PyBullet (``resetJointState``) and the *link frames* are read
(``getLinkState(...)[4:6]``, via :meth:`ar3cli.sim.session.Body.link_frames`), then the same frames are
computed by :func:`ar3cli.kinematics.fk.urdf_link_frames` from the Model. Differences that real
models produce are explained by :func:`model_notes`: mimic joints (pybullet does not couple them, so
we set the mimic joint's value ourselves), non-unit axes (pybullet normalises revolute axes but
moves prismatic joints by ``|axis| * q``), and the base pose being the COM in pybullet.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.kinematics import fk as kinematics
from ar3cli.urdf.mimic import driven_values
from ar3cli.urdf.model import Model


@dataclass
class Samples:
    """N configurations: ``values[:, i]`` drives ``names[i]``; ``all_values`` adds the mimic joints."""

    seed: int
    names: list[str]
    values: np.ndarray
    all_values: dict[str, np.ndarray]

    @property
    def count(self) -> int:
        return int(self.values.shape[0])

    def configuration(self, index: int) -> dict[str, float]:
        """One sample as {joint: value} (driving joints only), for reports."""
        return {name: float(self.values[index, i]) for i, name in enumerate(self.names)}


@dataclass
class LinkError:
    """Errors of one link frame over all samples.

    ``position_errors`` and ``reaches`` hold one value per sample: the reach is how far from the
    world origin the link or one of its ancestors is in that sample (m), which bounds pybullet's
    single-precision rounding there (see :class:`ar3cli.kinematics.verify.Tolerance`).
    """

    link: str
    max_position: float
    mean_position: float
    max_orientation: float
    mean_orientation: float
    worst_sample: int
    position_errors: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    reaches: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)

    @property
    def max_reach(self) -> float:
        return float(self.reaches.max()) if self.reaches.size else 0.0

    def to_dict(self) -> dict[str, Any]:
        return {"link": self.link, "max_position_error_m": self.max_position,
                "mean_position_error_m": self.mean_position, "max_orientation_error_rad": self.max_orientation,
                "mean_orientation_error_rad": self.mean_orientation, "worst_sample": self.worst_sample,
                "max_reach_m": self.max_reach}


@dataclass
class Comparison:
    """Per-link errors, the explaining notes, and the independent frames (reused by the DH check)."""

    links: list[LinkError]
    notes: list[str] = field(default_factory=list)
    reference: dict[str, np.ndarray] = field(default_factory=dict)
    left_out: list = field(default_factory=list)
    """The shapes loaded without (:class:`~ar3cli.sim.loadable_copy.LeftOut`: a mesh not found); frames need no mesh."""


def draw_samples(model: Model, body, count: int, seed: int) -> Samples:
    """Uniform samples of the driving joints (:mod:`ar3cli.sim.sampling`); mimic joints follow.

    Ranges come from :meth:`ar3cli.sim.session.JointRecord.sample_range`, i.e. the URDF's limits.
    """
    from ar3cli.sim import sampling

    space = sampling.joint_space(body)
    values = sampling.sample_driving(space, count, seed)
    names = list(space.driving_names)
    all_values = driven_values(model, {n: values[:, i] for i, n in enumerate(names)}, count)
    return Samples(seed=seed, names=names, values=values, all_values=all_values)


def body_configurations(body, samples: Samples) -> np.ndarray:
    """(N, movable joints) values in :attr:`~ar3cli.sim.session.Body.actuated_joints` order, mimic joints included."""
    names = [joint.name for joint in body.actuated_joints]
    if not names:
        return np.zeros((samples.count, 0))
    return np.stack([samples.all_values[name] for name in names], axis=1)


def pybullet_frames(body, samples: Samples) -> dict[str, np.ndarray]:
    """(N, 4, 4) world link frames per link from pybullet, every joint (mimic ones too) set explicitly."""
    poses = []
    for number, q in enumerate(body_configurations(body, samples)):
        body.set_positions(q)
        frames = body.link_frames()
        broken = body.nonfinite_links(frames)
        if broken:
            raise UserError(f"{body.model.path}: pybullet computes non-finite (NaN) frames for "
                            f"{listed(broken)} in sample {number} (seed {samples.seed}); no comparison is possible")
        poses.append([frames[link] for link in body.link_names])
    return frames_from_poses(body.link_names, poses)


def frames_from_poses(links: list[str], poses) -> dict[str, np.ndarray]:
    """{link: (N, 4, 4)} from ``poses[n][i]`` = (position, quaternion xyzw) of ``links[i]`` in sample n."""
    count = len(poses)
    positions = np.array([[pose[0] for pose in row] for row in poses], dtype=float).reshape(count, len(links), 3)
    quaternions = np.array([[pose[1] for pose in row] for row in poses], dtype=float).reshape(count, len(links), 4)
    result = {}
    for i, link in enumerate(links):
        frames = np.tile(np.eye(4), (count, 1, 1))
        frames[:, :3, :3] = kinematics.quaternion_matrices(quaternions[:, i])
        frames[:, :3, 3] = positions[:, i]
        result[link] = frames
    return result


def compare_links(reference: dict[str, np.ndarray], measured: dict[str, np.ndarray],
                  parents: dict[str, str] | None = None) -> list[LinkError]:
    """Per-link max/mean errors for links present in both, in ``measured`` order.

    ``parents`` (child link -> parent link) lets each link's reach include its ancestors'.
    """
    reaches = link_reaches(reference, parents or {})
    errors = []
    for link, frames in measured.items():
        if link not in reference:
            continue
        position, angle = kinematics.pose_errors(reference[link], frames)
        worst = int(np.argmax(position / max(float(position.max()), 1e-300)
                              + angle / max(float(angle.max()), 1e-300)))
        errors.append(LinkError(link, float(position.max()), float(position.mean()), float(angle.max()),
                                float(angle.mean()), worst, position, reaches[link]))
    return errors


def link_reaches(reference: dict[str, np.ndarray], parents: dict[str, str]) -> dict[str, np.ndarray]:
    """Per link, per sample: the largest distance from the world origin of the link or an ancestor (m).

    pybullet composes the frames in single precision from the base out, so a link's rounding error
    grows with the largest coordinate met along its chain (a mobile base 20 m out, an arm folded
    back to the origin), not only with its own position.
    """
    reaches: dict[str, np.ndarray] = {}
    for link in reference:
        chain: list[str] = []  # the link and its ancestors not yet measured, child first (iterative: chains can be long)
        node: str | None = link
        while node is not None and node in reference and node not in reaches and node not in chain:
            chain.append(node)
            node = parents.get(node)
        above = reaches.get(node) if node is not None else None
        for name in reversed(chain):
            own = np.linalg.norm(reference[name][..., :3, 3], axis=-1)
            above = own if above is None else np.maximum(own, above)
            reaches[name] = above
    return reaches


def model_notes(model: Model, body) -> list[str]:
    """Sentences explaining where pybullet and the URDF spec differ for this model."""
    notes = []
    for joint in model.joints:
        if joint.mimic is not None and joint.moves:
            notes.append(f"joint {joint.name} mimics {joint.mimic.joint} (x{joint.mimic.multiplier:g} "
                         f"{joint.mimic.offset:+g}): pybullet does not enforce <mimic>, so fk-verify sets it "
                         "explicitly; a controller must do the same (or add a gear constraint)")
        norm = float(np.linalg.norm(joint.axis))
        if joint.moves and joint.axis_given and norm > 0 and abs(norm - 1.0) > 1e-9:
            if joint.type == "prismatic":
                notes.append(f"joint {joint.name} has a non-unit axis {joint.axis} (length {norm:g}): the URDF "
                             f"spec normalises it, but pybullet moves the joint {norm:g} x q along it, so its "
                             "child links disagree; write a unit axis")
            else:
                notes.append(f"joint {joint.name} has a non-unit axis {joint.axis} (length {norm:g}): pybullet "
                             "and the URDF spec both normalise revolute axes; write a unit axis anyway")
    root = model.root_link
    if root.inertial is not None and any(abs(v) > 0 for v in (*root.inertial.origin.xyz, *root.inertial.origin.rpy)):
        notes.append(f"root link {root.name} has an inertial origin {root.inertial.origin.xyz}: pybullet's base "
                     "position (getBasePositionAndOrientation) is the COM, not the link frame; fk-verify undoes "
                     "the offset (a floating-base controller must too)")
    missing = [link.name for link in model.links if link.name not in body.link_index]
    if missing:
        notes.append(f"links not present in pybullet (merged or disconnected): {listed(missing)}")
    return notes


def compare(model: Model, body, samples: Samples) -> Comparison:
    """Run both FKs over ``samples`` and measure every link."""
    reference = kinematics.urdf_link_frames(model, samples.all_values, samples.count)
    measured = pybullet_frames(body, samples)
    parents = {joint.child: joint.parent for joint in model.joints if joint.child and joint.parent}
    return Comparison(links=compare_links(reference, measured, parents), notes=model_notes(model, body),
                      reference=reference)
