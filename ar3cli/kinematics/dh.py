"""DH tables: read and validate the YAML, compare the chain with the URDF, diagnose disagreements.

The file format (see ``docs/commands/fk-verify.md``)::

    convention: standard            # or modified (Craig)
    base: base_link                 # URDF link where DH frame 0 sits (after base_offset)
    tip: link_6                     # URDF link whose frame the chain must reproduce (after tool)
    units: {length: m, angle: rad}  # or mm / deg
    base_offset: {xyz: [0, 0, 0], rpy: [0, 0, 0]}
    tool: {xyz: [0, 0, 0], rpy: [0, 0, 0]}
    joints:
      - {joint: joint_1, a: 0.0642, alpha: -1.5708, d: 0.16977, theta_offset: 0, sign: 1}

Every problem with the file is a one-line :class:`~ar3cli.errors.UserError` naming the file.
Diagnoses try one repair at a time (units, a constant tool/base offset, a flipped sign, one
parameter of one row) and report those that make the chain agree with the URDF.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.kinematics import fk as kinematics
from ar3cli.kinematics.fk import DHRow
from ar3cli.urdf.model import Joint, Model

LENGTH_UNITS = {"m": 1.0, "mm": 1e-3}
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}
CONVENTIONS = ("standard", "modified")
ROW_KEYS = {"joint", "a", "alpha", "d", "theta_offset", "sign"}
TOP_KEYS = {"convention", "base", "tip", "units", "base_offset", "tool", "joints"}
ANGLE_FIELDS = ("alpha", "theta_offset")


@dataclass(frozen=True)
class DHTable:
    """A validated DH table in SI units, plus the numbers as typed (for re-reading in other units)."""

    path: Path
    convention: str
    base: str
    tip: str
    length_unit: str
    angle_unit: str
    raw_rows: tuple[Mapping[str, float], ...]
    raw_base_offset: tuple[tuple[float, ...], tuple[float, ...]]
    raw_tool: tuple[tuple[float, ...], tuple[float, ...]]
    chain: tuple[Joint, ...]

    @property
    def rows(self) -> list[DHRow]:
        length, angle = LENGTH_UNITS[self.length_unit], ANGLE_UNITS[self.angle_unit]
        return [DHRow(joint=str(raw["joint"]), a=raw["a"] * length, alpha=raw["alpha"] * angle, d=raw["d"] * length,
                      theta_offset=raw["theta_offset"] * angle,
                      sign=raw["sign"], prismatic=joint.type == "prismatic")
                for raw, joint in zip(self.raw_rows, self.chain)]

    def _pose(self, raw: tuple[tuple[float, ...], tuple[float, ...]]) -> np.ndarray:
        xyz = [v * LENGTH_UNITS[self.length_unit] for v in raw[0]]
        rpy = [v * ANGLE_UNITS[self.angle_unit] for v in raw[1]]
        return kinematics.transform(xyz, rpy)

    @property
    def base_offset(self) -> np.ndarray:
        return self._pose(self.raw_base_offset)

    @property
    def tool(self) -> np.ndarray:
        return self._pose(self.raw_tool)

    def with_row(self, index: int, **changes: float) -> DHTable:
        rows = list(self.raw_rows)
        rows[index] = {**rows[index], **changes}
        return dataclasses.replace(self, raw_rows=tuple(rows))


# ---- reading ------------------------------------------------------------------------------------

def load_dh(path: Path, model: Model) -> DHTable:
    """Read and validate a DH YAML file against ``model``; every problem is a one-line UserError."""
    from ar3cli.urdf.yamlfile import load_yaml

    where = str(path)
    document = load_yaml(path, "DH file")
    if not isinstance(document, dict):
        raise UserError(f"{where}: DH file must be a YAML mapping with convention, base, tip and joints")
    unknown = sorted(set(map(str, document)) - TOP_KEYS)
    if unknown:
        raise UserError(f"{where}: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(sorted(TOP_KEYS))}")
    for key in ("convention", "base", "tip", "joints"):
        if key not in document:
            raise UserError(f"{where}: missing required key {key!r}")
    convention = str(document["convention"]).lower()
    if convention == "craig":
        convention = "modified"
    if convention not in CONVENTIONS:
        raise UserError(f"{where}: convention is {document['convention']!r}; use standard or modified")
    length_unit, angle_unit = _units(document.get("units"), where)
    base, tip = str(document["base"]), str(document["tip"])
    for role, name in (("base", base), ("tip", tip)):
        if model.link(name) is None:
            raise UserError(f"{where}: {role} link {name!r} is not a link of {model.path.name}")
    chain = chain_joints(model, base, tip, where)
    movable = [joint for joint in chain if joint.type != "fixed"]
    if not movable:
        raise UserError(f"{where}: the chain {base} -> {tip} has no movable joint, so there is nothing for a DH "
                        "table to describe; choose base and tip links with joints between them")
    rows = document["joints"]
    if not isinstance(rows, list):
        raise UserError(f"{where}: joints must be a list of rows")
    if len(rows) != len(movable):
        raise UserError(f"{where}: {len(rows)} DH row(s), but the chain {base} -> {tip} has {len(movable)} movable "
                        f"joint(s) ({listed(j.name for j in movable)})")
    raw_rows = tuple(_row(row, index, where, model, movable) for index, row in enumerate(rows))
    return DHTable(path=Path(path), convention=convention, base=base, tip=tip, length_unit=length_unit,
                   angle_unit=angle_unit, raw_rows=raw_rows,
                   raw_base_offset=_pose(document.get("base_offset"), "base_offset", where),
                   raw_tool=_pose(document.get("tool"), "tool", where), chain=tuple(movable))


def chain_joints(model: Model, base: str, tip: str, where: str = "") -> list[Joint]:
    """Joints from ``base`` down to ``tip`` (fixed ones included), base first."""
    joints: list[Joint] = []
    link = tip
    seen = set()
    while link != base:
        joint = model.parent_joint(link)
        if joint is None or link in seen:
            raise UserError(f"{where}: tip link {tip!r} is not below base link {base!r} in {model.path.name}")
        seen.add(link)
        joints.append(joint)
        link = joint.parent  # type: ignore[assignment]
    return list(reversed(joints))


def _units(units: Any, where: str) -> tuple[str, str]:
    if units is None:
        return "m", "rad"
    if not isinstance(units, dict) or set(map(str, units)) - {"length", "angle"}:
        raise UserError(f"{where}: units must be {{length: m|mm, angle: rad|deg}}, got {units!r}")
    length, angle = str(units.get("length", "m")), str(units.get("angle", "rad"))
    if length not in LENGTH_UNITS:
        raise UserError(f"{where}: length unit {length!r} is not supported; use m or mm")
    if angle not in ANGLE_UNITS:
        raise UserError(f"{where}: angle unit {angle!r} is not supported; use rad or deg")
    return length, angle


def _number(value: Any, what: str, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(float(value)):
        raise UserError(f"{where}: {what} must be a finite number, got {value!r}")
    return float(value)


def _pose(value: Any, what: str, where: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    if value is None:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    if not isinstance(value, dict) or set(map(str, value)) - {"xyz", "rpy"}:
        raise UserError(f"{where}: {what} must be {{xyz: [x, y, z], rpy: [r, p, y]}}, got {value!r}")
    parts = []
    for key in ("xyz", "rpy"):
        numbers = value.get(key, [0, 0, 0])
        if not isinstance(numbers, list) or len(numbers) != 3:
            raise UserError(f"{where}: {what}.{key} must be a list of 3 numbers, got {numbers!r}")
        parts.append(tuple(_number(v, f"{what}.{key}", where) for v in numbers))
    return parts[0], parts[1]


def _row(row: Any, index: int, where: str, model: Model, movable: list[Joint]) -> dict[str, float]:
    label = f"joints[{index}]"
    if not isinstance(row, dict):
        raise UserError(f"{where}: {label} must be a mapping like {{joint: NAME, a: 0, alpha: 0, d: 0}}")
    unknown = sorted(set(map(str, row)) - ROW_KEYS)
    if unknown:
        raise UserError(f"{where}: {label} has unknown key(s) {', '.join(unknown)}; "
                        f"allowed: {', '.join(sorted(ROW_KEYS))}")
    for key in ("joint", "a", "alpha", "d"):
        if key not in row:
            raise UserError(f"{where}: {label} is missing {key!r}")
    name = str(row["joint"])
    if model.joint(name) is None:
        raise UserError(f"{where}: {label} names joint {name!r}, which is not in {model.path.name}")
    expected = movable[index].name
    if name != expected:
        raise UserError(f"{where}: {label} is joint {name!r}, but joint {index + 1} of the chain is {expected!r} "
                        "(rows go in chain order, base to tip)")
    sign = _number(row.get("sign", 1), f"{label}.sign", where)
    if sign not in (1.0, -1.0):
        raise UserError(f"{where}: {label}.sign must be 1 or -1, got {row['sign']!r}")
    values: dict[str, Any] = {"joint": name, "sign": sign}
    for key in ("a", "alpha", "d", "theta_offset"):
        values[key] = _number(row.get(key, 0.0), f"{label}.{key}", where)
    return values


# ---- evaluating ---------------------------------------------------------------------------------

@dataclass
class Evaluation:
    """URDF and DH frames (relative to the base link) over the samples."""

    urdf_tip: np.ndarray
    dh_tip: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray

    @property
    def max_position(self) -> float:
        return float(self.position_error.max())

    @property
    def max_orientation(self) -> float:
        return float(self.orientation_error.max())

    def within(self, tolerance_m: float, tolerance_rad: float) -> bool:
        return self.max_position <= tolerance_m and self.max_orientation <= tolerance_rad


def joint_matrix(table: DHTable, values: Mapping[str, np.ndarray]) -> np.ndarray:
    """(N, n) joint values of the chain's joints, in row order."""
    return np.stack([np.asarray(values[joint.name], dtype=float) for joint in table.chain], axis=1)


def urdf_relative(frames: Mapping[str, np.ndarray], table: DHTable, link: str) -> np.ndarray:
    """A link's frames expressed in the DH base link."""
    return kinematics.invert(frames[table.base]) @ frames[link]


def evaluate(table: DHTable, urdf_frames: Mapping[str, np.ndarray], q: np.ndarray) -> Evaluation:
    """Compare the table's tip (base_offset, rows, tool) with the URDF tip over the samples."""
    urdf_tip = urdf_relative(urdf_frames, table, table.tip)
    dh_tip = kinematics.dh_frames(table.rows, q, table.convention, table.base_offset)[-1] @ table.tool
    position, angle = kinematics.pose_errors(urdf_tip, dh_tip)
    return Evaluation(urdf_tip, dh_tip, position, angle)


# ---- diagnosing ---------------------------------------------------------------------------------

@dataclass
class Diagnosis:
    """One explanation of a disagreement: ``kind`` is a stable code, ``fix`` what to change."""

    kind: str
    message: str
    fix: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "message": self.message, "fix": self.fix}


def _fmt(values) -> str:
    return " ".join(f"{v:.9g}" for v in values)


def constant_offset(evaluation: Evaluation, tolerance_m: float,
                    tolerance_rad: float) -> tuple[np.ndarray | None, np.ndarray | None]:
    """(tip-side, base-side) offsets when the DH tip differs from the URDF tip by one constant transform."""
    tip_side = kinematics.invert(evaluation.urdf_tip) @ evaluation.dh_tip  # T_urdf^-1 T_dh
    base_side = evaluation.dh_tip @ kinematics.invert(evaluation.urdf_tip)
    result: list[np.ndarray | None] = []
    for offsets in (tip_side, base_side):
        position, angle = kinematics.spread(offsets)
        result.append(offsets[0] if position <= tolerance_m and angle <= tolerance_rad else None)
    return result[0], result[1]


def diagnose(table: DHTable, urdf_frames: Mapping[str, np.ndarray], q: np.ndarray, tolerance_m: float,
             tolerance_rad: float) -> list[Diagnosis]:
    """Explanations for a table whose tip does not match the URDF (empty when it matches)."""
    current = evaluate(table, urdf_frames, q)
    if current.within(tolerance_m, tolerance_rad):
        return []

    def fixes(candidate: DHTable) -> bool:
        return evaluate(candidate, urdf_frames, q).within(tolerance_m, tolerance_rad)

    diagnoses = _unit_diagnoses(table, fixes)
    tool_offset, base_offset = constant_offset(current, tolerance_m, tolerance_rad)
    if tool_offset is not None:
        new_tool = table.tool @ kinematics.invert(tool_offset)
        xyz, rpy = _tidy(kinematics.xyz_rpy(new_tool))
        diagnoses.append(Diagnosis("tool-offset", f"looks like a tool offset of {_fmt(xyz)} m (rpy {_fmt(rpy)} rad), "
                                   f"add it as tool: {{xyz: [{', '.join(f'{v:.9g}' for v in xyz)}], "
                                   f"rpy: [{', '.join(f'{v:.9g}' for v in rpy)}]}} (in m / rad)",
                                   {"tool": {"xyz": xyz, "rpy": rpy}}))
    elif base_offset is not None:
        new_base = kinematics.invert(base_offset) @ table.base_offset
        xyz, rpy = _tidy(kinematics.xyz_rpy(new_base))
        diagnoses.append(Diagnosis("base-offset", f"looks like a base offset of {_fmt(xyz)} m (rpy {_fmt(rpy)} rad), "
                                   "set it as base_offset", {"base_offset": {"xyz": xyz, "rpy": rpy}}))
    for index, raw in enumerate(table.raw_rows):
        if fixes(table.with_row(index, sign=-raw["sign"])):
            diagnoses.append(Diagnosis("sign-flipped", f"row {index + 1} ({raw['joint']}): the sign looks flipped; "
                                       f"set sign: {-raw['sign']:g}", {"row": index + 1, "joint": raw["joint"],
                                                                        "sign": -raw["sign"]}))
    first_bad = first_wrong_row(table, urdf_frames, q, tolerance_m, tolerance_rad)
    if first_bad is not None and not any(d.kind in ("sign-flipped", "angles-in-degrees", "lengths-in-mm",
                                                    "angles-in-radians", "lengths-in-m") for d in diagnoses):
        diagnoses.extend(_fit_rows(table, urdf_frames, q, first_bad, tolerance_m, tolerance_rad))
    explained = any(d.fix and d.kind != "wrong-value" for d in diagnoses)
    if first_bad is not None and not explained:
        joint = table.raw_rows[first_bad - 1]["joint"]
        if table.convention == "standard":
            suspects = "the base_offset" if first_bad == 1 else f"row {first_bad - 1}'s d / a / alpha / theta_offset"
        else:
            suspects = "the base_offset" if first_bad == 1 else f"row {first_bad - 1}'s d / theta_offset"
        diagnoses.append(Diagnosis(
            "wrong-row", f"DH frames agree with the URDF up to row {first_bad - 1}; the errors start at row "
                         f"{first_bad} ({joint}): the axis of {joint} is misplaced, check row {first_bad}'s sign"
                         f"{' / a / alpha' if table.convention == 'modified' else ''} and {suspects}",
            {"row": first_bad, "joint": joint}))
    elif tool_offset is None and base_offset is None and not diagnoses:
        diagnoses.append(Diagnosis("tool-or-last-row", "every DH frame moves rigidly with its URDF link, but the tip "
                                   "does not: check the last row and the tool", {}))
    return diagnoses


def _tidy(pose: tuple[list[float], list[float]]) -> tuple[list[float], list[float]]:
    """Round-off (below 1e-12) written as 0, so a suggested offset reads like what a person would type."""
    return tuple([0.0 if abs(v) < 1e-12 else v for v in part] for part in pose)  # type: ignore[return-value]


def _unit_diagnoses(table: DHTable, fixes) -> list[Diagnosis]:
    """Angles typed in degrees under ``angle: rad`` (and the reverse), millimetres under ``length: m``."""
    result = []
    angles = [abs(raw[key]) for raw in table.raw_rows for key in ANGLE_FIELDS]
    if table.angle_unit == "rad":
        looks = any(value > 2 * math.pi for value in angles)
        if fixes(dataclasses.replace(table, angle_unit="deg")):
            result.append(Diagnosis("angles-in-degrees", "the angles look like degrees read as radians"
                                    f"{' (some exceed 2 pi)' if looks else ''}: set units: {{angle: deg}}",
                                    {"units": {"angle": "deg"}}))
        elif looks:
            result.append(Diagnosis("angles-in-degrees", "some angles exceed 2 pi under angle: rad; they look like "
                                    "degrees: convert them or set units: {angle: deg}", {}))
    elif fixes(dataclasses.replace(table, angle_unit="rad")):
        result.append(Diagnosis("angles-in-radians", "the angles look like radians read as degrees: set units: "
                                "{angle: rad}", {"units": {"angle": "rad"}}))
    other_length = "mm" if table.length_unit == "m" else "m"
    if fixes(dataclasses.replace(table, length_unit=other_length)):
        kind = "lengths-in-mm" if other_length == "mm" else "lengths-in-m"
        result.append(Diagnosis(kind, f"the lengths look like {other_length} read as {table.length_unit}: set "
                                f"units: {{length: {other_length}}}", {"units": {"length": other_length}}))
    return result


def first_wrong_row(table: DHTable, urdf_frames: Mapping[str, np.ndarray], q: np.ndarray, tolerance_m: float,
                    tolerance_rad: float) -> int | None:
    """1-based row k where DH frame k first stops moving rigidly with its URDF link (None: all rigid).

    DH frame k and the child link of row k's joint both move with joints 1..k only, so in a right
    table ``T_link_k^-1 T_dh_k`` is one constant transform over all samples.
    """
    frames = kinematics.dh_frames(table.rows, q, table.convention, table.base_offset)
    for index, joint in enumerate(table.chain):
        relative = kinematics.invert(urdf_relative(urdf_frames, table, joint.child)) @ frames[index + 1]  # type: ignore[arg-type]
        position, angle = kinematics.spread(relative)
        if position > tolerance_m or angle > tolerance_rad:
            return index + 1
    return None


def _fit_rows(table: DHTable, urdf_frames: Mapping[str, np.ndarray], q: np.ndarray, first_bad: int,
              tolerance_m: float, tolerance_rad: float) -> list[Diagnosis]:
    """Fit one parameter at a time in the rows around ``first_bad``; report the fits that fix the tip."""
    result = []
    fit_count = min(len(q), 64)
    for index in sorted({max(first_bad - 2, 0), first_bad - 1}):
        for key in ("d", "a", "alpha", "theta_offset"):
            value = _fit_parameter(table, urdf_frames, q[:fit_count], index, key)
            if value is None:
                continue
            candidate = table.with_row(index, **{key: value})
            if evaluate(candidate, urdf_frames, q).within(tolerance_m, tolerance_rad):
                raw = table.raw_rows[index]
                unit = table.angle_unit if key in ANGLE_FIELDS else table.length_unit
                result.append(Diagnosis("wrong-value", f"row {index + 1} ({raw['joint']}): {key} is {raw[key]:.9g} "
                                        f"{unit}; the URDF needs {value:.9g} {unit}",
                                        {"row": index + 1, "joint": raw["joint"], key: value}))
    return result


def _fit_parameter(table: DHTable, urdf_frames: Mapping[str, np.ndarray], q: np.ndarray, index: int,
                   key: str) -> float | None:
    """Gauss-Newton on one raw parameter, minimising the tip pose residual; None if it diverges."""
    subset = {name: frames[: len(q)] for name, frames in urdf_frames.items()}

    def residual(value: float) -> np.ndarray:
        evaluation = evaluate(table.with_row(index, **{key: value}), subset, q)
        difference = evaluation.dh_tip[:, :3, :] - evaluation.urdf_tip[:, :3, :]
        return difference.ravel()

    value = float(table.raw_rows[index][key])
    for _ in range(12):
        r = residual(value)
        step = 1e-6 * max(1.0, abs(value))
        jacobian = (residual(value + step) - r) / step
        norm = float(jacobian @ jacobian)
        if norm == 0.0 or not np.isfinite(norm):
            return None
        delta = float(jacobian @ r) / norm
        value -= delta
        if abs(delta) <= 1e-13 * max(1.0, abs(value)):
            break
    return value if np.isfinite(value) else None


# ---- deriving a table from the URDF -------------------------------------------------------------

def derive_standard(model: Model, base: str, tip: str, signs: list[int] | None = None) -> dict[str, Any]:
    """A standard-DH table (as a YAML-ready dict, m / rad) that reproduces ``base -> tip`` exactly.

    Frame 0 sits on joint 1's axis at the foot of the perpendicular from the base link origin; each
    frame i has z along joint i+1's URDF axis times ``signs[i]`` (default +1) and x along the common normal
    (for parallel axes: through the previous origin), oriented to keep theta offsets small. The last
    frame keeps joint n's axis and sits level with the tip origin; ``tool`` absorbs the rest.
    """
    chain = [joint for joint in chain_joints(model, base, tip) if joint.type != "fixed"]
    signs = list(signs) if signs is not None else [1] * len(chain)
    frames = kinematics.urdf_link_frames(model, {}, 1)
    to_base = kinematics.invert(frames[base][0])
    points, axes = [], []
    for joint in chain:
        joint_frame = to_base @ frames[joint.parent][0] @ kinematics.transform(joint.origin.xyz, joint.origin.rpy)  # type: ignore[index]
        points.append(joint_frame[:3, 3])
        axes.append(signs[len(axes)] * (joint_frame[:3, :3] @ kinematics.unit_axis(joint)))
    tip_frame = to_base @ frames[tip][0]
    z0 = axes[0]
    origin = points[0] + np.dot(-points[0], z0) * z0
    x0 = _perpendicular(np.array([1.0, 0.0, 0.0]), z0)
    frame = _frame(origin, x0, z0)
    base_offset = frame.copy()
    rows = []
    for i, joint in enumerate(chain):
        z_prev, o_prev, x_prev = frame[:3, 2], frame[:3, 3], frame[:3, 0]
        if i + 1 < len(chain):
            z_next, p_next = axes[i + 1], points[i + 1]
            cross = np.cross(z_prev, z_next)
            if np.linalg.norm(cross) > 1e-9:
                x_new = cross / np.linalg.norm(cross)
                x_new = x_new if np.dot(x_new, x_prev) >= 0 else -x_new
                # feet of the common normal on both lines
                w = o_prev - p_next
                b = np.dot(z_prev, z_next)
                d_, e_ = np.dot(z_prev, w), np.dot(z_next, w)
                s = (b * e_ - d_) / (1 - b * b)
                t = (e_ - b * d_) / (1 - b * b)
                foot, o_new = o_prev + s * z_prev, p_next + t * z_next
            else:
                o_new = p_next + np.dot(o_prev - p_next, z_next) * z_next
                foot = o_prev
                normal = o_new - foot
                x_new = normal / np.linalg.norm(normal) if np.linalg.norm(normal) > 1e-12 else x_prev
        else:
            z_next = z_prev
            foot = o_prev + np.dot(tip_frame[:3, 3] - o_prev, z_prev) * z_prev
            o_new = foot
            x_new = _perpendicular(tip_frame[:3, 0], z_prev)
        d = float(np.dot(foot - o_prev, z_prev))
        a = float(np.dot(o_new - foot, x_new))
        theta = float(np.arctan2(np.dot(np.cross(x_prev, x_new), z_prev), np.dot(x_prev, x_new)))
        alpha = float(np.arctan2(np.dot(np.cross(z_prev, z_next), x_new), np.dot(z_prev, z_next)))
        rows.append({"joint": joint.name, "a": a, "alpha": alpha, "d": d, "theta_offset": theta, "sign": signs[i]})
        frame = frame @ kinematics.dh_row_transforms(DHRow(joint.name, a, alpha, d, theta), np.zeros(1), "standard")[0]
    tool = kinematics.invert(frame) @ tip_frame
    xyz_b, rpy_b = kinematics.xyz_rpy(base_offset)
    xyz_t, rpy_t = kinematics.xyz_rpy(tool)
    return {"convention": "standard", "base": base, "tip": tip, "units": {"length": "m", "angle": "rad"},
            "base_offset": {"xyz": xyz_b, "rpy": rpy_b}, "tool": {"xyz": xyz_t, "rpy": rpy_t}, "joints": rows}


def _perpendicular(vector: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """``vector`` projected onto the plane normal to ``axis`` and normalised (another axis if degenerate)."""
    for candidate in (vector, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
        projected = candidate - np.dot(candidate, axis) * axis
        if np.linalg.norm(projected) > 1e-6:
            return projected / np.linalg.norm(projected)
    raise AssertionError("unreachable")


def _frame(origin: np.ndarray, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    result = np.eye(4)
    result[:3, 0], result[:3, 1], result[:3, 2], result[:3, 3] = x, np.cross(z, x), z, origin
    return result
