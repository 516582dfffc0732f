"""Vectorised forward kinematics, independent of any simulator.

Two ways to place frames, both batched over N configurations (arrays of shape ``(N, 4, 4)``):

- :func:`urdf_link_frames` walks the URDF tree of a :class:`~ar3cli.urdf.model.Model` the way the URDF
  spec says: joint origin (xyz, then rpy as ``Rz(yaw) Ry(pitch) Rx(roll)``, or URDF 1.1's normalised
  ``quat_xyzw``: the Origin's exact rotation matrix), then the motion about
  the **normalised** axis (rotation for revolute/continuous, translation for prismatic); mimic
  joints take ``multiplier * q[mimicked] + offset``.
- :func:`dh_frames` chains Denavit-Hartenberg rows, standard (``Rz Tz Tx Rx``) or modified/Craig
  (``Rx Tx Rz Tz``).

:func:`pose_errors` measures two batches of frames against each other: the position distance and
the geodesic angle of ``R_a^T R_b``, computed with ``atan2(sin, cos)`` so that tiny angles keep
their precision (``acos`` of the trace cannot resolve anything below ~1e-8 rad).
Only numpy is imported here: this module is also the FK hot path.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ar3cli.errors import UserError
from ar3cli.maths.mass_properties import rpy_to_matrix as rpy_matrix  # Rz(yaw) Ry(pitch) Rx(roll)
from ar3cli.maths.tensor_math import matrix_to_rpy
from ar3cli.urdf.mimic import driven_values
from ar3cli.urdf.model import ACTUATED_JOINT_TYPES, ROTATING_JOINT_TYPES, Joint, Model

SUPPORTED_TYPES = (*ACTUATED_JOINT_TYPES, "fixed")
"""Joint types the URDF forward kinematics here can place (not planar, floating or spherical)."""


def matrix_rpy(rotation: np.ndarray) -> tuple[float, float, float]:
    """Inverse of ``rpy_matrix`` (URDF rpy from a rotation; pitch in [-pi/2, pi/2], exact at gimbal lock)."""
    return matrix_to_rpy(rotation)


def transform(xyz: Sequence[float] = (0.0, 0.0, 0.0), rpy: Sequence[float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """4x4 homogeneous transform from a URDF-style ``xyz`` / ``rpy``."""
    result = np.eye(4)
    result[:3, :3] = rpy_matrix(rpy)
    result[:3, 3] = xyz
    return result


def invert(frames: np.ndarray) -> np.ndarray:
    """Inverse of rigid transforms (``(..., 4, 4)``) without a general matrix inverse."""
    result = np.zeros_like(frames)
    rotation_t = np.swapaxes(frames[..., :3, :3], -1, -2)
    result[..., :3, :3] = rotation_t
    result[..., :3, 3] = -np.einsum("...ij,...j->...i", rotation_t, frames[..., :3, 3])
    result[..., 3, 3] = 1.0
    return result


def axis_rotations(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Batched Rodrigues rotation about a unit ``axis`` by ``angles`` (N,) -> (N, 4, 4)."""
    x, y, z = axis
    c, s = np.cos(angles), np.sin(angles)
    t = 1.0 - c
    result = np.zeros((len(angles), 4, 4))
    result[:, 0, 0] = c + x * x * t
    result[:, 0, 1] = x * y * t - z * s
    result[:, 0, 2] = x * z * t + y * s
    result[:, 1, 0] = y * x * t + z * s
    result[:, 1, 1] = c + y * y * t
    result[:, 1, 2] = y * z * t - x * s
    result[:, 2, 0] = z * x * t - y * s
    result[:, 2, 1] = z * y * t + x * s
    result[:, 2, 2] = c + z * z * t
    result[:, 3, 3] = 1.0
    return result


def unit_axis(joint: Joint) -> np.ndarray:
    """The joint axis normalised, as the URDF spec asks; a zero axis is a UserError."""
    axis = np.asarray(joint.axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    if not np.isfinite(norm) or norm == 0.0:
        raise UserError(f"joint {joint.name!r} (line {joint.line}) has axis {joint.axis}, which has no direction; "
                        "give a non-zero <axis xyz>")
    return axis / norm


def joint_motion(joint: Joint, values: np.ndarray) -> np.ndarray:
    """(N, 4, 4) motion of ``joint`` at ``values`` in its own frame (after its origin)."""
    if joint.type in ROTATING_JOINT_TYPES:
        return axis_rotations(unit_axis(joint), values)
    motion = np.tile(np.eye(4), (len(values), 1, 1))
    if joint.type == "prismatic":
        motion[:, :3, 3] = np.outer(values, unit_axis(joint))
    return motion


def tree_order(model: Model) -> list[Joint]:
    """Joints in parent-before-child order from the single root link.

    Each link is entered once: a joint leading back to a link already reached (a loop, lint's
    S-rules) is left out instead of looping forever. Children are grouped by parent in one pass,
    so a long chain costs O(joints), not O(links x joints).
    """
    children: dict[str | None, list[Joint]] = {}
    for joint in model.joints:
        children.setdefault(joint.parent, []).append(joint)
    order: list[Joint] = []
    root = model.root_link.name
    seen = {root}
    stack = [root]
    while stack:
        link = stack.pop()
        for joint in reversed(children.get(link, [])):
            if joint.child is None or joint.child in seen:
                continue
            seen.add(joint.child)
            order.append(joint)
            stack.append(joint.child)
    return order


def urdf_link_frames(model: Model, positions: Mapping[str, np.ndarray], count: int) -> dict[str, np.ndarray]:
    """World frame of every link, (N, 4, 4), with the root link at the identity.

    ``positions`` maps joint names to (N,) arrays; missing movable joints are 0 and mimic joints
    follow their source joint. Unsupported joint types (floating, planar) are a UserError.
    """
    values = driven_values(model, positions, count)
    frames = {model.root_link.name: np.tile(np.eye(4), (count, 1, 1))}
    for joint in tree_order(model):
        if joint.type not in SUPPORTED_TYPES:
            raise UserError(f"joint {joint.name!r} (line {joint.line}) is of type {joint.type!r}; fk-verify handles "
                            "revolute, continuous, prismatic and fixed joints")
        if joint.parent not in frames or joint.child is None:
            continue
        origin = np.eye(4)
        origin[:3, :3] = joint.origin.rotation
        origin[:3, 3] = joint.origin.xyz
        parent_origin = frames[joint.parent] @ origin
        if joint.type == "fixed":
            frames[joint.child] = parent_origin
        else:
            frames[joint.child] = parent_origin @ joint_motion(joint, values[joint.name])
    return frames


# ---- Denavit-Hartenberg ------------------------------------------------------------------------

@dataclass(frozen=True)
class DHRow:
    """One DH row in SI units: the joint drives theta (revolute) or d (prismatic).

    Revolute: ``theta = sign * q + theta_offset``; prismatic: ``d = d + sign * q``.
    For the modified convention ``a``/``alpha`` are Craig's ``a_{i-1}``/``alpha_{i-1}``.
    """

    joint: str
    a: float
    alpha: float
    d: float
    theta_offset: float
    sign: float = 1.0
    prismatic: bool = False


def _rot_z(theta: np.ndarray) -> np.ndarray:
    result = np.zeros((len(theta), 4, 4))
    c, s = np.cos(theta), np.sin(theta)
    result[:, 0, 0], result[:, 0, 1], result[:, 1, 0], result[:, 1, 1] = c, -s, s, c
    result[:, 2, 2] = result[:, 3, 3] = 1.0
    return result


def _tx_rx(a: float, alpha: float) -> np.ndarray:
    """``Tx(a) Rx(alpha)``: the constant half of a DH row."""
    c, s = np.cos(alpha), np.sin(alpha)
    return np.array([[1.0, 0.0, 0.0, a], [0.0, c, -s, 0.0], [0.0, s, c, 0.0], [0.0, 0.0, 0.0, 1.0]])


def dh_row_transforms(row: DHRow, q: np.ndarray, convention: str) -> np.ndarray:
    """(N, 4, 4) transform of one row at joint values ``q`` (N,)."""
    if row.prismatic:
        theta, d = np.full(len(q), row.theta_offset), row.d + row.sign * q
    else:
        theta, d = row.sign * q + row.theta_offset, np.full(len(q), row.d)
    translate_z = np.tile(np.eye(4), (len(q), 1, 1))
    translate_z[:, 2, 3] = d
    if convention == "standard":  # Rz(theta) Tz(d) Tx(a) Rx(alpha)
        return _rot_z(theta) @ translate_z @ _tx_rx(row.a, row.alpha)
    return _tx_rx(row.a, row.alpha) @ _rot_z(theta) @ translate_z  # Rx(alpha) Tx(a) Rz Tz


def dh_frames(rows: Sequence[DHRow], q: np.ndarray, convention: str, base: np.ndarray | None = None) -> list[np.ndarray]:
    """DH frames 0..n, each (N, 4, 4); frame 0 is ``base`` (the base offset), q is (N, n)."""
    count = q.shape[0]
    frame = np.tile(base if base is not None else np.eye(4), (count, 1, 1))
    frames = [frame]
    for index, row in enumerate(rows):
        frame = frame @ dh_row_transforms(row, q[:, index], convention)
        frames.append(frame)
    return frames


# ---- comparing frames --------------------------------------------------------------------------

def quaternion_matrices(quaternions: np.ndarray) -> np.ndarray:
    """(N, 3, 3) rotations from (N, 4) quaternions in pybullet's (x, y, z, w) order (normalised first)."""
    q = np.asarray(quaternions, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def rotation_angles(rotations: np.ndarray) -> np.ndarray:
    """Angle of each rotation (..., 3, 3) in [0, pi]: ``atan2(|skew|, (trace - 1) / 2)``, stable near 0."""
    skew = np.stack([rotations[..., 2, 1] - rotations[..., 1, 2], rotations[..., 0, 2] - rotations[..., 2, 0],
                     rotations[..., 1, 0] - rotations[..., 0, 1]], -1)
    sine = 0.5 * np.linalg.norm(skew, axis=-1)
    cosine = 0.5 * (np.trace(rotations, axis1=-2, axis2=-1) - 1.0)
    return np.arctan2(sine, cosine)


def pose_errors(frames_a: np.ndarray, frames_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame position distance (m) and geodesic orientation angle (rad) between two batches."""
    position = np.linalg.norm(frames_a[..., :3, 3] - frames_b[..., :3, 3], axis=-1)
    relative = np.swapaxes(frames_a[..., :3, :3], -1, -2) @ frames_b[..., :3, :3]
    return position, rotation_angles(relative)


def spread(frames: np.ndarray) -> tuple[float, float]:
    """How far a batch of transforms is from being one constant transform: max (m, rad) from the first."""
    if len(frames) == 0:
        return 0.0, 0.0
    position, angle = pose_errors(frames[:1], frames)
    return float(position.max()), float(angle.max())


def xyz_rpy(frame: np.ndarray) -> tuple[list[float], list[float]]:
    """A single 4x4 transform as URDF-style xyz and rpy lists."""
    return [float(v) for v in frame[:3, 3]], list(matrix_rpy(frame[:3, :3]))
