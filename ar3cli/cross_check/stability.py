"""cross-check --stability: a passive drop in both engines at two timesteps; energy growth is instability.

The robot (fixed base, PyBullet's default motors released) starts at rest at the home pose and
falls limp under gravity for :data:`SECONDS`. A passive mechanism can only lose energy (joint
damping, PyBullet's default link damping, MuJoCo's constraint softness), so total energy rising above
its start by more than :data:`GROWTH_SHARE` of ``m g L`` (the energy of lifting the robot by its
size), or a NaN, means the integrator is feeding energy in: an inertia too small for the
timestep, a degenerate mass. Two timesteps (the engine's default and half of it) show whether a
smaller step cures it.
"""

from __future__ import annotations

import math
from typing import Any

from ar3cli.errors import UserError
from ar3cli.urdf.model import Model

SECONDS = 1.0
GROWTH_SHARE = 0.05
PYBULLET_STEPS = (1.0 / 240.0, 1.0 / 480.0)
MUJOCO_STEPS = (0.002, 0.001)


def drop_pybullet(model: Model) -> list[dict[str, Any]]:
    from ar3cli.sim.session import run_pybullet

    return run_pybullet(lambda: [_pybullet_drop(model, step) for step in PYBULLET_STEPS], model)


def drop_mujoco(model: Model) -> list[dict[str, Any]]:
    from ar3cli.sim.mujoco_session import run_mujoco

    return run_mujoco(lambda: [_mujoco_drop(model, step) for step in MUJOCO_STEPS], model)


def _verdict(engine: str, step: float, energies: list[float], scale: float) -> dict[str, Any]:
    finite = all(math.isfinite(e) for e in energies)
    growth = max(energies) - energies[0] if finite else math.inf
    stable = finite and growth <= GROWTH_SHARE * scale
    return {"engine": engine, "timestep": step, "energy_start": energies[0] if finite else None,
            "energy_growth": growth if finite else None, "allowed_growth": GROWTH_SHARE * scale, "stable": stable}


def _pybullet_drop(model: Model, step: float) -> dict[str, Any]:
    import numpy as np

    from ar3cli.sim.sampling import home_positions
    from ar3cli.sim.session import Session

    with Session(gravity=-9.81, timestep=step) as session:
        body = session.load(model, visuals=False)
        p, client = session.p, session.client
        body.set_positions(home_positions(body))
        body.release_motors()
        masses = [body.dynamics(name).mass for name in body.link_names]
        indices = [joint.index for joint in body.joints]

        def energy() -> float:
            states = p.getLinkStates(body.id, indices, physicsClientId=client) if indices else []
            heights = [p.getBasePositionAndOrientation(body.id, physicsClientId=client)[0][2],
                       *(state[0][2] for state in states)]
            potential = sum(m * 9.81 * z for m, z in zip(masses, heights))
            joints = body.joint_states()
            if not joints:
                return potential
            q, qd = [s[0] for s in joints], np.array([s[1] for s in joints])
            try:
                matrix = np.array(p.calculateMassMatrix(body.id, q, physicsClientId=client))
            except (p.error, SystemError) as exc:  # SystemError: its C code on absurd masses (1e30 kg)
                raise UserError(f"{model.path}: pybullet's mass matrix failed ({exc})") from None
            return potential + 0.5 * float(qd @ matrix @ qd)

        frames = body.link_frames()
        scale = sum(masses) * 9.81 * max(0.1, *(math.hypot(*pose[0]) for pose in frames.values()))
        energies = [energy()]
        for _ in range(round(SECONDS / step)):
            session.step()
            energies.append(energy())
            if not math.isfinite(energies[-1]):
                break
        return _verdict("pybullet", step, energies, scale)


def _mujoco_drop(model: Model, step: float) -> dict[str, Any]:
    from ar3cli.sim.mujoco_session import MjRobot, home_pose

    robot = MjRobot(model, fuse=False)
    robot.m.opt.timestep = step
    robot.set_positions(home_pose(model))
    frames = robot.link_frames()
    scale = robot.total_mass() * 9.81 * max(0.1, *(math.hypot(*pose[0]) for pose in frames.values()))
    energies = [robot.energy()]
    for _ in range(round(SECONDS / step)):
        robot.step()
        energies.append(robot.energy())
        if not math.isfinite(energies[-1]):
            break
    return _verdict("mujoco", step, energies, scale)

