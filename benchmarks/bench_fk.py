"""Time the independent FK of fk-verify: vectorised numpy vs a per-configuration yourdfpy loop.

Run from the repository root: ``python benchmarks/bench_fk.py [N]`` (default 10,000 configurations
of pybullet_data's franka_panda, 7 arm joints + the finger). Prints absolute times and the ratio
against the baseline measured in the same run, then times a whole ``fk-verify --samples N`` run
(PyBullet included) in a subprocess.
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))


def main(count: int = 10_000) -> None:
    import pybullet_data
    import yourdfpy

    from ar3cli.kinematics import fk as kinematics
    from ar3cli.urdf.model import load_model

    path = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"
    model = load_model(path)
    names = [f"panda_joint{i}" for i in range(1, 8)] + ["panda_finger_joint1"]
    q = np.random.default_rng(0).uniform(-2.5, 2.5, size=(count, len(names)))
    positions = {name: q[:, i] for i, name in enumerate(names)}

    start = time.perf_counter()
    frames = kinematics.urdf_link_frames(model, positions, count)
    vectorised = time.perf_counter() - start

    robot = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False,
                               load_collision_meshes=False)
    links = list(frames)
    baseline_count = min(count, 1000)  # the loop is slow; time 1,000 and scale
    start = time.perf_counter()
    worst = 0.0
    for n in range(baseline_count):
        robot.update_cfg({name: q[n, i] for i, name in enumerate(names)})
        for link in links:
            worst = max(worst, float(np.abs(robot.get_transform(link) - frames[link][n]).max()))
    loop = (time.perf_counter() - start) * count / baseline_count

    print(f"panda, {count} configurations, {len(links)} link frames each")
    print(f"  vectorised numpy FK : {vectorised * 1e3:9.1f} ms")
    print(f"  yourdfpy loop       : {loop * 1e3:9.1f} ms (update_cfg + get_transform per config; "
          f"{baseline_count} timed, scaled)")
    print(f"  ratio               : {loop / vectorised:9.1f}x faster")
    print(f"  max |difference|    : {worst:.2e} (same frames)")

    start = time.perf_counter()
    result = subprocess.run([sys.executable, "-m", "ar3cli", "fk-verify", str(path), "--samples", str(count),
                             "--format", "json"], cwd=REPO, capture_output=True, text=True)
    whole = time.perf_counter() - start
    print(f"  whole `fk-verify --samples {count}` (pybullet included, process start): {whole:.2f} s, "
          f"exit {result.returncode}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10_000)
