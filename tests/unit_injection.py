"""Inject one unit or reference mistake into a real robot, as a person editing it would make it (issue 35).

Each injector takes a loaded :class:`~ar3cli.urdf.model.Model`, picks the first element of the robot
where the mistake can be made (deterministic), changes that element's attribute in a copy of the parsed
tree and returns the robot's new text, the rule that must report it, words its message must hold (the
unit it names) and a needle: text that only the changed line holds, to check the finding points at the
element. None when the robot offers no such element. Used by tests/test_unit_mistakes.py (on
pybullet_data's robots) and benchmarks/inject_units.py (example-robot-data and pybullet_data).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path

from ar3cli.lint.engine import LintOptions, lint_model
from ar3cli.urdf.model import ROTATING_JOINT_TYPES, load_model


@dataclass
class Injection:
    kind: str
    code: str
    words: str
    source: bytes
    needle: str


def _serialise(root) -> bytes:
    from lxml import etree

    return etree.tostring(root, encoding="utf-8", xml_declaration=True)


def _twin(model, element):
    """``element``'s counterpart in a deep copy of the model's tree: (copied root, copied element)."""
    root = copy.deepcopy(model.root)
    path = model.root.getroottree().getpath(element)
    return root, root.getroottree().xpath(path)[0]


def _number(value: float) -> str:
    return f"{value:.6g}"


def rpy_degrees(model) -> Injection | None:
    """A joint origin whose rotation was typed in degrees (rpy="0 0 90" for a quarter turn)."""
    for joint in model.joints:
        origin = joint.origin.element
        if origin is None or origin.get("quat_xyzw") is not None:
            continue
        values = joint.origin.rpy
        if any(abs(v) > 0.05 for v in values) and all(abs(math.degrees(v)) <= 360 for v in values):
            degrees = [round(math.degrees(v)) for v in values]
            if not any(abs(d) > 7 for d in degrees):
                continue
            root, twin = _twin(model, origin)
            text = " ".join(str(d) for d in degrees)
            twin.set("rpy", text)
            return Injection("rpy in degrees", "J015", "looks like degrees", _serialise(root), f'rpy="{text}"')
    return None


def mass_grams(model, ctx) -> Injection | None:
    """The heaviest link whose density its collision geometry bounds, its mass typed in grams."""
    from ar3cli.lint.rules.plausibility import density_bounds

    links = [link for link in model.links if density_bounds(ctx, link)[1] is not None]
    if not links:
        return None
    link = max(links, key=lambda item: item.inertial.mass)
    mass = link.inertial.element.find("mass")
    root, twin = _twin(model, mass)
    text = _number(link.inertial.mass * 1000)
    twin.set("value", text)
    return Injection("mass in grams", "I013", "looks like grams", _serialise(root), f'value="{text}"')


def tensor_units(model, ctx, factor: float) -> Injection | None:
    """The first link with a plausible, measured (not placeholder) tensor, written x ``factor`` (1e6 for
    kg·mm², 1e9 for g·mm²)."""
    from ar3cli.lint.rules.inertia import IMPLAUSIBLE_FACTOR, _gyration_ratio, _placeholder_tensor

    for link in model.links:
        found = _gyration_ratio(ctx, link)
        if found is None or not 0.05 < found[0] <= IMPLAUSIBLE_FACTOR / 2 or _placeholder_tensor(link.inertial.tensor):
            continue
        element = link.inertial.element.find("inertia")
        root, twin = _twin(model, element)
        keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        for key, value in zip(keys, link.inertial.tensor):
            twin.set(key, _number(value * factor))
        unit = "kg·mm²" if factor == 1e6 else "g·mm²"
        return Injection(f"inertia in {unit}", "I007", f"looks like {unit}", _serialise(root),
                         f'ixx="{_number(link.inertial.tensor[0] * factor)}"')
    return None


def velocity_degrees(model) -> Injection | None:
    """A rotating joint whose speed, shared with another joint, was typed in deg/s (round to 5)."""
    speeds = [(joint, joint.limit.velocity) for joint in model.joints if joint.type in ROTATING_JOINT_TYPES
              and joint.limit is not None and joint.mimic is None and joint.limit.velocity]
    for joint, speed in speeds:
        degrees = round(math.degrees(speed) / 5) * 5
        if not 0.5 < speed <= 12 or abs(math.radians(degrees) - speed) > 0.01 * speed:
            continue
        if not any(other is not joint and abs(other_speed - speed) <= 0.005 * speed for other, other_speed in speeds):
            continue
        root, twin = _twin(model, joint.limit.element)
        twin.set("velocity", str(degrees))
        return Injection("velocity in deg/s", "J016", "looks like deg/s", _serialise(root), f'velocity="{degrees}"')
    return None


def colour_255(model) -> Injection | None:
    """A material colour typed on the 0-255 scale."""
    for colour in model.root.iter("color"):
        values = [float(v) for v in (colour.get("rgba") or "").split()]
        if len(values) == 4 and any(0.05 < v <= 1 for v in values[:3]):
            root, twin = _twin(model, colour)
            text = " ".join(str(round(v * 255)) for v in values[:3]) + f" {values[3]:g}"
            twin.set("rgba", text)
            return Injection("colour in 0-255", "G017", "looks like 0-255", _serialise(root), f'rgba="{text}"')
    return None


def com_millimetres(model, ctx) -> Injection | None:
    """A link's centre of mass (away from its origin) written in millimetres."""
    for link in model.links:
        inertial = link.inertial
        if inertial is None or inertial.origin.element is None or not (inertial.mass or 0) > 0 \
                or ctx.link_bounds(link) is None or max(map(abs, inertial.origin.xyz)) < 0.01:
            continue
        root, twin = _twin(model, inertial.origin.element)
        text = " ".join(_number(v * 1000) for v in inertial.origin.xyz)
        twin.set("xyz", text)
        return Injection("COM in millimetres", "I016", "looks like millimetres", _serialise(root), f'xyz="{text}"')
    return None


def soft_limits_degrees(model) -> Injection | None:
    """A revolute joint given a <safety_controller> whose soft limits were typed in degrees."""
    from lxml import etree

    for joint in model.joints:
        limit = joint.limit
        if joint.type != "revolute" or limit is None or limit.lower is None or limit.upper is None \
                or not limit.upper - limit.lower > 0.5 or math.degrees(limit.upper) < 10 \
                or max(abs(limit.lower), abs(limit.upper)) > math.pi:
            continue  # a person types the degrees of a real stop, not of a placeholder range
        root, twin = _twin(model, joint.element)
        lower, upper = round(math.degrees(limit.lower) * 0.95), round(math.degrees(limit.upper) * 0.95)
        for old in twin.findall("safety_controller"):
            twin.remove(old)
        etree.SubElement(twin, "safety_controller", soft_lower_limit=str(lower), soft_upper_limit=str(upper),
                         k_position="100", k_velocity="10")  # on the line of </joint>: no line moves
        return Injection("soft limits in degrees", "J017", "looks like degrees", _serialise(root),
                         f'soft_upper_limit="{upper}"')
    return None


def collision_scaled_twice(model, ctx) -> Injection | None:
    """A link whose collision mesh got scale 0.001 on top of a mesh already in metres (its visual's)."""
    for link in model.links:
        if not any(s.geometry.kind == "mesh" for s in link.visuals) or ctx.link_bounds(link) is None:
            continue
        for shape in link.collisions:
            geometry = shape.geometry
            if geometry.kind != "mesh" or geometry.resolution is None or not geometry.resolution.found:
                continue
            root, twin = _twin(model, geometry.element)
            scale = " ".join(_number(v / 1000) for v in geometry.params.get("scale") or (1.0, 1.0, 1.0))
            twin.set("scale", scale)
            return Injection("collision mesh in other unit", "G006", "its visual is in metres", _serialise(root),
                             f'scale="{scale}"')
    return None


def quaternion(model) -> Injection | None:
    """A rotated joint origin written as URDF 1.1's quat_xyzw (in a file that declares 1.1)."""
    from ar3cli.maths.tensor_math import rpy_to_matrix

    for joint in model.joints:
        origin = joint.origin.element
        if origin is None or not any(abs(v) > 0.05 for v in joint.origin.rpy):
            continue
        quat = _quaternion(rpy_to_matrix(joint.origin.rpy))
        root, twin = _twin(model, origin)
        del twin.attrib["rpy"]
        text = " ".join(_number(v) for v in quat)
        twin.set("quat_xyzw", text)
        root.set("version", "1.1")
        return Injection("quat_xyzw under pybullet", "T009", "PyBullet ignores it", _serialise(root),
                         f'quat_xyzw="{text}"')
    return None


def _quaternion(rotation) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation matrix (rows), Shepperd's method."""
    (a, b, c), (d, e, f), (g, h, i) = rotation
    trace = a + e + i
    if trace > 0:
        s = math.sqrt(trace + 1.0) * 2
        return ((h - f) / s, (c - g) / s, (d - b) / s, 0.25 * s)
    if a > e and a > i:
        s = math.sqrt(1.0 + a - e - i) * 2
        return (0.25 * s, (b + d) / s, (c + g) / s, (h - f) / s)
    if e > i:
        s = math.sqrt(1.0 + e - a - i) * 2
        return ((b + d) / s, 0.25 * s, (f + h) / s, (c - g) / s)
    s = math.sqrt(1.0 + i - a - e) * 2
    return ((c + g) / s, (f + h) / s, 0.25 * s, (d - b) / s)


KINDS = ("rpy", "grams", "kg·mm²", "g·mm²", "deg/s", "0-255", "com", "soft", "scale", "quat")
"""Every class of unit or reference mistake of issue 35, in the order the reports list them."""


def inject(kind: str, model) -> Injection | None:
    """The robot ``model`` with one mistake of ``kind`` (:data:`KINDS`), or None when it has no place for it."""
    from ar3cli.lint.context import Context

    ctx = Context(model)
    makers = {"rpy": lambda: rpy_degrees(model), "grams": lambda: mass_grams(model, ctx),
              "kg·mm²": lambda: tensor_units(model, ctx, 1e6), "g·mm²": lambda: tensor_units(model, ctx, 1e9),
              "deg/s": lambda: velocity_degrees(model), "0-255": lambda: colour_255(model),
              "com": lambda: com_millimetres(model, ctx), "soft": lambda: soft_limits_degrees(model),
              "scale": lambda: collision_scaled_twice(model, ctx), "quat": lambda: quaternion(model)}
    return makers[kind]()


def found_at_its_element(path: Path, injection: Injection) -> tuple[bool, str]:
    """Lint the injected robot with its rule; (reported at the changed element with its words, what was found)."""
    from ar3cli.urdf.xmlsource import decode_text

    model = load_model(path, source=injection.source)
    options = LintOptions(select=[injection.code])
    findings = lint_model(model, str(path), options.rules(), options).findings
    lines = decode_text(injection.source).splitlines()
    for finding in findings:
        if 1 <= finding.line <= len(lines) and injection.needle in lines[finding.line - 1] \
                and injection.words in finding.message:
            return True, finding.message
    return False, "; ".join(f"{f.line}: {f.message}" for f in findings) or "nothing"
