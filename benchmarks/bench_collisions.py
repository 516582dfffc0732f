"""Benchmark sample-collisions' hot path against the tutorial loop, on pybullet_data's franka_panda.

Baseline (same process, same configurations, same all-pairs flags): the tutorial loop, i.e.
resetJointState per joint, stepSimulation, getContactPoints(body, body). Ours: Checker.count
(resetJointStatesMultiDof + performCollisionDetection + one getContactPoints), one job, then
count_collisions with --jobs 2 (processes). Prints configurations per second and the ratios.

    python benchmarks/bench_collisions.py [--samples 10000] [--repeat 3]

Best of ``--repeat`` runs each, since other work on the machine only ever slows a run down.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from ar3cli.collisions.checker import Checker, ModelSource, count_collisions, sample_configurations  # noqa: E402 - after the sys.path line that finds ar3cli
from ar3cli.sim.session import Session  # noqa: E402 - after the sys.path line that finds ar3cli
from ar3cli.urdf.model import load_model  # noqa: E402 - after the sys.path line that finds ar3cli


def tutorial_loop(model, configs) -> float:
    """The loop from the tutorials; returns seconds."""
    with Session() as session:
        p, client = session.p, session.client
        body = session.load(model, self_collision="all-pairs")
        joints = [joint.index for joint in body.movable_joints]
        start = time.perf_counter()
        for q in configs:
            for index, value in zip(joints, q):
                p.resetJointState(body.id, index, value, physicsClientId=client)
            p.stepSimulation(physicsClientId=client)
            p.getContactPoints(body.id, body.id, physicsClientId=client)
        return time.perf_counter() - start


def best(function, repeat: int) -> float:
    return min(function() for _ in range(repeat))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=10_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    import pybullet_data

    path = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"
    model, source = load_model(path), ModelSource(path)
    with Checker(model) as checker:
        configs = sample_configurations(checker.joint_space(), args.samples, seed=0)
        baseline = best(lambda: tutorial_loop(model, configs), args.repeat)

        def timed(jobs: int) -> float:
            start = time.perf_counter()
            count_collisions(checker, source, configs, jobs=jobs)
            return time.perf_counter() - start

        one = best(lambda: timed(1), args.repeat)
        two = best(lambda: timed(2), args.repeat)
    n = args.samples
    print(f"panda, {n} configurations, best of {args.repeat}")
    print(f"baseline tutorial loop (reset per joint + stepSimulation): {n / baseline:9,.0f} configs/s")
    print(f"ours, --jobs 1:                                          {n / one:9,.0f} configs/s"
          f"  ({baseline / one:.2f}x baseline, goal >= 2x)")
    print(f"ours, --jobs 2:                                          {n / two:9,.0f} configs/s"
          f"  ({one / two:.2f}x --jobs 1, goal >= 1.7x)")


if __name__ == "__main__":
    main()
