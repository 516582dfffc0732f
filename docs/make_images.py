"""Make the pictures in README.md and docs/ by running the real ar3cli commands.

Run from anywhere: ``python docs/make_images.py``. The images are committed; rerun after a change
to the AR3 model, the renderer or the demo. Every picture is deterministic (fixed seeds).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
IMAGES = REPO / "docs" / "images"
AR3 = "assets/ar3/ar3.urdf"

COMMANDS = [
    ["render", AR3, "-o", "docs/images/ar3_home.png", "--width", "480", "--height", "480"],
    ["render", AR3, "-o", "docs/images/ar3_folded_collision.png", "--width", "480", "--height", "480",
     "--config", "joint_2=1.2,joint_3=2.4", "--collision"],
    ["sample-collisions", AR3, "--samples", "2000", "--seed", "1", "--png", "docs/images/collision_matrix.png"],
    ["grasp-demo", "--seed", "0", "--record", "docs/images/grasp.gif"],
]


def main() -> int:
    IMAGES.mkdir(parents=True, exist_ok=True)
    env = {**os.environ, "PYTHONPATH": str(REPO), "NO_COLOR": "1"}
    for arguments in COMMANDS:
        print("ar3cli", " ".join(arguments), flush=True)
        done = subprocess.run([sys.executable, "-m", "ar3cli", *arguments], cwd=REPO, env=env,
                              stdout=subprocess.DEVNULL)
        if done.returncode != 0:
            print(f"failed with exit code {done.returncode}", file=sys.stderr)
            return done.returncode
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
