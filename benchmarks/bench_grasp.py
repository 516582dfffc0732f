"""Benchmark ``ar3cli grasp-demo``: real-time factor, overhead against raw stepping, success rate.

    python benchmarks/bench_grasp.py [--runs N] [--trials M]

* demo: ``run_grasp`` on seeds 0..N-1, headless, no recording: sim time / wall time (the
  issue's target is >= 20x real time), wall time including scene setup and IK.
* baseline, same process: the same scene (arm, cube, ground, IK client) built the same way,
  then ``stepSimulation`` the same number of steps with no controller. The ratio demo/baseline
  is the cost of our controller, IK and bookkeeping on top of pybullet itself.
* ``--trials M``: success rate over seeds 1000..1000+M-1 (seeds the tests never use).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from ar3cli.grasp.pick_and_lift import TIMESTEP, GraspScene, GraspSettings, run_grasp
from ar3cli.sim.capture import capture_fds


def baseline(seed: int, steps: int) -> float:
    """Wall time of building the scene and stepping it ``steps`` times with no control."""
    start = time.perf_counter()
    scene = GraspScene(seed, GraspSettings())
    try:
        for _ in range(steps):
            scene.p.stepSimulation(physicsClientId=scene.client)
    finally:
        scene.close()
    return time.perf_counter() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10, help="demo runs timed (seeds 0..N-1)")
    parser.add_argument("--trials", type=int, default=0, help="extra runs for the success rate (seeds 1000..)")
    args = parser.parse_args()

    with capture_fds():  # keep pybullet's banner off the report
        run_grasp(0)  # warm-up: imports, first connect
    demo_walls, base_walls, factors, sims = [], [], [], []
    for seed in range(args.runs):
        result = run_grasp(seed)
        base = baseline(seed, result.steps)
        demo_walls.append(result.wall_time_s)
        base_walls.append(base)
        sims.append(result.sim_time_s)
        factors.append(result.realtime_factor)
    print(f"grasp-demo, {args.runs} runs headless, no recording ({TIMESTEP * 1000:.3f} ms steps)")
    print(f"  sim time per run      {statistics.mean(sims):.2f} s")
    print(f"  wall time per run     median {statistics.median(demo_walls):.3f} s")
    print(f"  real-time factor      median {statistics.median(factors):.1f}x, min {min(factors):.1f}x "
          f"(target >= 20x)")
    print(f"  baseline (same scene, raw stepSimulation, same steps): median {statistics.median(base_walls):.3f} s, "
          f"{statistics.median(s / w for s, w in zip(sims, base_walls)):.1f}x real time")
    print(f"  demo / baseline       {statistics.median(d / b for d, b in zip(demo_walls, base_walls)):.2f}x "
          f"(cost of controller, IK and checks over bare physics)")
    if args.trials:
        failures = []
        start = time.perf_counter()
        for seed in range(1000, 1000 + args.trials):
            result = run_grasp(seed)
            if not result.success:
                failures.append(f"seed {seed}: {result.failed_phase}: {result.reason}")
        wall = time.perf_counter() - start
        print(f"success rate over {args.trials} seeds (1000..{999 + args.trials}): "
              f"{args.trials - len(failures)}/{args.trials} ({wall:.1f} s)")
        for failure in failures:
            print("  " + failure)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
