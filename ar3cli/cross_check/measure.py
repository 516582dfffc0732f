"""What each engine says about one robot: frames, mass, centre of mass, mass matrix, gravity torques,
and where the joints go when one leader joint is driven (the constraints the engine enforces).

The constraint probe drives one leader joint and holds every joint that follows nothing (no
``<mimic>``) at home, in both engines: only the kinematic coupling is compared. Left free, MuJoCo's
arm joints move through the reaction forces of a driven finger (example-robot-data's panda:
``panda_joint6`` by 0.0038 rad when ``panda_finger_joint1`` moves 0.01 m), a dynamic effect that no
file error explains and that PyBullet, whose velocity motors hold its joints, does not show.

Each engine runs in its own forked child (:func:`~ar3cli.sim.session.run_pybullet`,
:func:`~ar3cli.sim.mujoco_session.run_mujoco`) and hands back plain arrays (:class:`EngineData`), so
the comparison (:mod:`ar3cli.cross_check.compare`) never touches either engine. The configurations
are drawn once, in the PyBullet child (:mod:`ar3cli.sim.sampling`: home, then ``--samples``
uniform ones from ``--seed``, mimic joints following their leader), and set in both engines.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.urdf.model import Model

GRAVITY = -9.81
DRIVE_SECONDS = 0.5
"""How long the constraint probe drives a leader joint. MuJoCo's joint equality (default solref
0.02 s, critically damped) brings a mimic follower to within 1e-6 rad of its target in this time
(measured on pybullet_data's panda finger)."""
MULTI_DOF_TYPES = ("spherical", "planar", "floating")
"""Joints PyBullet's calculateMassMatrix / calculateInverseDynamics do not take as one value each."""
DRIVE_STEP = 0.05
"""rad or m a leader joint is moved by the probe (a quarter of its range when that is smaller)."""


@dataclass
class EngineData:
    """One engine's answers; every list has one entry per configuration (home first)."""

    engine: str
    joints: list[str]
    frames: list[dict[str, tuple[tuple[float, ...], tuple[float, ...]]]] = field(default_factory=list)
    mass: float = 0.0
    link_masses: dict[str, float] = field(default_factory=dict)
    com: list[tuple[float, float, float]] = field(default_factory=list)
    mass_matrix: list[list[list[float]]] = field(default_factory=list)
    gravity: list[list[float]] = field(default_factory=list)
    driven: dict[str, dict[str, float]] = field(default_factory=dict)
    """Leader joint -> {joint: how far it moved} after the probe drove the leader by its step."""
    notes: list[str] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Plan:
    """What both engines are asked: the configurations (label, {joint: value}) and the probe's steps."""

    joints: list[str]
    configurations: list[tuple[str, dict[str, float]]]
    home: dict[str, float]
    steps: dict[str, float]
    """Leader (driving) joint -> signed step the probe moves it by."""
    followers: list[str] = field(default_factory=list)
    """Joints with a ``<mimic>``: the only ones the probe leaves free (the others are held at home)."""

    def held(self, leader: str) -> list[str]:
        """The joints the probe holds at home while it drives ``leader``: all but it and the followers."""
        return [name for name in self.joints if name != leader and name not in self.followers]


def plan_and_measure_pybullet(model: Model, samples: int, seed: int) -> tuple[Plan, EngineData]:
    """Draw the configurations and measure PyBullet (in a child)."""
    from ar3cli.sim.session import run_pybullet

    return run_pybullet(lambda: _pybullet(model, samples, seed), model)


def measure_mujoco(model: Model, plan: Plan) -> EngineData:
    """Measure MuJoCo at ``plan``'s configurations (in a child)."""
    from ar3cli.sim.mujoco_session import run_mujoco

    return run_mujoco(lambda: _mujoco(model, plan), model)


def _plan(model: Model, body: Any, samples: int, seed: int) -> Plan:
    from ar3cli.sim.sampling import joint_space, sample_configurations

    space = joint_space(body)
    rows = [("home", space.home), *((f"sample {i + 1}", row)
                                    for i, row in enumerate(sample_configurations(space, samples, seed)))]
    home = space.as_dict(space.home)
    steps = {}
    for index, name in enumerate(space.driving_names):
        lower, upper = float(space.lower[index]), float(space.upper[index])
        step = min(DRIVE_STEP, (upper - lower) / 4) if upper > lower else 0.0
        steps[name] = step if home[name] + step <= upper else -step
    followers = [name for name in space.names if (joint := model.joint(name)) is not None and joint.mimic is not None]
    return Plan(list(space.names), [(label, space.as_dict(row)) for label, row in rows], home, steps, followers)


def _pybullet(model: Model, samples: int, seed: int) -> tuple[Plan, EngineData]:
    from ar3cli.sim.capture import capture_fds
    from ar3cli.sim.session import Session

    with Session(gravity=GRAVITY) as session:
        body = session.load(model, visuals=False)
        plan = _plan(model, body, samples, seed)
        p, client = session.p, session.client
        data = EngineData("pybullet", plan.joints)
        # The base is welded to the world (useFixedBase): PyBullet reports its mass as 0 and MuJoCo fuses it
        # into the world's subtree; it moves nothing, so masses and the centre of mass leave it out in both.
        data.link_masses = {name: body.dynamics(name).mass for name in body.link_names[1:]}
        data.mass = sum(data.link_masses.values())
        zeros = [0.0] * len(plan.joints)
        multi = [joint for joint in body.joints if joint.urdf_type in MULTI_DOF_TYPES]
        if multi:
            data.notes.append(f"mass matrix and gravity torques not compared: joint '{multi[0].name}' is "
                              f"{multi[0].urdf_type} (ar3cli compares 1-DOF joints only)")
        for _, configuration in plan.configurations:
            body.set_positions(configuration)
            q = [configuration[name] for name in plan.joints]
            data.frames.append(body.link_frames())
            data.com.append(_pybullet_com(body))
            if plan.joints and not multi:
                with capture_fds() as captured:  # Bullet's inverse dynamics prints warnings from C (romeo: axes)
                    try:
                        matrix = p.calculateMassMatrix(body.id, q, physicsClientId=client)
                        torques = p.calculateInverseDynamics(body.id, q, zeros, zeros, physicsClientId=client)
                    except (p.error, SystemError) as exc:  # SystemError: its C code on absurd masses (1e30 kg)
                        raise UserError(f"{model.path}: pybullet's mass matrix failed ({exc})") from None
                data.mass_matrix.append([list(row) for row in matrix])
                data.gravity.append(list(torques))
                for message in captured.messages:
                    if message not in data.notes:
                        data.notes.append(f"PyBullet: {message}")
            else:
                data.mass_matrix.append([])
                data.gravity.append([])
        p.setGravity(0, 0, 0, physicsClientId=client)
        body.release_motors()
        by_name = {joint.name: joint.index for joint in body.actuated_joints}
        steps = round(DRIVE_SECONDS * 240)
        for leader, step in plan.steps.items():
            body.set_positions(plan.home)
            held = [(by_name[name], plan.home[name]) for name in plan.held(leader)]
            for _ in range(steps):
                p.resetJointState(body.id, by_name[leader], plan.home[leader] + step, 0.0, physicsClientId=client)
                for index, value in held:
                    p.resetJointState(body.id, index, value, 0.0, physicsClientId=client)
                session.step()
            data.driven[leader] = {name: value - plan.home[name] for name, value in zip(plan.joints, body.positions())}
    return plan, data


def _pybullet_com(body: Any) -> tuple[float, float, float]:
    """Mass-weighted centre of mass of every link but the (welded) base; ``getLinkState[0]`` is a link's COM."""
    p, client = body.session.p, body.session.client
    points: list[tuple[float, Any]] = []
    for joint in body.joints:
        points.append((body.dynamics(joint.link_name).mass,
                       p.getLinkState(body.id, joint.index, computeForwardKinematics=True, physicsClientId=client)[0]))
    total = sum(mass for mass, _ in points) or 1.0
    return tuple(sum(mass * point[k] for mass, point in points) / total for k in range(3))  # type: ignore[return-value]


def _mujoco(model: Model, plan: Plan) -> EngineData:
    from ar3cli.sim.mujoco_session import MjRobot

    robot = MjRobot(model, fuse=False, gravity=GRAVITY)
    data = EngineData("mujoco", plan.joints)
    missing = [name for name in plan.joints if name not in robot.joint_ids]
    if missing:
        data.notes.append("MuJoCo has no 1-DOF joint named " + listed(f"'{n}'" for n in missing))
    known = [name for name in plan.joints if name in robot.joint_ids]
    data.joints = known
    roots = model.root_links()
    root = roots[0].name if len(roots) == 1 else ""
    data.link_masses = {name: float(robot.m.body_mass[i]) for i, name in enumerate(robot.body_names)
                        if i > 0 and name != root}
    data.mass = sum(data.link_masses.values())
    moving = [i for i, name in enumerate(robot.body_names) if name in data.link_masses]
    for _, configuration in plan.configurations:
        robot.set_positions(configuration)
        data.frames.append(robot.link_frames())
        data.com.append(robot.centre_of_mass(moving))
        data.mass_matrix.append(robot.mass_matrix(known))
        data.gravity.append(robot.gravity_torques(known))
    data.extra = {"equalities": int(robot.m.neq), "armature": {n: float(robot.m.dof_armature[i])
                                                                for n, i in zip(known, robot.dof_indices(known))},
                  "substitutions": [f"link '{s.link}': {s.reason}; {s.replacement}" for s in robot.substitutions],
                  "fused": _fused_count(model)}
    robot.m.opt.gravity[:] = 0.0
    robot.m.opt.disableflags |= int(robot.mujoco.mjtDisableBit.mjDSBL_CONTACT)
    steps = round(DRIVE_SECONDS / robot.m.opt.timestep)
    for leader, step in plan.steps.items():
        if leader not in robot.joint_ids:
            continue
        robot.mujoco.mj_resetData(robot.m, robot.d)
        robot.set_positions(plan.home)
        targets = [(robot.m.jnt_qposadr[robot.joint_ids[name]], robot.m.jnt_dofadr[robot.joint_ids[name]],
                    plan.home[name] + (step if name == leader else 0.0))
                   for name in [leader, *plan.held(leader)] if name in robot.joint_ids]
        for _ in range(steps):
            for address, dof, value in targets:
                robot.d.qpos[address] = value
                robot.d.qvel[dof] = 0.0
            robot.step()
        data.driven[leader] = {name: value - plan.home[name] for name, value in zip(known, robot.positions(known))}
    return data


def _fused_count(model: Model) -> int:
    """Links MuJoCo's default compile (``fusestatic``) would merge into their parent: children of fixed joints."""
    return sum(joint.type == "fixed" for joint in model.joints)
