"""What Ray costs ``ar3cli scan`` before the first file: a local Ray it starts, and a running head it joins.

Whole processes, alternating, warm-up first (``benchmarks/_timing.py``), every run checking the same
small set of files again (``--rescan``), so the difference between the variants is Ray's fixed cost:

* ``scan -j 2`` (the local backend, the reference);
* ``scan --backend ray -j 2``: starts a local Ray with 2 CPUs and stops it;
* ``scan --backend ray --address 127.0.0.1:PORT``: joins a head this benchmark starts beforehand
  (``ray start --head --block --num-cpus 2``, token authentication on, in its own HOME and temporary
  folder; its process group is stopped at the end).

Ray pays off when the CPUs it adds save more than it costs: scanning n files of t CPU-seconds each
on c local cores takes n t / c; on a cluster of M CPUs it takes S + n t / M, S the fixed cost
measured here. ``docs/scale.md`` has the numbers and the break-even.

Usage (inside the project's venv, with ray installed)::

    python benchmarks/bench_ray.py            # 5 runs each, ~4 minutes on 2 busy cores
    python benchmarks/bench_ray.py --runs 7 --files 16
"""

from __future__ import annotations

import argparse
import contextlib
import os
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import _timing as timing

CHAIN = ('<link name="l{i}"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
         'iyz="0"/></inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>')


def write_files(folder: Path, count: int) -> None:
    """``count`` small robots (a 3-link chain each): a static check is milliseconds, Ray's cost shows."""
    folder.mkdir(parents=True)
    for index in range(count):
        links = "".join(CHAIN.format(i=i) for i in range(3))
        joints = "".join(f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
                         f'<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
                         for i in range(2))
        (folder / f"robot{index:03d}.urdf").write_text(f'<robot name="r{index}">{links}{joints}</robot>\n')


@contextlib.contextmanager
def ray_head(home: Path) -> Iterator[str]:
    """A Ray head on 127.0.0.1 with 2 CPUs and token authentication; yields its address."""
    ray = str(Path(sys.executable).parent / "ray")
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    temp = Path(tempfile.mkdtemp(prefix="ray", dir="/tmp"))
    env = {**timing.BASE_ENV, "HOME": str(home), "RAY_USAGE_STATS_ENABLED": "0"}
    subprocess.run([ray, "get-auth-token", "--generate"], env=env, capture_output=True, check=True, timeout=60)
    head = subprocess.Popen([ray, "start", "--head", "--block", "--node-ip-address", "127.0.0.1", "--port", str(port),
                             "--num-cpus", "2", "--include-dashboard", "false", "--temp-dir", str(temp),
                             "--disable-usage-stats"], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, start_new_session=True)
    try:
        for line in head.stdout:  # type: ignore[union-attr]
            if "Ray runtime started" in line:
                break
        else:
            raise SystemExit("ray start --head ended before the runtime started")
        yield f"127.0.0.1:{port}"
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(head.pid, signal.SIGKILL)
        head.wait()
        shutil.rmtree(temp, ignore_errors=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--files", type=int, default=8, help="small robots scanned per run (default 8)")
    args = parser.parse_args()
    if shutil.which("ray", path=str(Path(sys.executable).parent)) is None:
        raise SystemExit("ray is not installed here: pip install 'ar3cli[ray]'")
    robots, home = timing.WORK / "robots", timing.WORK / "home"
    write_files(robots, args.files)
    home.mkdir()
    ar3cli = timing.ar3cli_command()
    print(timing.machine_header("ar3cli scan: Ray's fixed cost"))
    with ray_head(home) as address:
        def scan(name: str, *extra: str) -> timing.Variant:
            store = timing.WORK / f"{name}.sqlite"
            return timing.Variant(name, [*ar3cli, "scan", str(robots), "--store", str(store), "--rescan", "-f", "json",
                                         *extra], prepare=lambda: {"HOME": str(home)})

        comparison = timing.measure(f"scan of {args.files} small files, static", [
            scan("local backend, -j 2", "-j", "2"),
            scan("Ray, starts a local cluster (-j 2)", "--backend", "ray", "-j", "2"),
            scan("Ray, joins a running head (2 CPUs)", "--backend", "ray", "--address", address),
        ], args.runs)
    print(timing.table(comparison))
    reference = comparison.variants[0]
    for variant in comparison.variants[1:]:
        extra = [mine.wall - ref.wall for mine, ref in zip(variant.runs, reference.runs)]
        print(f"- {variant.name}: fixed cost S = {statistics.median(extra):.1f} s wall (median of the per-round "
              f"differences to the local backend: {' '.join(f'{value:.1f}' for value in extra)})")
    print()
    print(timing.machine_footer())


if __name__ == "__main__":
    main()
