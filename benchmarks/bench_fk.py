"""Time ``ar3cli fk-verify`` as a user runs it, against a plain pybullet getLinkState loop.

Whole processes, alternating, warm-up first (see ``benchmarks/_timing.py``):

* A: ``ar3cli fk-verify ROBOT --samples N`` (text output, as a user reads it);
* B: the same with ``--format json`` (its exit code is checked: 0 = every frame agreed);
* C: the plain script: ``loadURDF(useFixedBase=True)``, N uniform configurations within the joint
  limits (numpy, seed 0), per configuration ``resetJointState`` for each movable joint and
  ``getLinkState(body, i, computeForwardKinematics=True)`` for each link; it prints its loop time.

The plain script only reads PyBullet's frames. fk-verify does that too (the frame, not the centre
of mass) and also computes every frame independently from the URDF (vectorised numpy) and compares
the two, which is the point of the command; so the ratio is the price of the check, start-up included.

Usage (inside the project's venv)::

    python benchmarks/bench_fk.py                     # panda, 1,000 samples, 5 runs
    python benchmarks/bench_fk.py --samples 10000 --runs 9
    python benchmarks/bench_fk.py --robot path/to/robot.urdf
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _timing  # noqa: E402 - after the sys.path line that finds it

BASELINE = r'''
"""Plain pybullet forward kinematics: getLinkState(computeForwardKinematics=True) per link."""
import json, math, sys, time
import numpy as np
import pybullet as p

path, samples, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
p.connect(p.DIRECT)
body = p.loadURDF(path, useFixedBase=True)
links = range(p.getNumJoints(body))
joints, low, high = [], [], []
for i in links:
    info = p.getJointInfo(body, i)
    if info[2] in (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC):
        lower, upper = info[8], info[9]
        if upper < lower:  # continuous / unlimited
            lower, upper = -math.pi, math.pi
        joints.append(i)
        low.append(lower)
        high.append(upper)
configs = np.random.default_rng(seed).uniform(low, high, size=(samples, len(joints))).tolist()
start = time.perf_counter()
frames = []
for q in configs:
    for joint, value in zip(joints, q):
        p.resetJointState(body, joint, value)
    frames.append([p.getLinkState(body, i, computeForwardKinematics=True)[4:6] for i in links])
loop = time.perf_counter() - start
print(json.dumps({"samples": samples, "joints": len(joints), "links": len(links), "loop_s": loop}))
'''


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", type=Path, help="URDF (default: pybullet_data's franka_panda/panda.urdf)")
    parser.add_argument("--samples", type=int, default=1000, help="configurations per run (default 1,000)")
    parser.add_argument("--runs", type=int, default=5, help="timed runs of each variant (default 5)")
    args = parser.parse_args()

    robot = (args.robot or _timing.pybullet_data_path() / "franka_panda" / "panda.urdf").expanduser().resolve()
    if not robot.is_file():
        raise SystemExit(f"{robot}: no such file")
    fk = [*_timing.ar3cli_command(), "fk-verify", str(robot), "--samples", str(args.samples)]
    script = _timing.write_script("plain_fk.py", BASELINE)
    loops: list[float] = []

    def keep_loop(run: _timing.Run) -> None:
        loops.append(json.loads(run.stdout.strip().splitlines()[-1])["loop_s"])

    print(_timing.machine_header(f"fk-verify: {robot.name}"))
    try:
        variants = [
            _timing.Variant(f"`ar3cli fk-verify {robot.name} --samples {args.samples}`", fk),
            _timing.Variant("the same, `--format json`", [*fk, "--format", "json"]),
            _timing.Variant("plain script: resetJointState + getLinkState(computeForwardKinematics=True) per link",
                            [sys.executable, str(script), str(robot), str(args.samples), "0"], check=keep_loop),
        ]
        comparison = _timing.measure(f"{robot.name}, {args.samples} configurations, one process each",
                                     variants, args.runs)
        loop = statistics.median(loops[1:] or loops)
        comparison.notes.append(f"plain script: its loop took {loop:.3f} s ({loop / args.samples * 1e6:.0f} us per "
                                f"configuration), the rest of the process {variants[2].wall - loop:.3f} s")
        print(_timing.table(comparison))
        print(_timing.machine_footer())
    finally:
        _timing.cleanup()


if __name__ == "__main__":
    main()
