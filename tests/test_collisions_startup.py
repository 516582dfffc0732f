"""sample-collisions start-up: the parent imports its report while the pybullet child samples, and
never imports numpy (the child does, with one OpenBLAS thread). No wall-clock time is asserted."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from ar3cli.infra import isolation
from tests.conftest import ASSETS, REPO

PARENT_MODULES = r"""
import atexit, json, os, sys
parent = os.getpid()
def report():
    if os.getpid() == parent:
        print(json.dumps({m: m in sys.modules for m in ("numpy", "pybullet", "ar3cli.collisions.matrix_report")}),
              file=sys.stderr)
atexit.register(report)
sys.argv = ["ar3cli", "sample-collisions", sys.argv[1], "--samples", "50", "--format", "json"]
from ar3cli.cli import run
run()
"""


def test_meanwhile_runs_in_the_parent_while_the_child_works() -> None:
    calls: list[int] = []
    child = isolation.run_isolated(os.getpid, "robot.urdf", meanwhile=lambda: calls.append(os.getpid()))
    assert calls == [os.getpid()]
    assert child != os.getpid()


def test_meanwhile_runs_after_the_work_where_there_is_no_fork(monkeypatch) -> None:
    order: list[str] = []
    monkeypatch.setattr(isolation, "can_fork", lambda: False)
    assert isolation.run_isolated(lambda: order.append("work") or 7, "robot.urdf",
                                  meanwhile=lambda: order.append("meanwhile")) == 7
    assert order == ["work", "meanwhile"]


def test_the_parent_never_imports_numpy_or_pybullet() -> None:
    env = {**os.environ, "PYTHONPATH": str(REPO), "NO_COLOR": "1"}
    done = subprocess.run([sys.executable, "-c", PARENT_MODULES, str(ASSETS / "ar3" / "ar3.urdf")],
                          capture_output=True, text=True, env=env, cwd=REPO, timeout=120)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["samples"] == 50
    loaded = json.loads(done.stderr.strip().splitlines()[-1])
    assert loaded == {"numpy": False, "pybullet": False, "ar3cli.collisions.matrix_report": True}
