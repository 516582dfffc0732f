"""What a hostile pull request costs the gate: time and peak memory of whole ``ar3cli`` processes.

Builds, in a temporary folder, the inputs issue 34 reproduced against the CI gate, and runs the
command the gate runs on each, as a separate process (``python -m ar3cli`` of this checkout, or of
``--code DIR``):

* ``orphans-N``: a robot of N links and no joints (N roots: S005 names every one of them in each of
  its findings), ``lint-urdf --format github`` (annotations, and the step summary file);
* ``loop-paths``: two symbolic links ``a -> .`` and ``b -> .`` and 120 distinct paths (``a/b/a/m.obj``)
  to one 20 MB OBJ, ``lint-urdf``;
* ``renamed-star-N``: a star of N children, OLD and NEW with every child renamed, ``diff``;
* ``macro-bomb``: a xacro macro of 50 links called 200 times (a 9 KB file, 10,000 root links once
  expanded), ``lint-urdf``.

Each line gives the exit code, the wall time and the peak resident memory of the process and its
children (``os.wait4``'s ``ru_maxrss``: the largest resident set of ar3cli and of every child it
waited for), and the last line ar3cli wrote on stderr. No number is
asserted: the table is what docs/security.md quotes.

Usage (inside the project's venv)::

    python benchmarks/bench_hostile.py                   # every case, one run each (a few minutes on 2 cores)
    python benchmarks/bench_hostile.py --only orphans    # the cases whose name starts with it
    python benchmarks/bench_hostile.py --write-only DIR  # just write the inputs
    python benchmarks/bench_hostile.py --timeout 600     # ar3cli's --timeout (default: its own, 120 s)
    python benchmarks/bench_hostile.py --code ../main    # another checkout (careful: before issue 34,
                                                         # orphans-20000 grew past 20 GB)
"""

from __future__ import annotations

import argparse
import itertools
import os
import random
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _timing  # noqa: E402 - after the sys.path line that finds it

INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'


def orphans(count: int) -> str:
    """``count`` links and no joint: ``count`` root links."""
    links = "\n".join(f'<link name="orphan_link_{index}">{INERTIAL}</link>' for index in range(count))
    return f'<?xml version="1.0"?>\n<robot name="orphans">\n{links}\n</robot>\n'


def star(count: int, prefix: str) -> str:
    """A root with ``count`` children, each named with ``prefix`` (OLD and NEW differ only in it)."""
    body = [f'<link name="base">{INERTIAL}</link>']
    for index in range(count):
        body.append(f'<link name="{prefix}_link_{index}">{INERTIAL}<collision><geometry><box size="0.1 0.1 0.1"/>'
                    f'</geometry></collision></link>')
        body.append(f'<joint name="{prefix}_joint_{index}" type="revolute"><parent link="base"/>'
                    f'<child link="{prefix}_link_{index}"/><origin xyz="{index * 0.01:.2f} {index % 7 * 0.1:.1f} 0"/>'
                    '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    return '<?xml version="1.0"?>\n<robot name="star">\n' + "\n".join(body) + "\n</robot>\n"


def macro_bomb(calls: int = 200, links_per_call: int = 50) -> str:
    """A xacro macro of ``links_per_call`` links without joints called ``calls`` times: a 9 KB file
    that expands to 10,000 links, every one a root."""
    body = "\n".join(f'    <link name="${{prefix}}_{index}"/>' for index in range(links_per_call))
    uses = "\n".join(f'  <xacro:parts prefix="copy{index}"/>' for index in range(calls))
    return ('<?xml version="1.0"?>\n<robot name="bomb" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            f'  <xacro:macro name="parts" params="prefix">\n{body}\n  </xacro:macro>\n{uses}\n</robot>\n')


def loop_paths(folder: Path, paths: int = 120, mesh_bytes: int = 20_000_000) -> Path:
    """``a -> .``, ``b -> .``, one OBJ of ``mesh_bytes`` and a robot naming it by ``paths`` paths."""
    rng = random.Random(0)
    with open(folder / "m.obj", "w", encoding="ascii") as mesh:
        while mesh.tell() < mesh_bytes:
            mesh.write("".join(f"v {rng.random():.6f} {rng.random():.6f} {rng.random():.6f}\n" for _ in range(1000)))
        mesh.write("f 1 2 3\n")
    for name in ("a", "b"):
        os.symlink(".", folder / name)
    names = ["/".join(combo) + "/m.obj" for depth in range(1, 8) for combo in itertools.product("ab", repeat=depth)]
    shapes = "".join(f'<collision><geometry><mesh filename="{name}"/></geometry></collision>' for name in names[:paths])
    path = folder / "loop.urdf"
    path.write_text(f'<?xml version="1.0"?>\n<robot name="loop">\n<link name="base">{INERTIAL}{shapes}</link>\n</robot>\n')
    return path


def write_cases(folder: Path) -> dict[str, tuple[list[str], Path]]:
    """Write every input into ``folder``: case name -> (ar3cli arguments, the folder to run them in)."""
    cases: dict[str, tuple[list[str], Path]] = {}
    for count in (5_000, 20_000):
        (folder / f"orphans_{count}.urdf").write_text(orphans(count))
        cases[f"orphans-{count}"] = (["lint-urdf", "--format", "github", f"orphans_{count}.urdf"], folder)
    loop = folder / "loop"
    loop.mkdir()
    loop_paths(loop)
    cases["loop-paths"] = (["lint-urdf", "--no-cache", "loop.urdf"], loop)
    for count in (1_000, 2_000):
        (folder / f"old_star_{count}.urdf").write_text(star(count, "old"))
        (folder / f"new_star_{count}.urdf").write_text(star(count, "new"))
        cases[f"renamed-star-{count}"] = (["diff", f"old_star_{count}.urdf", f"new_star_{count}.urdf", "-n", "10"],
                                          folder)
    (folder / "bomb.urdf.xacro").write_text(macro_bomb())
    cases["macro-bomb"] = (["lint-urdf", "bomb.urdf.xacro"], folder)
    return cases


def run(args: list[str], cwd: Path, timeout: float | None, code: Path) -> tuple[int, float, float, str]:
    """(exit code, wall seconds, peak MB of the process and its children, its last stderr line) of
    ``python -m ar3cli ARGS`` run from the checkout ``code``."""
    command = [sys.executable, "-m", "ar3cli", *args, *(["--timeout", f"{timeout:g}"] if timeout is not None else [])]
    summary = cwd / "step_summary.md"
    env = {**_timing.BASE_ENV, "GITHUB_STEP_SUMMARY": str(summary), "PYTHONPATH": str(code)}
    with tempfile.TemporaryFile() as errors:
        started = time.perf_counter()
        process = subprocess.Popen(command, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=errors,
                                   stdin=subprocess.DEVNULL)
        _, status, usage = os.wait4(process.pid, 0)  # usage: the process and every child it waited for
        seconds = time.perf_counter() - started
        process.returncode = os.waitstatus_to_exitcode(status)
        errors.seek(0)
        lines = [line for line in errors.read().decode("utf-8", "replace").splitlines() if line.strip()]
    summary.unlink(missing_ok=True)
    return process.returncode, seconds, usage.ru_maxrss / 1024, (lines[-1] if lines else "")  # ru_maxrss: kB


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="run the cases whose name starts with this")
    parser.add_argument("--timeout", type=float, default=None, help="ar3cli's --timeout (default: its own)")
    parser.add_argument("--write-only", type=Path, default=None, help="write the inputs into this folder and stop")
    parser.add_argument("--code", type=Path, default=_timing.REPO,
                        help="the ar3cli checkout to run (default: the one holding this script)")
    options = parser.parse_args(argv)
    if options.write_only is not None:
        options.write_only.mkdir(parents=True, exist_ok=True)
        for name, (args, cwd) in write_cases(options.write_only).items():
            print(f"{name}: (cd {cwd} && ar3cli {' '.join(args)})")
        return
    report: Callable[[str], None] = print
    with tempfile.TemporaryDirectory(prefix="ar3cli-hostile-") as folder:
        cases = write_cases(Path(folder))
        report(f"ar3cli from {options.code}, {os.cpu_count()} CPUs; peak MB: the largest resident set of ar3cli and of "
               "each child it waited for")
        report("| case | command | exit | wall s | peak MB | last stderr line |")
        report("| --- | --- | --- | --- | --- | --- |")
        for name, (args, cwd) in cases.items():
            if not name.startswith(options.only):
                continue
            code, seconds, peak, last = run(args, cwd, options.timeout, options.code)
            report(f"| {name} | ar3cli {' '.join(args)} | {code} | {seconds:.1f} | {peak:.0f} | {last[:160]} |")


if __name__ == "__main__":
    main()
