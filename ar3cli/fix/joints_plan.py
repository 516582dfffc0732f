"""The fix-joints fixer: the joint findings of lint-urdf that have one right answer.

What it fixes is decided by the lint rules themselves, run on the model at call time (so a change
to a rule's heuristic changes the fixer with it):

* J003 (lower > upper on a revolute or prismatic joint): ``lower`` and ``upper`` swapped, each
  keeping the other's text byte for byte. PyBullet's deliberate "no limit" idiom (lower="1"
  upper="-1", J014) is not J003's: it is left alone and named in a note (a swap would limit a
  joint PyBullet users rely on being free);
* J005 (revolute limits that look like degrees): ``lower`` and ``upper`` converted to radians,
  both of them, as the rule's hint does (a person who typed one limit in degrees typed both). The
  virtual joints of a floating base (a range such as ±20 shared with prismatic siblings, or a
  chain of massless dummy links from the root) are not J005's, so they are never converted;
* J009 (zero axis): not fixable, there is no direction to recover: reported as not fixed;
* J010 (axis not a unit vector): normalised, written with :func:`~ar3cli.fix.driver.number`;
* J007 (``<limit>`` without effort or velocity): filled from MoveIt's ``joint_limits.yaml``
  (``--limits-from``, its max_effort / max_velocity when has_*_limits is true), else from
  ``--effort`` / ``--velocity``; when neither says, the joint is reported as not fixed;
* J015 (a joint origin's rpy beyond a full turn: typed in degrees): the three angles converted to
  radians (the origins of visuals, collisions and inertials are left to the author: the lint hint
  gives their value);
* J016 (a velocity that is a round number of deg/s and, converted, another joint's speed): converted
  to rad/s.

:func:`verify` loads the written file in PyBullet and reads each changed joint back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.fix.driver import Change, Fixer, FixPlan, Skipped, check_row, number, same_numbers, verified_in_pybullet
from ar3cli.fix.settings import require_positive, setting
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.urdf.edits import Document
from ar3cli.urdf.joint_limits_yaml import YamlLimits, read_joint_limits

INVERTED, DEGREES, AXIS_ZERO, EFFORT_VELOCITY_MISSING, AXIS_NOT_UNIT = "J003", "J005", "J009", "J007", "J010"
RPY_DEGREES, VELOCITY_DEGREES = "J015", "J016"
"""The lint rules whose findings fix-joints acts on."""
UNLIMITED_IDIOM = "J014"
"""PyBullet's lower > upper "no limit" idiom: reported in a note, never changed."""
SAME_NUMBER = 1e-12
"""Relative tolerance under which a computed value is the file's (and nothing is rewritten)."""


@dataclass
class JointsOptions:
    """fix-joints' own options (each :func:`~ar3cli.fix.settings.setting` is one), and the limits read."""

    effort: float | None = setting("--effort", default=None,
                                   help="Effort (N*m or N) to add where a `<limit>` has none (J007).")
    velocity: float | None = setting("--velocity", default=None,
                                     help="Velocity (rad/s or m/s) to add where a `<limit>` has none (J007).")
    limits_path: Path | None = setting(
        "--limits-from", metavar="JOINT_LIMITS_YAML", default=None,
        help="MoveIt joint_limits.yaml: its max_effort / max_velocity fill a `<limit>` without them "
             "(before --effort / --velocity).")
    verify: bool = setting("--verify/--no-verify", default=True,
                           help="After writing, load the result in PyBullet and read the joints back.")
    limits: dict[str, YamlLimits] | None = field(default=None, init=False)
    """``--limits-from``'s joints, read once."""

    def __post_init__(self) -> None:
        require_positive(effort=self.effort, velocity=self.velocity)
        self.limits = read_joint_limits(self.limits_path) if self.limits_path is not None else None


def flagged_joints(model, code: str) -> set[str]:
    """The joints (their element paths, ``/robot/joint[3]``: names may repeat) the lint rule
    ``code`` reports on ``model``, by running the rule's own check, imported at call time: the rule
    is the one definition of what it flags."""
    from ar3cli.lint.context import Context
    from ar3cli.lint.rules import REGISTRY

    found = REGISTRY.get(code)
    if found is None or found.check is None:
        raise UserError(f"internal: lint rule {code} is not in the rule registry")
    names: set[str] = set()
    for hit in found.check(Context(model)):
        element = hit.element
        while element is not None and element.tag != "joint":
            element = element.getparent()
        if element is not None:
            names.add(_path(element))
    return names


def _path(element) -> str:
    return element.getroottree().getpath(element)


def plan_joints(model, document: Document, options: JointsOptions) -> FixPlan:
    plan = FixPlan(context={"joints": {}})
    for name in options.limits or {}:
        if model.joint(name) is None:
            plan.notes.append(f"warning: {options.limits_path}: joint {name!r} is not in {model.path}")
    flagged = {code: flagged_joints(model, code)
               for code in (INVERTED, DEGREES, AXIS_ZERO, AXIS_NOT_UNIT, EFFORT_VELOCITY_MISSING, RPY_DEGREES,
                            VELOCITY_DEGREES)}
    swapped: list[str] = []
    for joint in model.joints:
        path = _path(joint.element)
        if path in flagged[INVERTED] or path in flagged[DEGREES]:
            fixed = _fix_range(document, plan, joint, swap=path in flagged[INVERTED], degrees=path in flagged[DEGREES])
            if fixed and path in flagged[INVERTED]:
                swapped.append(joint.name)
        if path in flagged[AXIS_ZERO]:
            axis = joint.element.find("axis")
            plan.skipped.append(Skipped(
                _element(joint), (axis.sourceline if axis is not None else None) or joint.line,
                f"axis is {axis.get('xyz') if axis is not None else '0 0 0'}: no direction to normalise; "
                "set the joint's real axis by hand (a unit vector in the joint frame, e.g. <axis xyz=\"0 0 1\"/>)"))
        elif path in flagged[AXIS_NOT_UNIT]:
            _normalise_axis(document, plan, joint)
        if path in flagged[EFFORT_VELOCITY_MISSING]:
            _fill_effort_velocity(document, plan, joint, options)
        if path in flagged[RPY_DEGREES]:
            _origin_to_radians(document, plan, joint)
        if path in flagged[VELOCITY_DEGREES]:
            _velocity_to_radians(document, plan, joint)
    if swapped:
        plan.notes.append(f"note: {model.path}: PyBullet reads lower > upper as 'no limit'; the swapped joint(s) "
                          f"{listed(swapped)} are limited to [lower, upper] there now. If the file meant unlimited, "
                          "give the real travel instead, or make a revolute joint continuous")
    idiom_paths = flagged_joints(model, UNLIMITED_IDIOM)
    idioms = [joint.name for joint in model.joints if _path(joint.element) in idiom_paths]
    if idioms:
        plan.notes.append(f"note: {model.path}: left {listed(idioms)} alone: lower > upper written as PyBullet's "
                          "'no limit' idiom (lower=\"1\" upper=\"-1\", J014), unlimited in PyBullet; swapping it "
                          "would limit the joint. For a portable file give the real travel, or make a revolute "
                          "joint continuous")
    return plan


def _element(joint) -> str:
    return f"joint {joint.name}"


def _record(plan: FixPlan, joint, **values) -> None:
    plan.context["joints"].setdefault(joint.name, {}).update(values)


def _fix_range(document: Document, plan: FixPlan, joint, *, swap: bool, degrees: bool) -> bool:
    """Swap (J003) and/or convert to radians (J005) the joint's lower/upper; False when the source
    cannot be edited (a xacro expression: reported as not fixed)."""
    limit = joint.limit
    texts = {key: limit.element.get(key) for key in ("lower", "upper")}
    values = {"lower": limit.lower, "upper": limit.upper}
    reasons = []
    if swap:
        texts = {"lower": texts["upper"], "upper": texts["lower"]}
        values = {"lower": values["upper"], "upper": values["lower"]}
        reasons.append(f"{INVERTED}: lower > upper, swapped")
    if degrees:
        for key in ("lower", "upper"):
            if values[key] is not None and math.isfinite(values[key]):
                values[key] = math.radians(values[key])
                texts[key] = number(values[key])
        reasons.append(f"{DEGREES}: degrees, converted to radians (x pi/180)")
    line = limit.element.sourceline or joint.line
    refused = document.refusal(limit.element, ("lower", "upper"))
    if refused is not None:
        plan.skipped.append(Skipped(_element(joint), line, refused))
        return False
    span = document.span(limit.element)
    for key in ("lower", "upper"):
        old, new = limit.element.get(key), texts[key]
        if new is None or old == new or (not swap and same_numbers(old, new, rel_tol=SAME_NUMBER)):
            continue
        document.set_attribute(span, key, new)
        plan.changes.append(Change(_element(joint), line, f"limit {key}", old, new, "; ".join(reasons)))
    _record(plan, joint, lower=values["lower"], upper=values["upper"])
    return True


def _origin_to_radians(document: Document, plan: FixPlan, joint) -> None:
    """J015: the joint origin's rpy, typed in degrees, in radians (all three angles, as the rule's hint)."""
    origin = joint.origin.element
    old = origin.get("rpy")
    new = " ".join(number(math.radians(value)) for value in map(float, old.split()))
    document.set_attribute(document.span(origin), "rpy", new)
    plan.changes.append(Change(_element(joint), origin.sourceline or joint.line, "origin rpy", old, new,
                               f"{RPY_DEGREES}: degrees, converted to radians (x pi/180)"))


def _velocity_to_radians(document: Document, plan: FixPlan, joint) -> None:
    """J016: a velocity typed in deg/s, in rad/s."""
    limit = joint.limit
    old = limit.element.get("velocity")
    value = math.radians(limit.velocity)
    new = number(value)
    document.set_attribute(document.span(limit.element), "velocity", new)
    plan.changes.append(Change(_element(joint), limit.element.sourceline or joint.line, "limit velocity", old, new,
                               f"{VELOCITY_DEGREES}: deg/s, converted to rad/s (x pi/180)"))
    _record(plan, joint, velocity=float(new))


def _normalise_axis(document: Document, plan: FixPlan, joint) -> None:
    axis = joint.element.find("axis")
    norm = math.sqrt(sum(c * c for c in joint.axis))
    unit = tuple(c / norm for c in joint.axis)
    new = " ".join(number(c) for c in unit)
    old = axis.get("xyz")
    if old == new:
        return
    refused = document.refusal(axis, ("xyz",))
    if refused is not None:
        plan.skipped.append(Skipped(_element(joint), axis.sourceline or joint.line, refused))
        return
    document.set_attribute(document.span(axis), "xyz", new)
    plan.changes.append(Change(_element(joint), axis.sourceline or joint.line, "axis xyz", old, new,
                               f"{AXIS_NOT_UNIT}: length {norm:.6g}, normalised"))
    _record(plan, joint, axis=unit)


def _fill_effort_velocity(document: Document, plan: FixPlan, joint, options: JointsOptions) -> None:
    """Add the missing effort/velocity of a <limit>: from the yaml, else from the options."""
    limit = joint.limit
    entry = (options.limits or {}).get(joint.name)
    source = options.limits_path.name if options.limits_path else "joint_limits.yaml"
    line = limit.element.sourceline or joint.line
    refused = document.refusal(limit.element, ("effort", "velocity"))
    if refused is not None:
        plan.skipped.append(Skipped(_element(joint), line, refused))
        return
    span = document.span(limit.element)
    for key in ("effort", "velocity"):
        if limit.element.get(key) is not None:
            continue
        from_yaml = getattr(entry, key) if entry is not None else None
        option = options.effort if key == "effort" else options.velocity
        if from_yaml is not None:
            value, origin = from_yaml, f"{source}: max_{key}"
        elif option is not None:
            value, origin = option, f"--{key}"
        else:
            where = f" and {source} has no max_{key} for it" if options.limits is not None else ""
            plan.skipped.append(Skipped(_element(joint), line,
                                        f"<limit> has no {key}{where}: pass --{key} or --limits-from "
                                        "joint_limits.yaml (urdfdom refuses a <limit> without it)"))
            continue
        text = number(value)
        document.set_attribute(span, key, text)
        plan.changes.append(Change(_element(joint), line, f"limit {key}", None, text, f"{origin} (added)"))
        _record(plan, joint, **{key: float(text)})


# ---- verification in PyBullet -----------------------------------------------------------------
def verify(model, plan: FixPlan) -> dict:
    """Load the fixed file in PyBullet; each changed joint's limits, effort, velocity and axis as
    getJointInfo reports them must be the new values."""
    joints = plan.context.get("joints", {})
    return verified_in_pybullet(model, lambda: _checks_in_pybullet(model, joints), nothing_changed=not joints)


def _checks_in_pybullet(model, joints: dict) -> list[dict]:
    from ar3cli.sim.session import Session

    checks: list[dict] = []
    with Session() as session:
        body = session.load(model, visuals=False, allow_nan_frames=True)  # a zero axis left alone is NaN
        records = {record.name: record for record in body.joints}
        for name, expected in joints.items():
            record = records.get(name)
            if record is None:
                checks.append(check_row(name, "loaded", False, "joint not found in pybullet"))
                continue
            info = session.p.getJointInfo(body.id, record.index, physicsClientId=session.client)
            if "lower" in expected:
                ok = all(value is None or math.isclose(got, value, rel_tol=1e-9, abs_tol=1e-9)
                         for got, value in ((info[8], expected["lower"]), (info[9], expected["upper"])))
                checks.append(check_row(name, "limits", ok, f"getJointInfo lower={info[8]:.9g} upper={info[9]:.9g}"))
            for key, index in (("effort", 10), ("velocity", 11)):
                if key in expected:
                    checks.append(check_row(name, key, math.isclose(info[index], expected[key], rel_tol=1e-9),
                                         f"getJointInfo {key}={info[index]:.9g}"))
            if "axis" in expected:
                got = info[13]
                ok = all(math.isclose(a, b, abs_tol=1e-9) for a, b in zip(got, expected["axis"]))
                checks.append(check_row(name, "unit axis", ok,
                                     "getJointInfo axis=" + " ".join(f"{c:.9g}" for c in got)))
    return checks


FIXER = Fixer[JointsOptions]("fix-joints", plan_joints, verify, options=JointsOptions, timeout=DEFAULT_TIMEOUT_S,
                             edits_xacro=True,
                             help="""\
Fix the joint findings of lint-urdf that have one right answer, byte for byte, atomically.

Inverted limits (J003) are swapped; revolute limits in degrees (J005), a joint origin's rpy in
degrees (J015) and a velocity in deg/s (J016) become radians; a non-unit axis (J010) is
normalised; a `<limit>` without effort or velocity (J007) gets them from --limits-from or
--effort/--velocity. A zero axis (J009) cannot be fixed automatically: it is reported, with what
to do. Only the changed attributes are edited.
""")
"""``ar3cli fix-joints``: :func:`plan_joints`, then :func:`verify` with ``--verify``."""
