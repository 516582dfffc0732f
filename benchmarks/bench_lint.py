"""Time ``ar3cli lint-urdf`` against baselines measured in the same run.

1. One file (pybullet_data's franka_panda/panda.urdf), cold process, median of N runs, against
   ``python -c pass`` (interpreter start-up) and ``check_urdf panda.urdf`` when installed.
2. pybullet_data's 95 models outside random_urdfs in ONE ar3cli call, against a loop running
   ``check_urdf`` once per file (apt-get install liburdfdom-tools).

Usage: python benchmarks/bench_lint.py [--repeats 5]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(REPO), "NO_COLOR": "1"}


def timed(command: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=ENV, cwd=REPO)
    return time.perf_counter() - start


def median(command: list[str], repeats: int) -> float:
    timed(command)  # warm the OS file cache; "cold" means a fresh process, not a cold disk
    return statistics.median(timed(command) for _ in range(repeats))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="runs per measurement (median reported)")
    args = parser.parse_args()
    import pybullet_data

    data = Path(pybullet_data.getDataPath())
    panda = data / "franka_panda" / "panda.urdf"
    models = sorted(p for p in data.rglob("*.urdf") if "random_urdfs" not in p.parts)
    check_urdf = shutil.which("check_urdf")
    lint = [sys.executable, "-m", "ar3cli", "lint-urdf", "--exit-zero", "--format", "json"]

    python = median([sys.executable, "-c", "pass"], args.repeats)
    one = median([*lint, str(panda)], args.repeats)
    print(f"panda.urdf, cold process (median of {args.repeats}):")
    print(f"  python -c pass            {python:7.3f} s")
    print(f"  ar3cli lint-urdf          {one:7.3f} s   ({one / python:.1f}x interpreter start-up; target <= 0.3 s)")
    imports = median([sys.executable, "-c", "import ar3cli.cli, ar3cli.lint, ar3cli.mass_properties, rich.table"],
                     args.repeats)
    print(f"  of which imports          {imports:7.3f} s   (python + typer + rich + lxml + numpy)")
    if check_urdf:
        single = median([check_urdf, str(panda)], args.repeats)
        print(f"  check_urdf                {single:7.3f} s   (ar3cli / check_urdf = {one / single:.1f}x)")

    print(f"\n{len(models)} pybullet_data models (random_urdfs excluded):")
    ours = median([*lint, *map(str, models)], max(1, args.repeats // 2))
    print(f"  ar3cli lint-urdf, 1 call  {ours:7.3f} s")
    print(f"  (load average while measuring: {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs)")
    if check_urdf:
        start = time.perf_counter()
        for model in models:
            subprocess.run([check_urdf, str(model)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        loop = time.perf_counter() - start
        print(f"  check_urdf, once per file {loop:7.3f} s   (ar3cli is {loop / ours:.1f}x faster)")
    else:
        print("  check_urdf not installed (apt-get install liburdfdom-tools): no baseline")


if __name__ == "__main__":
    main()
