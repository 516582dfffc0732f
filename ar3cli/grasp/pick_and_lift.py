"""The headless pick-and-lift demo: the AR3 picks up the cube with friction alone.

One run (:func:`run_grasp`) builds a scene (ground plane, the AR3 on a fixed base, the cube at
a seeded pose), then drives the arm through five phases with joint POSITION_CONTROL:

    approach  home -> 10 cm above the cube, gripper pointing down, jaw square to the cube
    descend   straight down until the tcp is at the cube's centre (5 mm higher, off the ground)
    close     fingers close with a bounded force (default 20 N of the model's 30 N effort)
    lift      straight up 10 cm
    hold      keep still for 1 s

Nothing is teleported after the start and nothing glues the cube to the gripper: the arm only
gets motor targets, and friction between the pads and the cube does the holding.

Inverse kinematics follows ``shared/docs/pybullet-facts.md`` section 8, which tutorials get
wrong: the keyword is ``maxNumIterations`` (``maxIter=`` raises TypeError), and the null-space
lists are used only when all four have one entry per movable DOF (8 here: 6 arm joints and 2
fingers), otherwise pybullet silently ignores them. IK runs in a *separate* IK-only physics
client, so the simulated arm is never reset: the IK body is set to the solution and solved
again from there (with the rest pose moved to the current solution, so the null-space pull
does not bias the answer). The result is clamped to the joint limits, since the limits are
only a soft penalty inside pybullet's solver.

Determinism: the cube pose comes from ``numpy.random.default_rng(seed)`` and every pybullet
call is made in the same order, so the same seed gives the same result; only wall-clock
fields differ.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from ar3cli.errors import UserError

TIMESTEP = 1.0 / 240.0
GRAVITY = -9.81
ARM_JOINTS = ("joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6")
FINGER_JOINTS = ("gripper_finger_left", "gripper_finger_right")
FINGER_LINKS = ("finger_left", "finger_right")
TCP_LINK = "tcp"
READY_POSE = (0.0, 1.0, 1.4, 0.0, 0.7, 0.0)
"""IK seed and rest pose: arm bent forward over the workspace, wrist bent (away from the
joint_5 = 0 singularity where joint_4 and joint_6 line up and the solver stalls)."""

PHASES = ("approach", "descend", "close", "lift", "hold")


@dataclass(frozen=True)
class GraspSettings:
    """Everything that shapes one run; the defaults are the demo the docs describe.

    The default region (cube 0.28-0.40 m from the base axis, within 35 deg of the arm's front,
    the -y axis) is where the IK solution with the gripper pointing down converges to < 0.1 mm
    for every yaw (measured on a 5 cm grid; closer than 0.25 m the arm cannot fold enough).
    """

    radius_range: tuple[float, float] = (0.28, 0.40)  # m from the base z axis
    azimuth_range: tuple[float, float] = (math.radians(-125.0), math.radians(-55.0))  # front is -y
    yaw_range: tuple[float, float] = (math.radians(-45.0), math.radians(45.0))
    gripper_force: float = 20.0  # N per finger, bounded by the finger effort limit
    squeeze_target: float = 0.03  # finger joint target (m): pads meet a 45 mm cube at ~0.0175
    hover_height: float = 0.10  # m above the grasp point
    grasp_offset: float = 0.005  # tcp this much above the cube centre: fingertips clear the ground
    lift_height: float = 0.10  # m
    hold_time: float = 1.0  # s
    cartesian_speed: float = 0.08  # m/s for descend and lift
    joint_speed_fraction: float = 0.6  # of each joint's velocity limit, for the approach
    settle_time: float = 0.25  # s after each move
    close_time: float = 0.6  # s for the fingers to close and squeeze
    ik_tolerance: float = 0.002  # m: a target further than this from the IK solution is unreachable
    success_rise: float = 0.05  # m the cube must end above its start
    centring_span: float = 0.003  # m of finger asymmetry that shifts the whole squeeze to one finger


@dataclass
class PhaseResult:
    """The state at the end of one phase. Lengths in m, times in s."""

    name: str
    sim_time_s: float
    tcp_error_m: float
    gripper_opening_m: float
    cube_height_m: float
    ok: bool
    detail: str = ""


@dataclass
class GraspResult:
    """One run: the verdict, the phases, and the timing."""

    success: bool
    seed: int
    cube_start: list[float]
    cube_yaw_deg: float
    lift_height_m: float
    steps: int
    sim_time_s: float
    wall_time_s: float
    phases: list[PhaseResult] = field(default_factory=list)
    failed_phase: str | None = None
    reason: str = ""
    cube_between_fingers: bool = False

    @property
    def realtime_factor(self) -> float:
        return self.sim_time_s / self.wall_time_s if self.wall_time_s > 0 else math.inf

    def to_dict(self) -> dict[str, Any]:
        """The JSON document of one run (``wall_time_s``/``realtime_factor`` vary between runs)."""
        return {
            "success": self.success,
            "seed": self.seed,
            "cube_start": self.cube_start,
            "cube_yaw_deg": self.cube_yaw_deg,
            "lift_height_m": self.lift_height_m,
            "cube_between_fingers": self.cube_between_fingers,
            "steps": self.steps,
            "sim_time_s": self.sim_time_s,
            "wall_time_s": round(self.wall_time_s, 4),
            "realtime_factor": round(self.realtime_factor, 1),
            "failed_phase": self.failed_phase,
            "reason": self.reason,
            "phases": [asdict(phase) for phase in self.phases],
        }


WALL_CLOCK_FIELDS = ("wall_time_s", "realtime_factor")


def sample_cube_pose(seed: int, settings: GraspSettings) -> tuple[np.ndarray, float]:
    """Seeded cube centre (x, y on the ground) and yaw inside the default region."""
    rng = np.random.default_rng(seed)
    radius = rng.uniform(*settings.radius_range)
    azimuth = rng.uniform(*settings.azimuth_range)
    yaw = rng.uniform(*settings.yaw_range)
    return np.array([radius * math.cos(azimuth), radius * math.sin(azimuth)]), float(yaw)


def gripper_yaw(cube_yaw: float, position_xy: Sequence[float]) -> float:
    """Yaw of the gripper-down orientation ``Rz(yaw) * Ry(pi)`` that squares the jaw to the cube.

    With that orientation the jaw closes along ``Rz(yaw) * y``; the arm reaches the point
    naturally (joint_4 + joint_6 near 0) at ``yaw = azimuth + 90 deg``. A cube looks the same
    every 90 deg, so pick the face pair closest to the natural yaw: the wrist turns < 45 deg.
    """
    natural = math.atan2(position_xy[1], position_xy[0]) + math.pi / 2
    quarter = math.pi / 2
    return cube_yaw + quarter * round((natural - cube_yaw) / quarter)


class IKSolver:
    """pybullet's calculateInverseKinematics on an IK-only copy of the arm.

    The copy is loaded into the given session (a second connection costs ~25 ms, a second
    load ~10 ms) and must be removed with :meth:`close` before the simulation steps: it is
    reset to each iterate and solved again, which is never done to the simulated arm.
    """

    def __init__(self, session: Any, model: Any, tcp_link: str = TCP_LINK, iterations: int = 8) -> None:
        self.session = session
        self.body = session.load(model, fixed_base=True, visuals=False)  # IK never draws: loads faster
        self.p, self.client = session.p, session.client
        self.tcp = self.body.link_index[tcp_link]
        movable = self.body.actuated_joints
        self.lower = [joint.lower if joint.lower is not None else -math.pi for joint in movable]
        self.upper = [joint.upper if joint.upper is not None else math.pi for joint in movable]
        self.ranges = [hi - lo for lo, hi in zip(self.lower, self.upper)]
        self.iterations = iterations

    def close(self) -> None:
        """Remove the IK copy from the world."""
        if self.body is not None:
            self.body.remove()
            self.body = None

    def solve(self, position: Sequence[float], orientation: Sequence[float],
              seed: Sequence[float]) -> tuple[np.ndarray, float]:
        """Joint positions (all movable DOF, clamped to limits) reaching the pose; and the tcp error in m.

        ``seed`` (one value per movable DOF) is the start and the first rest pose; later
        passes use the current iterate as rest pose, so the null-space term does not pull
        the answer away from the exact solution.
        """
        p, client = self.p, self.client
        q = np.clip(np.asarray(seed, dtype=float), self.lower, self.upper)
        self.body.set_positions(q)
        rest = list(q)
        error = math.inf
        for _ in range(self.iterations):
            solution = p.calculateInverseKinematics(
                self.body.id, self.tcp, list(position), list(orientation),
                lowerLimits=self.lower, upperLimits=self.upper, jointRanges=self.ranges, restPoses=rest,
                maxNumIterations=100, residualThreshold=1e-6, physicsClientId=client)
            q = np.clip(np.asarray(solution, dtype=float), self.lower, self.upper)
            self.body.set_positions(q)
            rest = list(q)
            error = self.tcp_error(position)
            if error < 1e-5:
                break
        return q, error

    def tcp_error(self, position: Sequence[float]) -> float:
        state = self.p.getLinkState(self.body.id, self.tcp, computeForwardKinematics=True,
                                    physicsClientId=self.client)
        return float(np.linalg.norm(np.asarray(state[4]) - np.asarray(position)))


class PhaseFailed(Exception):
    """Raised inside a run when a phase's check fails; carries the phase name and why."""

    def __init__(self, phase: str, reason: str) -> None:
        super().__init__(f"{phase}: {reason}")
        self.phase = phase
        self.reason = reason


FrameHook = Callable[[Any, int], None]
"""Called as ``hook(scene, step)`` after every simulation step (the GIF recorder uses it)."""


class GraspScene:
    """The simulated world of one run and the controller that drives it."""

    def __init__(self, seed: int, settings: GraspSettings, gui: bool = False,
                 frame_hook: FrameHook | None = None, realtime: bool = False) -> None:
        from ar3cli.infra.assets import asset
        from ar3cli.sim.session import Session
        from ar3cli.urdf.model import load_model

        self.settings = settings
        self.frame_hook = frame_hook
        self.realtime = realtime
        self.session = Session(gui=gui, gravity=GRAVITY, timestep=TIMESTEP)
        self.p, self.client = self.session.p, self.session.client
        p, client = self.p, self.client
        try:
            arm_model = load_model(asset("ar3/ar3.urdf"))
            cube_model = load_model(asset("objects/cube.urdf"))
            self.ground = make_ground(p, client)
            # the visual meshes only matter to a picture (--gui, --record's frame hook): without one
            # the arm loads without them, which changes no contact, mass or frame
            drawn = gui or frame_hook is not None
            self.arm = self.session.load(arm_model, fixed_base=True, visuals=drawn)
            self.cube_half = cube_model.links[0].collisions[0].geometry.params["size"][2] / 2
            xy, self.cube_yaw = sample_cube_pose(seed, settings)
            self.cube_start = np.array([xy[0], xy[1], self.cube_half])
            # a plain rigid body (maximal coordinates), not a one-link multibody: the grasp
            # phases' contact steps are ~30% cheaper (measured 116 vs 168 us per step)
            self.cube = self.session.load(cube_model, fixed_base=False, base_position=self.cube_start,
                                          base_orientation=p.getQuaternionFromEuler([0, 0, self.cube_yaw]),
                                          maximal_coordinates=True, visuals=drawn)
            self.arm_model = arm_model
            # Friction anchors on the pads and the cube: without them pybullet's contact
            # friction lets a squeezed box creep and tilt (measured: 5-18 deg and up to 1 cm of
            # slip during a 1 s hold with the default 50 solver iterations). An anchor keeps
            # the contact point fixed while it sticks; it is friction, not a constraint.
            for link in (self.arm.link_index[name] for name in FINGER_LINKS):
                p.changeDynamics(self.arm.id, link, frictionAnchor=1, physicsClientId=client)
            p.changeDynamics(self.cube.id, -1, frictionAnchor=1, physicsClientId=client)
        except Exception:
            self.session.close()
            raise
        joints = {joint.name: joint for joint in self.arm.joints}
        self.arm_joints = [joints[name] for name in ARM_JOINTS]
        self.finger_joints = [joints[name] for name in FINGER_JOINTS]
        self.arm_indices = [joint.index for joint in self.arm_joints]
        self.finger_indices = [joint.index for joint in self.finger_joints]
        self.arm_position_gains = [0.3] * len(self.arm_joints)
        self.arm_velocity_gains = [1.0] * len(self.arm_joints)
        self.arm_forces = [joint.effort for joint in self.arm_joints]
        self.arm_velocity = np.array([joint.velocity for joint in self.arm_joints])
        self.tcp = self.arm.link_index[TCP_LINK]
        self.finger_links = [self.arm.link_index[name] for name in FINGER_LINKS]
        self.movable_names = [joint.name for joint in self.arm.actuated_joints]
        self.steps = 0
        self.wall_start = time.perf_counter()
        self.target_q = np.zeros(len(ARM_JOINTS))
        self.finger_target = 0.0
        self.squeezing = False
        self.command_fingers(0.0, self.finger_joints[0].effort)

    def close(self) -> None:
        self.session.close()

    # --- state -------------------------------------------------------------------------
    def arm_q(self) -> np.ndarray:
        states = self.p.getJointStates(self.arm.id, self.arm_indices, physicsClientId=self.client)
        return np.array([state[0] for state in states])

    def full_q(self, arm_q: Sequence[float]) -> list[float]:
        """A movable-DOF vector (IK order) from arm joint values and the current finger targets."""
        by_name = dict(zip(ARM_JOINTS, arm_q))
        return [by_name.get(name, self.finger_target) for name in self.movable_names]

    def tcp_position(self) -> np.ndarray:
        state = self.p.getLinkState(self.arm.id, self.tcp, computeForwardKinematics=True,
                                    physicsClientId=self.client)
        return np.asarray(state[4])

    def cube_pose(self) -> tuple[np.ndarray, tuple[float, ...]]:
        position, orientation = self.p.getBasePositionAndOrientation(self.cube.id, physicsClientId=self.client)
        return np.asarray(position), orientation

    def gripper_opening(self) -> float:
        """Distance between the pads' inner faces (the finger link frames sit on them)."""
        states = self.p.getLinkStates(self.arm.id, self.finger_links, computeForwardKinematics=True,
                                      physicsClientId=self.client)
        return float(np.linalg.norm(np.asarray(states[0][4]) - np.asarray(states[1][4])))

    def fingers_touching_cube(self) -> list[bool]:
        """Whether each finger has a contact point with the cube (from the last step)."""
        points = self.p.getContactPoints(self.arm.id, self.cube.id, physicsClientId=self.client)
        touched = {point[3] for point in points}
        return [link in touched for link in self.finger_links]

    def cube_between_fingers(self) -> bool:
        """The cube centre lies inside the jaw in the tcp frame, and both pads touch it."""
        state = self.p.getLinkState(self.arm.id, self.tcp, computeForwardKinematics=True,
                                    physicsClientId=self.client)
        inverse = self.p.invertTransform(state[4], state[5])
        centre, _ = self.cube_pose()
        local, _ = self.p.multiplyTransforms(inverse[0], inverse[1], centre.tolist(), [0, 0, 0, 1])
        half_opening = self.gripper_opening() / 2
        inside = abs(local[1]) < half_opening and abs(local[0]) < 0.011 + self.cube_half \
            and -0.0225 - self.cube_half < local[2] < 0.0325
        return inside and all(self.fingers_touching_cube())

    # --- motion ------------------------------------------------------------------------
    def command_fingers(self, target: float, force: float) -> None:
        """Both fingers to ``target`` (0 open, 0.04 closed) with at most ``force`` N and the velocity limit."""
        self.finger_target = target
        for joint in self.finger_joints:
            self.p.setJointMotorControl2(self.arm.id, joint.index, self.p.POSITION_CONTROL, targetPosition=target,
                                         force=force, maxVelocity=joint.velocity, positionGain=0.3,
                                         velocityGain=1.0, physicsClientId=self.client)

    def centre_fingers(self) -> None:
        """Share the squeeze between the fingers so the jaw stays centred on the tcp.

        The two fingers are independent joints; both push with the same saturated force, so
        the pair and the cube are in neutral balance and drift sideways together (measured:
        6 mm in 3 s). A real parallel gripper couples its jaws mechanically. Here the total
        force stays ``2 * gripper_force`` and moves towards the finger that is behind, each
        finger's force within [0, effort]: a proportional coupling, not a constraint.
        """
        p, client, arm = self.p, self.client, self.arm.id
        states = p.getJointStates(arm, self.finger_indices, physicsClientId=client)
        share = (states[0][0] - states[1][0]) / self.settings.centring_span
        force, target, control = self.settings.gripper_force, self.finger_target, p.POSITION_CONTROL
        for joint, sign in zip(self.finger_joints, (-1.0, 1.0)):
            bounded = min(joint.effort, max(0.0, force * (1.0 + sign * share)))
            p.setJointMotorControl2(arm, joint.index, control, targetPosition=target, force=bounded,
                                    maxVelocity=joint.velocity, positionGain=0.3, velocityGain=1.0,
                                    physicsClientId=client)

    def command_arm(self, q: Sequence[float], qdot: Sequence[float]) -> None:
        self.target_q = np.asarray(q, dtype=float)
        self._send_arm(self.target_q.tolist(), np.asarray(qdot, dtype=float).tolist())

    def _send_arm(self, q: list[float], qdot: list[float]) -> None:
        """The arm's position-control command (plain float lists: the per-step call of a move)."""
        self.p.setJointMotorControlArray(self.arm.id, self.arm_indices, self.p.POSITION_CONTROL,
                                         targetPositions=q, targetVelocities=qdot, forces=self.arm_forces,
                                         positionGains=self.arm_position_gains,
                                         velocityGains=self.arm_velocity_gains, physicsClientId=self.client)

    def step(self) -> None:
        if self.squeezing:
            self.centre_fingers()
        self.p.stepSimulation(physicsClientId=self.client)
        self.steps += 1
        if self.frame_hook is not None:
            self.frame_hook(self, self.steps)
        if self.realtime:
            lag = self.steps * TIMESTEP - (time.perf_counter() - self.wall_start)
            if lag > 0:
                time.sleep(lag)

    def move_joints(self, waypoints: Sequence[np.ndarray], durations: Sequence[float]) -> None:
        """Follow joint waypoints with linear interpolation (feed-forward velocity), then settle."""
        start = self.target_q
        for goal, duration in zip(waypoints, durations):
            count = max(1, round(duration / TIMESTEP))
            velocity = ((goal - start) / (count * TIMESTEP)).tolist()
            # every step's target at once: start + (goal - start) * (i / count), the same floats
            # as one numpy expression per step, without its per-step cost
            fractions = np.arange(1, count + 1) / count
            for target in (start + (goal - start) * fractions[:, None]).tolist():
                self._send_arm(target, velocity)
                self.step()
            start = goal
        self.command_arm(start, np.zeros_like(start))
        self.wait(self.settings.settle_time)

    def wait(self, duration: float) -> None:
        for _ in range(round(duration / TIMESTEP)):
            self.step()

    def joint_move_duration(self, start: np.ndarray, goal: np.ndarray) -> float:
        """Time for a joint move at a fraction of each joint's velocity limit (the slowest joint sets it)."""
        speed = self.arm_velocity * self.settings.joint_speed_fraction
        return max(0.5, float(np.max(np.abs(goal - start) / speed)))

    def solve(self, ik: IKSolver, position: np.ndarray, orientation: Sequence[float], seed_q: Sequence[float],
              phase: str) -> np.ndarray:
        """Arm joint values reaching the tcp pose, or PhaseFailed when IK cannot get within tolerance."""
        best_q, best_error = None, math.inf
        for seed in (seed_q, READY_POSE):
            q, error = ik.solve(position, orientation, self.full_q(seed))
            if error < best_error:
                best_q, best_error = q, error
            if error <= self.settings.ik_tolerance:
                break
        if best_error > self.settings.ik_tolerance:
            raise PhaseFailed(phase, f"IK cannot reach {fmt_xyz(position)} with the gripper down "
                                     f"(best {best_error * 1000:.1f} mm away)")
        by_name = dict(zip(self.movable_names, best_q))
        return np.array([by_name[name] for name in ARM_JOINTS])

    def cartesian_path(self, ik: IKSolver, start: np.ndarray, goal: np.ndarray, orientation: Sequence[float],
                       seed_q: np.ndarray, phase: str) -> tuple[list[np.ndarray], list[float]]:
        """IK waypoints every 2 cm along a straight tcp line, and the time for each segment.

        With joint-space interpolation between waypoints 2 cm apart the simulated tcp stays
        within 0.25 mm of the vertical line (measured, seeds 0-4, tracking lag included):
        finer waypoints would only cost IK time.
        """
        distance = float(np.linalg.norm(goal - start))
        count = max(1, math.ceil(distance / 0.02))
        waypoints, q = [], seed_q
        for i in range(1, count + 1):
            q = self.solve(ik, start + (goal - start) * (i / count), orientation, q, phase)
            waypoints.append(q)
        return waypoints, [distance / count / self.settings.cartesian_speed] * count


def demo_camera(seed: int, settings: GraspSettings) -> dict[str, Any]:
    """A fixed camera for the GIF: from the side of the arm's reach, looking at base and cube.

    The arm moves in the vertical plane through the base and the cube, so the camera looks
    across that plane (yaw = the cube's azimuth), from slightly above, at the point halfway
    out at 32 cm height: base, cube and the 10 cm lift are all in view.
    """
    xy, _ = sample_cube_pose(seed, settings)
    azimuth = math.degrees(math.atan2(xy[1], xy[0]))
    return {"target": [0.5 * xy[0], 0.5 * xy[1], 0.32], "distance": 1.25, "yaw_deg": azimuth,
            "pitch_deg": -18.0}


def make_ground(p: Any, client: int) -> int:
    """A static 3 m x 3 m slab whose top face is the z = 0 plane.

    A box, not GEOM_PLANE: creating a plane body costs ~14 ms in DIRECT (its visual is built
    for the renderer), a box 0.2 ms; the demo's whole budget is ~0.3 s.
    """
    half = [1.5, 1.5, 0.01]
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=[0.82, 0.84, 0.86, 1],
                                 physicsClientId=client)
    return p.createMultiBody(0, shape, visual, basePosition=[0, 0, -half[2]], physicsClientId=client)


def fmt_xyz(position: Sequence[float]) -> str:
    return "(" + ", ".join(f"{v:.3f}" for v in position) + ") m"


class GraspRun:
    """Runs the phases on a :class:`GraspScene` and records a :class:`PhaseResult` after each."""

    def __init__(self, scene: GraspScene) -> None:
        self.scene = scene
        self.phases: list[PhaseResult] = []

    def record(self, name: str, target: np.ndarray, ok: bool = True, detail: str = "") -> PhaseResult:
        scene = self.scene
        phase = PhaseResult(
            name=name, sim_time_s=round(scene.steps * TIMESTEP, 6),
            tcp_error_m=round(float(np.linalg.norm(scene.tcp_position() - target)), 6),
            gripper_opening_m=round(scene.gripper_opening(), 6),
            cube_height_m=round(float(scene.cube_pose()[0][2]), 6), ok=ok, detail=detail)
        self.phases.append(phase)
        if not ok:
            raise PhaseFailed(name, detail)
        return phase

    def run(self) -> None:
        scene, settings = self.scene, self.scene.settings
        p = scene.p
        start = scene.cube_start
        yaw = gripper_yaw(scene.cube_yaw, start[:2])
        down = p.getQuaternionFromEuler([0.0, math.pi, yaw])
        grasp = start + np.array([0.0, 0.0, settings.grasp_offset])
        hover = grasp + np.array([0.0, 0.0, settings.hover_height])
        lifted = grasp + np.array([0.0, 0.0, settings.lift_height])

        # plan every move before the first step, with the IK copy, then remove it
        ik = IKSolver(scene.session, scene.arm_model)
        try:
            q_hover = scene.solve(ik, hover, down, READY_POSE, "approach")
            descend_path, descend_times = scene.cartesian_path(ik, hover, grasp, down, q_hover, "descend")
            lift_path, lift_times = scene.cartesian_path(ik, grasp, lifted, down, descend_path[-1], "lift")
        finally:
            ik.close()

        # approach: one joint-space move from home to the hover pose
        scene.move_joints([q_hover], [scene.joint_move_duration(scene.arm_q(), q_hover)])
        self.check_tracking("approach", hover, start)

        # descend: straight down
        scene.move_joints(descend_path, descend_times)
        self.check_tracking("descend", grasp, start)

        # close: bounded force, target past the contact point so the pads squeeze
        scene.command_fingers(settings.squeeze_target, settings.gripper_force)
        scene.squeezing = True
        scene.wait(settings.close_time)
        touching = scene.fingers_touching_cube()
        opening = scene.gripper_opening()
        if not all(touching):
            which = " and ".join(name for name, t in zip(("left", "right"), touching) if not t) or "no"
            self.record("close", grasp, False, f"{which} pad not touching the cube "
                                              f"(jaw {opening * 1000:.1f} mm open)")
        self.record("close", grasp)

        # lift: straight up with the cube
        scene.move_joints(lift_path, lift_times)
        self.check_held("lift", lifted)

        # hold
        scene.wait(settings.hold_time)
        self.check_held("hold", lifted)

    def check_tracking(self, name: str, target: np.ndarray, cube_start: np.ndarray) -> None:
        """The tcp reached its target (within 5 mm) and the cube was not knocked (within 1 cm)."""
        scene = self.scene
        error = float(np.linalg.norm(scene.tcp_position() - target))
        moved = float(np.linalg.norm(scene.cube_pose()[0] - cube_start))
        if error > 0.005:
            self.record(name, target, False, f"tcp {error * 1000:.1f} mm from its target (arm too slow or blocked)")
        if moved > 0.01:
            self.record(name, target, False, f"the arm knocked the cube {moved * 100:.1f} cm off its start")
        self.record(name, target)

    def check_held(self, name: str, target: np.ndarray) -> None:
        """The cube rose with the gripper and is still between the pads."""
        scene = self.scene
        rise = float(scene.cube_pose()[0][2] - scene.cube_start[2])
        if rise < scene.settings.success_rise:
            self.record(name, target, False, f"cube slipped, ended {max(rise, 0.0) * 100:.1f} cm above its start "
                                             f"(needs {scene.settings.success_rise * 100:.0f} cm)")
        if not scene.cube_between_fingers():
            self.record(name, target, False, "cube is no longer between the fingers")
        self.record(name, target)


def run_grasp(seed: int = 0, settings: GraspSettings | None = None, gui: bool = False,
              frame_hook: FrameHook | None = None) -> GraspResult:
    """One pick-and-lift; never raises for a failed grasp (the result says which phase failed)."""
    settings = settings or GraspSettings()
    if not settings.gripper_force > 0:
        raise UserError(f"--gripper-force must be positive, got {settings.gripper_force}")
    import ar3cli.urdf.model  # noqa: F401 - imports are a one-off per process, not the demo's time
    from ar3cli.sim.session import import_pybullet

    import_pybullet()
    wall_start = time.perf_counter()
    scene = GraspScene(seed, settings, gui=gui, frame_hook=frame_hook, realtime=gui)
    try:
        finger_effort = scene.finger_joints[0].effort
        if settings.gripper_force > finger_effort:
            raise UserError(f"--gripper-force {settings.gripper_force:g} N exceeds the finger effort limit "
                            f"{finger_effort:g} N in the model")
        run = GraspRun(scene)
        failed_phase, reason = None, ""
        try:
            run.run()
        except PhaseFailed as failure:
            failed_phase, reason = failure.phase, failure.reason
        cube_end = scene.cube_pose()[0]
        between = scene.cube_between_fingers()
        result = GraspResult(
            success=failed_phase is None, seed=seed,
            cube_start=[round(float(v), 6) for v in scene.cube_start],
            cube_yaw_deg=round(math.degrees(scene.cube_yaw), 3),
            lift_height_m=round(float(cube_end[2] - scene.cube_start[2]), 6),
            steps=scene.steps, sim_time_s=round(scene.steps * TIMESTEP, 6),
            wall_time_s=0.0, phases=run.phases, failed_phase=failed_phase, reason=reason,
            cube_between_fingers=between)
    finally:
        scene.close()
    result.wall_time_s = time.perf_counter() - wall_start
    return result


@dataclass
class TrialsResult:
    """N runs on consecutive seeds."""

    seed: int
    runs: list[GraspResult]

    @property
    def successes(self) -> int:
        return sum(run.success for run in self.runs)

    @property
    def success_rate(self) -> float:
        return self.successes / len(self.runs) if self.runs else 0.0

    def to_dict(self) -> dict[str, Any]:
        sim = sum(run.sim_time_s for run in self.runs)
        wall = sum(run.wall_time_s for run in self.runs)
        return {
            "trials": len(self.runs), "successes": self.successes, "success_rate": self.success_rate,
            "seed": self.seed, "sim_time_s": round(sim, 6), "wall_time_s": round(wall, 4),
            "realtime_factor": round(sim / wall, 1) if wall > 0 else None,
            "failures": [{"seed": run.seed, "phase": run.failed_phase, "reason": run.reason}
                         for run in self.runs if not run.success],
            "runs": [run.to_dict() for run in self.runs],
        }


def run_trials(seed: int, trials: int, settings: GraspSettings | None = None,
               progress: Callable[[GraspResult], None] | None = None) -> TrialsResult:
    """Seeds ``seed, seed+1, ..., seed+trials-1``."""
    runs = []
    for offset in range(trials):
        result = run_grasp(seed + offset, settings)
        runs.append(result)
        if progress is not None:
            progress(result)
    return TrialsResult(seed, runs)


def strip_wall_clock(data: dict[str, Any]) -> dict[str, Any]:
    """A run's JSON without the fields that legitimately change between identical runs."""
    return {key: value for key, value in data.items() if key not in WALL_CLOCK_FIELDS}


__all__ = ["GraspSettings", "GraspResult", "PhaseResult", "TrialsResult", "run_grasp", "run_trials",
           "sample_cube_pose", "gripper_yaw", "IKSolver", "PHASES", "strip_wall_clock"]
