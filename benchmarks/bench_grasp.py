"""Real-time factor of ``ar3cli grasp-demo`` as a user runs it: simulated seconds / whole-process wall seconds.

For each seed S in 0..N-1 (default N = 10), alternating, after one warm-up run of each (seed 0):

* A: ``ar3cli grasp-demo --seed S --format json`` as a subprocess. Its JSON reports the simulated
  duration (``sim_time_s`` = steps x 1/240 s, the demo's fixed time step), so the real-time factor
  of the run is ``sim_time_s / wall`` with ``wall`` the whole process (interpreter start, imports,
  loading the AR3 and the cube, IK, the five phases, the JSON). The demo's own in-process figure
  (``realtime_factor``: the same sim time over its wall time from scene setup to the end of the
  hold) is printed next to it.
* B: a plain pybullet script building the same world (the box ground ar3cli makes, the bundled AR3
  with a fixed base and the cube at the seed's pose as A's JSON reports it, 1/240 s, gravity) and
  calling ``stepSimulation`` as many times as run A stepped, with no controller: the arm holds its
  zero pose with one position-control call. Its real-time factor is the ceiling pybullet itself
  sets on this machine; B / A is what the controller, IK, checks and start-up cost. The fingers
  never reach the cube in B, so it has fewer contacts to solve than the grasp phases of A.

The medians are over the seeds (one run per seed; ``--repeat R`` runs every seed R times).

``--trials M`` then runs ``ar3cli grasp-demo --seed 1000 --trials M --format json`` once (seeds the
tests never use) and prints its success rate, and the real-time factor of that whole process
(M demos in one process: the start-up is paid once).

Usage (inside the project's venv)::

    python benchmarks/bench_grasp.py                  # seeds 0-9, ~10 s
    python benchmarks/bench_grasp.py --seeds 20 --repeat 2
    python benchmarks/bench_grasp.py --trials 100   # + success rate over seeds 1000..1099 (~15 s)
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
"""The grasp demo's world, stepped with no controller: pybullet's own ceiling on this machine."""
import json, math, sys, time
import pybullet as p

arm_path, cube_path, steps = sys.argv[1], sys.argv[2], int(sys.argv[3])
x, y, z, yaw_deg = map(float, sys.argv[4:8])
p.connect(p.DIRECT)
p.setGravity(0, 0, -9.81)
p.setTimeStep(1.0 / 240.0)
half = [1.5, 1.5, 0.01]
ground = p.createMultiBody(0, p.createCollisionShape(p.GEOM_BOX, halfExtents=half),
                           p.createVisualShape(p.GEOM_BOX, halfExtents=half), basePosition=[0, 0, -half[2]])
flags = p.URDF_USE_INERTIA_FROM_FILE | p.URDF_MAINTAIN_LINK_ORDER
arm = p.loadURDF(arm_path, useFixedBase=True, flags=flags)
cube = p.loadURDF(cube_path, [x, y, z], p.getQuaternionFromEuler([0, 0, math.radians(yaw_deg)]),
                  flags=flags, useMaximalCoordinates=True)
joints = [i for i in range(p.getNumJoints(arm)) if p.getJointInfo(arm, i)[2] != p.JOINT_FIXED]
p.setJointMotorControlArray(arm, joints, p.POSITION_CONTROL, targetPositions=[0.0] * len(joints))
start = time.perf_counter()
for _ in range(steps):
    p.stepSimulation()
print(json.dumps({"steps": steps, "loop_s": time.perf_counter() - start}))
'''

TIMESTEP = 1.0 / 240.0
"""ar3cli/grasp/pick_and_lift.py's TIMESTEP (read there, not imported: the benchmark only runs ar3cli)."""


def trials(count: int) -> str:
    """Success rate of ``grasp-demo --seed 1000 --trials count``, one process, and its real-time factor."""
    print(f"  measuring: grasp-demo --seed 1000 --trials {count}", file=sys.stderr, flush=True)
    run = _timing.run_once([*_timing.ar3cli_command(), "grasp-demo", "--seed", "1000", "--trials", str(count),
                            "--format", "json"])
    if run.returncode not in (0, 1):
        raise SystemExit(f"grasp-demo --trials: exit {run.returncode}\n{run.stderr[-2000:]}")
    document = json.loads(run.stdout)
    lines = [f"### grasp-demo --seed 1000 --trials {count}, one process", "",
             f"- success rate: {document['successes']}/{document['trials']} (seeds 1000..{999 + count})",
             f"- whole process: {run.wall:.2f} s wall, {run.cpu:.2f} s CPU, {document['sim_time_s']:.1f} s simulated: "
             f"{document['sim_time_s'] / run.wall:.1f}x real time (the demo reports {document['realtime_factor']}x)"]
    lines += [f"- failure: {failure}" for failure in document.get("failures", [])]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10, help="seeds 0..N-1 (default 10)")
    parser.add_argument("--repeat", type=int, default=1, help="runs per seed (default 1)")
    parser.add_argument("--trials", type=int, default=0,
                        help="also run `grasp-demo --seed 1000 --trials M` once: success rate (default: skip)")
    args = parser.parse_args()
    if args.seeds * args.repeat < 1:
        raise SystemExit("nothing to run")

    assets = _timing.REPO / "assets"
    arm, cube = assets / "ar3" / "ar3.urdf", assets / "objects" / "cube.urdf"
    script = _timing.write_script("plain_grasp_world.py", BASELINE)
    demo_docs: list[dict] = []
    plain_loops: list[float] = []
    seed_of_run: list[int] = []

    def demo_command() -> list[str]:
        return [*_timing.ar3cli_command(), "grasp-demo", "--seed", str(current_seed), "--format", "json"]

    def keep_demo(run: _timing.Run) -> None:
        document = json.loads(run.stdout)
        if not document.get("success"):
            print(f"note: seed {current_seed}: the grasp failed ({document.get('failed_phase')}: "
                  f"{document.get('reason')})", file=sys.stderr)
        demo_docs.append(document)

    def plain_command() -> list[str]:
        last = demo_docs[-1]
        return [sys.executable, str(script), str(arm), str(cube), str(last["steps"]),
                *map(str, last["cube_start"]), str(last["cube_yaw_deg"])]

    def keep_plain(run: _timing.Run) -> None:
        plain_loops.append(json.loads(run.stdout.strip().splitlines()[-1])["loop_s"])

    # grasp-demo exits 1 when the grasp fails: still a completed, timed run
    demo = _timing.Variant("`ar3cli grasp-demo --seed S --format json`", demo_command, check=keep_demo,
                           ok_codes=(0, 1))
    plain = _timing.Variant("plain script: same world, same number of stepSimulation calls, no controller",
                            plain_command, check=keep_plain)
    print(_timing.machine_header("grasp-demo"))
    try:
        print(f"  measuring: grasp-demo, seeds 0..{args.seeds - 1} x {args.repeat}, after a warm-up",
              file=sys.stderr, flush=True)
        current_seed = 0
        demo.run()
        plain.run()  # warm-ups, not counted
        del demo_docs[:], plain_loops[:]
        for _ in range(args.repeat):
            for current_seed in range(args.seeds):
                demo.runs.append(demo.run())
                plain.runs.append(plain.run())
                seed_of_run.append(current_seed)
        comparison = _timing.Comparison(f"grasp-demo, seeds 0..{args.seeds - 1}"
                                        + (f" x {args.repeat}" if args.repeat > 1 else "")
                                        + ", one process each", [demo, plain])
        sims = [document["sim_time_s"] for document in demo_docs]
        whole = [sim / run.wall for sim, run in zip(sims, demo.runs)]
        inside = [document["realtime_factor"] for document in demo_docs]
        plain_whole = [sim / run.wall for sim, run in zip(sims, plain.runs)]
        plain_loop = [sim / loop for sim, loop in zip(sims, plain_loops)]
        successes = sum(bool(document["success"]) for document in demo_docs)
        floor = [run.wall / mine.wall for run, mine in zip(plain.runs, demo.runs)]
        comparison.notes += [
            f"**ratio: grasp-demo's real-time factor / the bare-world floor's (plain script), whole processes, "
            f"round by round: median {statistics.median(floor):.2f}** (issue 29's target: >= 0.8; per round: "
            + " ".join(f"{value:.2f}" for value in floor) + ")",
            f"simulated time per run: median {statistics.median(sims):.3f} s (from the JSON's sim_time_s; "
            f"{statistics.median(d['steps'] for d in demo_docs):.0f} steps of {TIMESTEP * 1000:.4f} ms), "
            f"{successes}/{len(demo_docs)} grasps succeeded",
            f"**real-time factor of `ar3cli grasp-demo`, whole process: median {statistics.median(whole):.1f}x** "
            f"(min {min(whole):.1f}x, max {max(whole):.1f}x; per run: "
            + " ".join(f"{value:.1f}" for value in whole) + ")",
            f"real-time factor the demo reports (scene setup to end of hold, in-process): median "
            f"{statistics.median(inside):.1f}x (min {min(inside):.1f}x)",
            f"plain script: whole process {statistics.median(plain_whole):.1f}x real time, its stepping loop alone "
            f"{statistics.median(plain_loop):.1f}x (median)",
        ]
        print(_timing.table(comparison))
        if args.trials:
            print(trials(args.trials))
        print(_timing.machine_footer())
    finally:
        _timing.cleanup()


if __name__ == "__main__":
    main()
