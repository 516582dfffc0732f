"""CI's second stage: every command, run the way a user runs it, from a plain ``pip install .``.

``.ci/run`` builds a fresh venv, installs the checkout with no extras, and runs this script with
that venv's Python. Each step calls the venv's ``ar3cli`` console script (never ``python -m`` and
never the checkout's sources: PYTHONPATH is dropped) on small fixtures that need COLLADA and STL
meshes, convex hulls and xacro, and checks the exit code and the one output that shows the work was
really done (an inertial computed from a .dae mesh, an STL mesh decomposed into parts, a PNG...).
A test extra that hides a missing runtime dependency makes one of these steps fail here.

Usage: python .ci/plain_install_smoke.py [--ar3cli PATH]   (default: the ar3cli next to sys.executable)
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
FIXTURE = REPO / "tests" / "data" / "plain_install" / "robot.urdf"
DAE = REPO / "tests" / "data" / "meshes" / "cube_inches.dae"
XACRO = REPO / "assets" / "ar3" / "ar3.urdf.xacro"
U_CELLS = [(0, y, 0) for y in range(9)] + [(6, y, 0) for y in range(9)] + [(x, 0, 0) for x in range(1, 6)]
"""A U of 1 cm cubes (tests/test_fix_collision.py's): its convex hull has 2.74 times its volume."""
TIMEOUT_S = 300


def voxel_stl(cells: list[tuple[int, int, int]], size: float = 0.01) -> bytes:
    """A closed binary STL of unit cubes: the faces between filled and empty cells (stdlib only)."""
    filled = set(cells)
    triangles = []
    for cell in sorted(filled):
        for axis in range(3):
            for sign in (1, -1):
                neighbour = list(cell)
                neighbour[axis] += sign
                if tuple(neighbour) in filled:
                    continue
                corner = [float(c) for c in cell]
                corner[axis] += sign > 0
                u, v = [0.0] * 3, [0.0] * 3
                u[(axis + 1) % 3], v[(axis + 2) % 3] = 1.0, 1.0
                quad = [corner, [a + b for a, b in zip(corner, u)], [a + b + c for a, b, c in zip(corner, u, v)],
                        [a + b for a, b in zip(corner, v)]]
                quad = [[x * size for x in point] for point in quad]
                normal = [0.0] * 3
                normal[axis] = float(sign)
                order = ((0, 1, 2), (0, 2, 3)) if sign > 0 else ((0, 2, 1), (0, 3, 2))
                triangles += [(normal, [quad[i] for i in face]) for face in order]
    body = b"".join(struct.pack("<12fH", *normal, *(x for p in points for x in p), 0) for normal, points in triangles)
    return b"plain-install smoke U".ljust(80, b" ") + struct.pack("<I", len(triangles)) + body


def make_robot(folder: Path) -> Path:
    """The fixture robot in ``folder``: URDF, meshes/cube_inches.dae, meshes/u.stl (written here)."""
    meshes = folder / "meshes"
    meshes.mkdir(parents=True)
    shutil.copy(DAE, meshes / DAE.name)
    (meshes / "u.stl").write_bytes(voxel_stl(U_CELLS))
    text = FIXTURE.read_text(encoding="utf-8").replace("ABSOLUTE/", folder.resolve().as_posix() + "/")
    path = folder / "robot.urdf"
    path.write_text(text, encoding="utf-8")
    return path


class Smoke:
    """Runs ar3cli steps, records each one's outcome, and prints a summary."""

    def __init__(self, ar3cli: Path, work: Path) -> None:
        self.ar3cli, self.work, self.failures, self.count = ar3cli, work, [], 0
        self.env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
        self.env.update(COLUMNS="200", AR3CLI_CACHE_DIR=str(work / "cache"), XDG_CACHE_HOME=str(work / "cache"))

    def run(self, name: str, args: list[str], expect: tuple[int, ...] = (0,), check=None) -> subprocess.CompletedProcess:
        """Run ``ar3cli ARGS``; a failure is an unexpected exit code, or ``check(result)`` returning a reason."""
        self.count += 1
        start = time.perf_counter()
        result = subprocess.run([str(self.ar3cli), *args], capture_output=True, text=True, cwd=self.work,
                                env=self.env, stdin=subprocess.DEVNULL, timeout=TIMEOUT_S)
        reason = None
        if result.returncode not in expect:
            reason = f"exit {result.returncode}, expected {' or '.join(map(str, expect))}"
        elif check is not None:
            reason = check(result)
        took = time.perf_counter() - start
        print(f"{'ok  ' if reason is None else 'FAIL'} {name:<34} exit {result.returncode}  {took:5.1f} s", flush=True)
        if reason is not None:
            tail = (result.stdout + result.stderr).strip().splitlines()[-15:]
            print(f"     {reason}\n     $ ar3cli {' '.join(args)}\n" + "\n".join("     | " + line for line in tail))
            self.failures.append(name)
        return result


def json_of(result: subprocess.CompletedProcess) -> dict:
    try:
        return json.loads(result.stdout)
    except json.JSONDecodeError:
        return {}


def link_text(path: Path, link: str) -> str:
    """The text of ``<link name="LINK">`` ... ``</link>`` in ``path`` ('' when absent)."""
    return path.read_text(encoding="utf-8").partition(f'<link name="{link}">')[2].partition("</link>")[0]


def is_png(path: Path) -> bool:
    return path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def needs(text: str):
    """A check: ``text`` appears in stdout or stderr."""
    return lambda result: None if text in result.stdout + result.stderr else f"output lacks {text!r}"


def one_line(text: str):
    """A check: the output is one line on stderr, holding ``text`` (nothing on stdout)."""
    def check(result: subprocess.CompletedProcess) -> str | None:
        lines = result.stderr.strip().splitlines()
        if result.stdout.strip() or len(lines) != 1 or text not in lines[0]:
            return f"expected one stderr line with {text!r}"
        return None
    return check


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ar3cli", type=Path, default=Path(sys.executable).parent / "ar3cli",
                        help="the console script to test (default: the one next to this Python)")
    args = parser.parse_args()
    if not args.ar3cli.is_file():
        print(f"plain-install smoke: no console script at {args.ar3cli}", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="ar3cli-plain-smoke-") as folder:
        work = Path(folder)
        smoke = Smoke(args.ar3cli, work)
        steps(smoke, work)
        if smoke.failures:
            print(f"plain-install smoke: failed: {', '.join(smoke.failures)}")
        print(f"smoke: {smoke.count - len(smoke.failures)} passed, {len(smoke.failures)} failed")
        return 1 if smoke.failures else 0


def steps(smoke: Smoke, work: Path) -> None:
    """Every command once, on the fixture robot (a fresh copy for each fixer) and the AR3 xacro."""
    robot = make_robot(work / "robot")
    xacro = str(XACRO)
    smoke.run("install-check", ["install-check", "--format", "json"],
              check=lambda r: None if json_of(r).get("ok") is True else "install-check is not ok")
    smoke.run("--version", ["--version"])
    smoke.run("lint-urdf --sim (urdf)", ["lint-urdf", "--sim", str(robot)], expect=(0, 1))
    smoke.run("lint-urdf --sim (xacro)", ["lint-urdf", "--sim", xacro], expect=(0, 1))
    smoke.run("info (urdf)", ["info", str(robot)], check=needs("cube_link"))
    smoke.run("info (xacro)", ["info", xacro, "--format", "json"], check=lambda r: None if json_of(r) else "no JSON")
    smoke.run("fk-verify (xacro)", ["fk-verify", xacro, "--samples", "20", "--seed", "1"])
    smoke.run("fk-verify (urdf)", ["fk-verify", str(robot), "--samples", "20", "--seed", "1"])
    smoke.run("sample-collisions", ["sample-collisions", str(robot), "--samples", "200", "--seed", "1",
                                    "--srdf", str(work / "robot.srdf"), "--png", str(work / "pairs.png")],
              check=lambda r: None if (work / "robot.srdf").is_file() and is_png(work / "pairs.png")
              else "no SRDF or PNG written")
    for name, extra in (("render", []), ("render --collision", ["--collision"])):
        png = work / f"{name.replace(' ', '')}.png"
        smoke.run(name, ["render", str(robot), "--output", str(png), "--width", "160", "--height", "120", *extra],
                  check=lambda r, png=png: None if is_png(png) else "no PNG written")
    smoke.run("grasp-demo", ["grasp-demo"], expect=(0, 1))
    smoke.run("diff (no change)", ["diff", str(robot), str(robot), "--samples", "5"])
    smoke.run("report", ["report", str(robot), "-o", str(work / "robot.html"), "--samples", "20"],
              check=lambda r: None if (work / "robot.html").read_bytes().startswith(b"<!DOCTYPE html>")
              else "no HTML page written")
    smoke.run("scan", ["scan", str(robot.parent), "--store", str(work / "scan.sqlite"), "--format", "json"],
              expect=(0, 1), check=lambda r: None if json_of(r) else "no JSON")
    smoke.run("scan-report", ["scan-report", str(work / "scan.sqlite"), "--format", "json"],
              check=lambda r: None if json_of(r) else "no JSON")
    for name, args in (("cross-check (no mujoco)", ["cross-check", str(robot)]),
                       ("lint-urdf --engine mujoco (no mujoco)", ["lint-urdf", "--sim", "--engine", "mujoco", str(robot)])):
        smoke.run(name, args, expect=(2,), check=needs("pip install 'ar3cli[mujoco]'"))
    smoke.run("server (no pygls)", ["server"], expect=(2,), check=one_line("pip install 'ar3cli[server]'"))
    smoke.run("view (no viser)", ["view", str(robot)], expect=(2,), check=one_line("pip install 'ar3cli[view]'"))

    def fixed_copy(name: str) -> Path:
        return make_robot(work / name)

    copy = fixed_copy("inertia")
    smoke.run("fix-inertia (COLLADA)", ["fix-inertia", str(copy), "--links", "cube_link", "--density", "1000"],
              check=lambda r: None if "<inertial>" in link_text(copy, "cube_link")
              else "cube_link got no inertial from its .dae mesh")
    copy = fixed_copy("collision")
    before = copy.read_text()
    smoke.run("fix-collision (STL)", ["fix-collision", str(copy), "--resolution", "20000"],
              check=lambda r: None if copy.read_text() != before and '<mesh filename="meshes/u.stl"/>' not in
              link_text(copy, "u_link").partition("<collision")[2] else "u.stl was not decomposed")
    copy = fixed_copy("continuous")
    smoke.run("fix-continuous", ["fix-continuous", str(copy)],
              check=lambda r: None if 'lower="-3.14"' not in copy.read_text() else "the continuous joint kept its limits")
    copy = fixed_copy("joints")
    smoke.run("fix-joints", ["fix-joints", str(copy)],
              check=lambda r: None if 'lower="-90"' not in copy.read_text() else "the limits in degrees were kept")
    copy = fixed_copy("mesh_paths")
    smoke.run("fix-mesh-paths", ["fix-mesh-paths", str(copy), "--package", f"plain_install={copy.parent}",
                                  "--package-path", f"plain_install={copy.parent}"],
              check=lambda r: None if str(copy.parent.resolve()) not in copy.read_text() else "the absolute path was kept")


if __name__ == "__main__":
    sys.exit(main())
