"""The fix-continuous fixer: continuous joints with fake limits, and their real limits.

* Default: remove ``lower``/``upper`` from continuous joints. The URDF spec ignores them, and
  PyBullet clamps POSITION_CONTROL targets to them (pybullet-facts.md section 3), so the popular
  ``lower="-100" upper="100"`` adds a clamp and fixes nothing. ``effort``/``velocity`` are kept,
  and added from ``--effort``/``--velocity`` when missing.
* ``--limits-from joint_limits.yaml`` (MoveIt): joints with ``has_position_limits: true`` become
  revolute with those limits (the real fix for an arm with hard stops exported as continuous);
  velocity and effort come from the yaml when it has them, else from the file, else the options.
* ``--to-continuous``: revolute joints whose range covers a full turn become continuous.

:func:`verify` loads the written file in PyBullet and checks getJointInfo and a position target.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from ar3cli.fix.driver import Change, Fixer, FixPlan, Skipped, check_row, number, same_numbers, verified_in_pybullet
from ar3cli.fix.settings import require_positive, setting
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.urdf.edits import Document
from ar3cli.urdf.joint_limits_yaml import YamlLimits, read_joint_limits

FULL_TURN = 2.0 * math.pi
FULL_TURN_TOLERANCE = 1e-6
"""rad: files write pi with 8-9 digits (-3.14159265 .. 3.14159265 falls 7e-9 short of a full turn)."""


@dataclass
class ContinuousOptions:
    """fix-continuous' own options (each :func:`~ar3cli.fix.settings.setting` is one), and the limits read."""

    limits_path: Path | None = setting(
        "--limits-from", metavar="JOINT_LIMITS_YAML", default=None,
        help="MoveIt joint_limits.yaml: joints with has_position_limits become revolute with its limits.")
    to_continuous: bool = setting(
        "--to-continuous", default=False,
        help="Revolute joints whose range covers a full turn (>= 2 pi) become continuous.")
    effort: float | None = setting("--effort", default=None,
                                   help="Effort (N*m or N) to add where a fixed joint's `<limit>` has none.")
    velocity: float | None = setting("--velocity", default=None,
                                     help="Velocity (rad/s or m/s) to add where a fixed joint's `<limit>` has none.")
    verify: bool = setting("--verify/--no-verify", default=True,
                           help="After writing, load the result in PyBullet and check the joints.")
    limits: dict[str, YamlLimits] | None = field(default=None, init=False)
    """``--limits-from``'s joints, read once."""
    warnings: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        require_positive(effort=self.effort, velocity=self.velocity)
        self.limits = read_joint_limits(self.limits_path) if self.limits_path is not None else None


def plan_continuous(model, document: Document, options: ContinuousOptions) -> FixPlan:
    plan = FixPlan(context={"joints": {}})
    limits = options.limits or {}
    for name in limits:
        if model.joint(name) is None:
            plan.notes.append(f"warning: {options.limits_path}: joint {name!r} is not in {model.path}")
    for joint in model.joints:
        entry = limits.get(joint.name)
        if entry is not None and entry.lower is not None and entry.upper is not None:
            _to_revolute(document, plan, joint, entry, options)
        elif joint.type == "continuous":
            _remove_fake_limits(document, plan, joint, options)
        elif options.to_continuous and joint.type == "revolute":
            _full_turn_to_continuous(document, plan, joint)
    return plan


LIMIT_KEYS = ("lower", "upper", "effort", "velocity")
"""The attributes of a ``<limit>`` this fixer reads and writes."""


def _element(joint) -> str:
    return f"joint {joint.name}"


def _record(plan: FixPlan, joint, **values) -> None:
    plan.context["joints"].setdefault(joint.name, {}).update(values)


def _remove_fake_limits(document: Document, plan: FixPlan, joint, options: ContinuousOptions) -> None:
    """Continuous joint: drop lower/upper; keep effort/velocity, adding them from the options.

    urdfdom refuses a ``<limit>`` without effort and velocity, so the fix never leaves one behind:
    when neither is known the whole element goes (a continuous joint needs no ``<limit>``); when
    only one is known, the joint is left alone and reported (pass the other option).
    """
    limit = joint.element.find("limit")
    line = (limit.sourceline if limit is not None else None) or joint.line
    present = {key: limit.get(key) if limit is not None else None for key in ("effort", "velocity")}
    added = {key: number(value) for key, value in (("effort", options.effort), ("velocity", options.velocity))
             if value is not None and present[key] is None}
    has_range = limit is not None and any(limit.get(key) is not None for key in ("lower", "upper"))
    if not has_range and not added:
        return
    final = {key: present[key] if present[key] is not None else added.get(key) for key in present}
    missing = [key for key, value in final.items() if value is None]
    if len(missing) == 1:
        have = next(key for key in final if final[key] is not None)
        plan.skipped.append(Skipped(_element(joint), line, f"its <limit> would keep {have} but no {missing[0]}; "
                                                           f"urdfdom requires both: pass --{missing[0]}"))
        return
    refused = document.refusal(limit if limit is not None else joint.element, LIMIT_KEYS)
    if refused is not None:
        plan.skipped.append(Skipped(_element(joint), line, refused))
        return
    reason = "ignored by the URDF spec; pybullet only clamps position targets to it"
    if missing:  # neither effort nor velocity: an empty <limit/> is invalid, a continuous joint needs none
        document.remove_element(document.span(limit))
        reason += "; the <limit> had no effort/velocity either, so it is removed"
    elif limit is None:
        q = document.quote.decode()
        document.insert_child(document.span(joint.element),
                              [f"<limit effort={q}{final['effort']}{q} velocity={q}{final['velocity']}{q}/>"])
    else:
        span = document.span(limit)
        for key in ("lower", "upper"):
            if limit.get(key) is not None:
                document.remove_attribute(span, key)
        for key, value in added.items():
            document.set_attribute(span, key, value)
    for key in ("lower", "upper"):
        if limit is not None and limit.get(key) is not None:
            plan.changes.append(Change(_element(joint), line, f"limit {key}", limit.get(key), None, reason))
    for key, value in added.items():
        plan.changes.append(Change(_element(joint), line, f"limit {key}", None, value, f"--{key} (added)"))
    _record(plan, joint, expect="continuous", old_upper=joint.limit.upper if joint.limit else None)


def _same(old: str | None, new: str) -> bool:
    """A limit from joint_limits.yaml equals the file's to 1e-12 (relative)."""
    return same_numbers(old, new, rel_tol=1e-12)


def _to_revolute(document: Document, plan: FixPlan, joint, entry: YamlLimits, options: ContinuousOptions) -> None:
    source = options.limits_path.name if options.limits_path else "joint_limits.yaml"
    if joint.type not in ("continuous", "revolute", "prismatic"):
        plan.notes.append(f"warning: {source}: joint {joint.name} is {joint.type!r}; position limits ignored")
        return
    new_type = "prismatic" if joint.type == "prismatic" else "revolute"
    limit = joint.element.find("limit")
    values = {"lower": number(entry.lower), "upper": number(entry.upper)}
    yaml_extra = {"effort": entry.effort, "velocity": entry.velocity}
    # effort/velocity: yaml, else a file value, else the option; a revolute joint needs both
    for key in ("effort", "velocity"):
        old = limit.get(key) if limit is not None else None
        option = options.effort if key == "effort" else options.velocity
        if yaml_extra[key] is not None:
            values[key] = number(yaml_extra[key])
        elif old is not None:
            values[key] = old
        elif option is not None:
            values[key] = number(option)
        else:
            plan.skipped.append(Skipped(_element(joint), joint.line,
                                        f"becomes {new_type} but has no {key} in the file or {source}: "
                                        f"pass --{key}"))
            return
    refused = document.refusal(joint.element, ("type",)) or (document.refusal(limit, LIMIT_KEYS)
                                                             if limit is not None else None)
    if refused is not None:
        plan.skipped.append(Skipped(_element(joint), joint.line, refused))
        return
    if joint.type != new_type:
        document.set_attribute(document.span(joint.element), "type", new_type)
        plan.changes.append(Change(_element(joint), joint.line, "type", joint.type, new_type,
                                   f"{source}: has_position_limits"))
    if limit is None:
        q = document.quote.decode()
        text = "<limit " + " ".join(f"{k}={q}{values[k]}{q}" for k in ("lower", "upper", "effort", "velocity")) + "/>"
        document.insert_child(document.span(joint.element), [text])
        for key in ("lower", "upper", "effort", "velocity"):
            origin = source if key in ("lower", "upper") or yaml_extra.get(key) is not None else f"--{key} (added)"
            plan.changes.append(Change(_element(joint), joint.line, f"limit {key}", None, values[key], origin))
    else:
        span = document.span(limit)
        for key in ("lower", "upper", "effort", "velocity"):
            old = limit.get(key)
            if old is not None and (_same(old, values[key]) or old == values[key]):
                continue
            document.set_attribute(span, key, values[key])
            origin = source if key in ("lower", "upper") or yaml_extra.get(key) is not None else f"--{key} (added)"
            plan.changes.append(Change(_element(joint), limit.sourceline or joint.line, f"limit {key}", old,
                                       values[key], origin))
    _record(plan, joint, expect=new_type, lower=entry.lower, upper=entry.upper)


def _full_turn_to_continuous(document: Document, plan: FixPlan, joint) -> None:
    limit = joint.limit
    if limit is None or limit.lower is None or limit.upper is None:
        return
    if limit.upper - limit.lower < FULL_TURN - FULL_TURN_TOLERANCE:
        return
    refused = document.refusal(joint.element, ("type",)) or document.refusal(limit.element, ("lower", "upper"))
    if refused is not None:
        plan.skipped.append(Skipped(_element(joint), joint.line, refused))
        return
    document.set_attribute(document.span(joint.element), "type", "continuous")
    reason = f"range {limit.upper - limit.lower:.4g} rad covers a full turn (--to-continuous)"
    plan.changes.append(Change(_element(joint), joint.line, "type", "revolute", "continuous", reason))
    span = document.span(limit.element)
    for key in ("lower", "upper"):
        document.remove_attribute(span, key)
        plan.changes.append(Change(_element(joint), limit.element.sourceline or joint.line, f"limit {key}",
                                   limit.element.get(key), None, reason))
    _record(plan, joint, expect="continuous", old_upper=limit.upper)


# ---- verification in PyBullet -----------------------------------------------------------------
def verify(model, plan: FixPlan) -> dict:
    """Load the fixed file in PyBullet; check each changed joint's limits (and that a target
    beyond a removed fake limit is reached)."""
    joints = plan.context.get("joints", {})
    return verified_in_pybullet(model, lambda: _checks_in_pybullet(model, joints), nothing_changed=not joints)


def _checks_in_pybullet(model, joints: dict) -> list[dict]:
    """Each changed joint's limits as pybullet loads them, and a drive past a removed fake limit."""
    from ar3cli.sim.session import Session

    checks: list[dict] = []
    with Session() as session:
        body = session.load(model, visuals=False)
        p = session.p
        records = {record.name: record for record in body.joints}
        for name, expected in joints.items():
            record = records.get(name)
            if record is None:
                checks.append(check_row(name, "loaded", False, "joint not found in pybullet"))
                continue
            info = p.getJointInfo(body.id, record.index, physicsClientId=session.client)
            lower, upper = info[8], info[9]
            if expected["expect"] == "continuous":
                checks.append(check_row(name, "no position limit", lower > upper,
                                     f"getJointInfo lower={lower:g} upper={upper:g}"))
                old_upper = expected.get("old_upper")
                if old_upper is not None and old_upper < FULL_TURN:
                    target = old_upper + 0.5
                    reached = _drive(session, body, record.index, target)
                    checks.append(check_row(name, "target beyond old limit", abs(reached - target) < 1e-2,
                                         f"target {target:.4g} rad, reached {reached:.4g} rad "
                                         f"(old upper {old_upper:g})"))
            else:
                ok = math.isclose(lower, expected["lower"], abs_tol=1e-9) and math.isclose(
                    upper, expected["upper"], abs_tol=1e-9)
                checks.append(check_row(name, f"{expected['expect']} limits", ok,
                                     f"getJointInfo lower={lower:.9g} upper={upper:.9g}"))
    return checks




def _drive(session, body, index: int, target: float, steps: int = 2400) -> float:
    """POSITION_CONTROL one joint to ``target`` (others held by pybullet's default motors)."""
    p = session.p
    p.setJointMotorControl2(body.id, index, p.POSITION_CONTROL, targetPosition=target, force=1000.0,
                            physicsClientId=session.client)
    for _ in range(steps):
        p.stepSimulation(physicsClientId=session.client)
    return float(p.getJointState(body.id, index, physicsClientId=session.client)[0])


FIXER = Fixer[ContinuousOptions]("fix-continuous", plan_continuous, verify, options=ContinuousOptions,
                                  timeout=DEFAULT_TIMEOUT_S, edits_xacro=True, help="""\
Fix continuous joints: lower/upper on a continuous joint only add a PyBullet position clamp.

Default: remove them (keep effort/velocity). --limits-from turns joints with hard stops
into revolute joints with the real limits. Edits only those joints, byte for byte, atomically.
""")
"""``ar3cli fix-continuous``: :func:`plan_continuous`, then :func:`verify` with ``--verify``."""
