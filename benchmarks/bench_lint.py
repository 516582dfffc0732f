"""Time ``ar3cli lint-urdf`` (static) against baselines measured in the same run.

1. One file (pybullet_data's franka_panda/panda.urdf: 11 links, 18 OBJ meshes, 9 MB), cold
   process (a fresh interpreter; the OS file cache is warm), median of N runs, against
   ``python -c pass`` (interpreter start-up), ``python -c "import typer, rich, lxml"`` (the
   libraries any typer CLI reading XML pays for) and ``check_urdf panda.urdf`` when installed.
   Target: <= 0.3 s.
2. pybullet_data's 95 models outside random_urdfs (154 meshes, 52 MB) in ONE ar3cli call, against
   a loop running ``check_urdf`` once per file (apt-get install liburdfdom-tools), which checks XML
   structure and the kinematic tree only. Three states of ar3cli's caches (a temporary folder):
   "nothing cached" (every mesh read, every file checked: a fresh CI machine), "--no-cache" (mesh
   boxes cached, every file checked again), and "results cached" (the files are unchanged since
   the last run: a re-run, a pre-commit --all-files, a CI job that keeps ~/.cache). The variants
   and the loop run in interleaved rounds, so a machine that speeds up or slows down during the
   run moves them all alike; medians are printed.

Wall time is what the targets are about; CPU time (user + sys of the child, from getrusage) is
printed next to it. Bytecode is written on the first run (PYTHONDONTWRITEBYTECODE is dropped for
the children), as ``pip install`` does, so no run pays for compiling ar3cli.

Usage: python benchmarks/bench_lint.py [--repeats 7]
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
CACHE = Path(tempfile.mkdtemp(prefix="ar3cli-bench-cache-"))
"""ar3cli's on-disk caches (mesh boxes, lint results) for this run only: "nothing cached" runs delete them first."""
ENV = {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"},
       "PYTHONPATH": str(REPO), "NO_COLOR": "1", "AR3CLI_CACHE_DIR": str(CACHE)}


def timed(command: list[str], empty_cache: bool = False) -> tuple[float, float]:
    """(wall, CPU) seconds of one run of ``command`` (with ar3cli's caches emptied first if asked)."""
    if empty_cache:
        shutil.rmtree(CACHE, ignore_errors=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=ENV, cwd=REPO)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


class Timing:
    """Medians of wall and CPU time over repeated runs."""

    def __init__(self, runs: list[tuple[float, float]]) -> None:
        self.wall = statistics.median(w for w, _ in runs)
        self.cpu = statistics.median(c for _, c in runs)

    def __str__(self) -> str:
        return f"{self.wall:6.3f} s wall {self.cpu:6.3f} s CPU"


def median(command: list[str], repeats: int, empty_cache: bool = False) -> Timing:
    timed(command)  # warm the OS file cache; "cold" means a fresh process, not a cold disk
    return Timing([timed(command, empty_cache) for _ in range(repeats)])


def check_urdf_loop(check_urdf: str, models: list[Path]) -> float:
    start = time.perf_counter()
    for model in models:
        subprocess.run([check_urdf, str(model)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def load() -> str:
    one, five, _ = os.getloadavg()
    return f"load average {one:.2f} (1 min), {five:.2f} (5 min) on {os.cpu_count()} CPUs"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7, help="runs per measurement (median reported)")
    args = parser.parse_args()
    import pybullet_data

    data = Path(pybullet_data.getDataPath())
    panda = data / "franka_panda" / "panda.urdf"
    models = sorted(p for p in data.rglob("*.urdf") if "random_urdfs" not in p.parts)
    check_urdf = shutil.which("check_urdf")
    lint = [sys.executable, "-m", "ar3cli", "lint-urdf", "--exit-zero", "--no-config"]
    print(f"before: {load()}")

    python = median([sys.executable, "-c", "pass"], args.repeats)
    libraries = median([sys.executable, "-c", "import typer, rich, lxml.etree"], args.repeats)
    first = median([*lint, str(panda)], args.repeats, empty_cache=True)
    checked = median([*lint, "--no-cache", str(panda)], args.repeats)
    one = median([*lint, str(panda)], args.repeats)
    print(f"\npanda.urdf, cold process (median of {args.repeats}):")
    print(f"  python -c pass                                {python}")
    print(f"  python -c 'import typer, rich, lxml'          {libraries}")
    print(f"  ar3cli lint-urdf, nothing cached              {first}")
    print(f"  ar3cli lint-urdf, --no-cache (meshes cached)  {checked}   target <= 0.3 s wall: "
          f"{'met' if checked.wall <= 0.3 else 'NOT met'}")
    print(f"  ar3cli lint-urdf, result cached               {one}")
    if check_urdf:
        print(f"  check_urdf                                    {median([check_urdf, str(panda)], args.repeats)}")

    paths = list(map(str, models))
    variants = {
        "nothing cached": ([*lint, *paths], True),
        "--no-cache (mesh boxes cached)": ([*lint, "--no-cache", *paths], False),
        "results cached, text": ([*lint, *paths], False),
        "results cached, json": ([*lint, "--format", "json", *paths], False),
    }
    for command, _ in variants.values():
        timed(command)  # fill the caches, write bytecode, warm the OS file cache
    runs: dict[str, list[tuple[float, float]]] = {name: [] for name in variants}
    loops: list[float] = []
    for _ in range(args.repeats):
        for name, (command, empty_cache) in variants.items():
            runs[name].append(timed(command, empty_cache))
        if check_urdf:
            loops.append(check_urdf_loop(check_urdf, models))
    print(f"\n{len(models)} pybullet_data models (random_urdfs excluded), a single call "
          f"(median of {args.repeats} interleaved rounds):")
    loop = statistics.median(loops) if loops else None
    for name, timings in runs.items():
        timing = Timing(timings)
        ratio = f"   check_urdf loop / this: {loop / timing.wall:.2f}" if loop else ""
        print(f"  ar3cli lint-urdf, {name:31s} {timing}{ratio}")
    if loop:
        print(f"  check_urdf, once per file                         {loop:6.3f} s wall   (> 1 above: the single "
              "call is faster)")
    else:
        print("  check_urdf not installed (apt-get install liburdfdom-tools): no baseline")
    print(f"\nafter: {load()}")
    shutil.rmtree(CACHE, ignore_errors=True)


if __name__ == "__main__":
    main()
