"""Clean shutdown and bounded children (issue 22, items 2 and 4): SIGTERM is handled like Ctrl-C
(children stopped, temporary folders removed, exit 143), children die with their parent even when
it is killed with SIGKILL, a hung pybullet child is its file's one-line error after ``--timeout``
(the rest of the batch is still reported), and a child out of memory is one line too.

No test asserts a duration: every wait is bounded by a generous limit and fails only if it is reached.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ar3cli.errors import UserError
from ar3cli.infra import child_limits, process_pool
from ar3cli.infra.isolation import ChildTimeoutError, OutOfMemoryError, report_stage, run_isolated
from tests.conftest import REPO

pytestmark = pytest.mark.skipif(not process_pool.can_fork(), reason="children are forked on Linux only")

BOX = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
TWO_ARMS = f"""<robot name="arms">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>{BOX}</link>
  <link name="a"><collision><origin xyz="0 0 0.3"/><geometry><box size="0.05 0.05 0.5"/></geometry></collision>{BOX}</link>
  <link name="b"><collision><origin xyz="0 0 0.3"/><geometry><box size="0.05 0.05 0.5"/></geometry></collision>{BOX}</link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0 0 0.05"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0 0 0.55"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>
"""
ONE_BOX = f"""<robot name="good">
  <link name="base"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>{BOX}</link>
</robot>
"""
FIFO_MESH = f"""<robot name="fifo">
  <link name="base"><collision><geometry><mesh filename="m.stl"/></geometry></collision>{BOX}</link>
</robot>
"""


def _descendants(pid: int) -> set[int]:
    """Every process below ``pid`` (Linux: /proc), found through each task's children list."""
    found: set[int] = set()
    todo = [pid]
    while todo:
        current = todo.pop()
        try:
            tasks = os.listdir(f"/proc/{current}/task")
        except FileNotFoundError:
            continue
        for task in tasks:
            try:
                with open(f"/proc/{current}/task/{task}/children", encoding="ascii") as listing:
                    children = {int(child) for child in listing.read().split()}
            except FileNotFoundError:
                continue
            todo.extend(children - found)
            found |= children
    return found


def _alive(pid: int) -> bool:
    """Running (a zombie waiting for a reaper counts as ended)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as status:
            return status.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def _wait_until(condition, limit: float = 60.0) -> bool:
    """Poll ``condition()`` for at most ``limit`` seconds (a bound, not a measurement)."""
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return condition()


def _sampling_run(tmp_path: Path) -> tuple[subprocess.Popen, Path, set[int]]:
    """A long sample-collisions --jobs 2 in a private TMPDIR, once its pybullet child (and, with
    two CPUs, its collision worker) runs: (the process, the TMPDIR, the children's pids)."""
    robot = tmp_path / "arms.urdf"
    robot.write_text(TWO_ARMS)
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    env = {**os.environ, "PYTHONPATH": str(REPO), "TMPDIR": str(temporary), "AR3CLI_CACHE_DIR": str(tmp_path / "c")}
    run = subprocess.Popen([sys.executable, "-m", "ar3cli", "sample-collisions", str(robot), "--jobs", "2",
                            "--samples", "5000000", "-f", "json"], env=env, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, start_new_session=True)
    expected = 2 if process_pool.available_cpus() >= 2 else 1  # the pybullet child, and its worker
    try:
        assert _wait_until(lambda: len(_descendants(run.pid)) >= expected or run.poll() is not None)
        assert run.poll() is None, run.stderr.read() if run.stderr else ""
        time.sleep(0.3)  # the workers are counting now
        return run, temporary, _descendants(run.pid)
    except BaseException:
        os.killpg(run.pid, signal.SIGKILL)
        run.wait()
        raise


def test_sigterm_stops_the_children_removes_the_temporary_folder_and_exits_143(tmp_path) -> None:
    run, temporary, children = _sampling_run(tmp_path)
    assert children and any(temporary.iterdir())  # the pybullet child's folder exists while it runs
    os.kill(run.pid, signal.SIGTERM)  # the parent only, as `docker stop` does
    _, stderr = run.communicate(timeout=60)
    assert run.returncode == 143, stderr
    assert stderr.decode().strip().splitlines() == ["ar3cli: terminated"]
    assert _wait_until(lambda: not any(_alive(pid) for pid in children), limit=20)
    assert sorted(path.name for path in temporary.iterdir()) == []


def test_children_die_with_a_parent_killed_by_sigkill(tmp_path) -> None:
    run, _, children = _sampling_run(tmp_path)
    os.kill(run.pid, signal.SIGKILL)
    run.communicate(timeout=60)
    assert run.returncode == -signal.SIGKILL
    assert _wait_until(lambda: not any(_alive(pid) for pid in children), limit=20), "a child outlived its parent"


def test_a_mesh_that_is_a_fifo_is_its_own_finding_and_never_reaches_pybullet(tmp_path) -> None:
    """pybullet blocks for ever opening a FIFO named as a mesh: it was "file not found" (G001) and
    still handed to pybullet, which blocked until the timeout. Now the search stops at it, G001 says
    what it is, and the copy pybullet loads leaves it out: both files are checked in full."""
    os.mkfifo(tmp_path / "m.stl")
    (tmp_path / "fifo.urdf").write_text(FIFO_MESH)
    (tmp_path / "good.urdf").write_text(ONE_BOX)
    env = {**os.environ, "PYTHONPATH": str(REPO), "AR3CLI_CACHE_DIR": str(tmp_path / "c")}
    run = subprocess.run([sys.executable, "-m", "ar3cli", "lint-urdf", "--sim", "--timeout", "30", "--jobs", "1",
                          "-f", "json", "fifo.urdf", "good.urdf"], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert run.returncode == 1, run.stderr
    document = json.loads(run.stdout)
    assert [entry["error"] for entry in document["files"]] == [None, None]
    messages = [f["message"] for f in document["findings"] if f["path"] == "fifo.urdf" and f["rule"] == "G001"]
    assert len(messages) == 1 and "m.stl: not a regular file (a FIFO)" in messages[0], messages
    for name in ("fifo.urdf", "good.urdf"):  # the simulation checks of both ran
        assert any(f["path"] == name and f["rule"].startswith("P") for f in document["findings"]), name


def test_a_child_that_does_not_answer_in_time_is_stopped(monkeypatch) -> None:
    before = _descendants(os.getpid())

    def hang() -> None:
        report_stage("waiting for nothing")
        time.sleep(600)

    with pytest.raises(ChildTimeoutError) as raised:
        run_isolated(hang, "robot.urdf", timeout=0.5)
    assert raised.value.message == ("robot.urdf: timed out after 0.5 s while waiting for nothing; raise --timeout "
                                    "(0: no limit) if the file is just large")
    assert raised.value.exit_code == 2
    assert _descendants(os.getpid()) <= before
    monkeypatch.setattr(child_limits, "_timeout", 0.5)  # the command's --timeout, when none is given here
    with pytest.raises(ChildTimeoutError):
        run_isolated(hang, "robot.urdf")
    assert run_isolated(lambda: 7, "robot.urdf") == 7


def test_a_child_out_of_memory_is_one_line(monkeypatch) -> None:
    monkeypatch.setenv(child_limits.MEMORY_VARIABLE, "1500")

    def greedy() -> int:
        report_stage("reading a huge mesh")
        return len(bytearray(3 << 30))  # more than the limit: refused at once, nothing touched

    with pytest.raises(OutOfMemoryError) as raised:
        run_isolated(greedy, "robot.urdf")
    assert raised.value.message.startswith("robot.urdf: ran out of memory (the limit of a child process is 1.46 GB more than it starts with")
    assert raised.value.message.endswith("while reading a huge mesh")
    with pytest.raises(UserError, match=r"^in a test worker process: ran out of memory"):
        process_pool.map_in_processes(lambda item: len(bytearray(3 << 30)) if item else 0, [0, 1], 2,
                                      what="a test worker")


def test_a_pool_worker_that_hangs_is_stopped() -> None:
    before = _descendants(os.getpid())

    def work(item: int) -> int:
        if item == 1:  # the child's share
            time.sleep(600)
        return item

    with pytest.raises(UserError, match=r"^a test worker process timed out after 0.2 s per item; raise --timeout"):
        process_pool.map_in_processes(work, [0, 1], 2, what="a test worker", timeout=0.2)
    assert _descendants(os.getpid()) <= before


def test_memory_limit_default_and_override(monkeypatch) -> None:
    monkeypatch.delenv(child_limits.MEMORY_VARIABLE, raising=False)
    assert child_limits.MIN_MEMORY_BYTES <= child_limits.memory_limit() <= child_limits.MAX_MEMORY_BYTES
    monkeypatch.setenv(child_limits.MEMORY_VARIABLE, "0")
    assert child_limits.memory_limit() is None
    monkeypatch.setenv(child_limits.MEMORY_VARIABLE, "512")
    assert child_limits.memory_limit() == 512 << 20


def test_timeout_option(cli, tmp_path) -> None:
    robot = tmp_path / "good.urdf"
    robot.write_text(ONE_BOX)
    result = cli("fk-verify", str(robot), "--timeout", "nan")
    assert result.code == 2 and result.stderr.strip().splitlines() == [
        "ar3cli: error: Invalid value for '--timeout': nan: must be a finite number (see 'ar3cli fk-verify --help')"]
    result = cli("fk-verify", str(robot), "--timeout", "-1")
    assert result.code == 2 and len(result.stderr.strip().splitlines()) == 1
    assert cli("fk-verify", str(robot), "--timeout", "0", "--samples", "3").code == 0


def test_a_c_abort_under_the_memory_limit_names_both_likely_causes(monkeypatch) -> None:
    """C++ code that cannot allocate aborts (SIGABRT): the report names the memory limit too."""
    from ar3cli.infra.isolation import CrashError

    monkeypatch.setenv(child_limits.MEMORY_VARIABLE, "2048")
    with pytest.raises(CrashError) as raised:
        run_isolated(os.abort, "robot.urdf")
    assert raised.value.message.startswith("robot.urdf: pybullet crashed (SIGABRT) while running it: it ran out of "
                                           "memory (the limit of a child process is 2 GB more than it starts with; set AR3CLI_CHILD_MEMORY_MB")
    monkeypatch.setenv(child_limits.MEMORY_VARIABLE, "0")
    with pytest.raises(CrashError, match=r"\(SIGABRT\) while running it: a bug in pybullet's C code"):
        run_isolated(os.abort, "robot.urdf")


def test_a_child_whose_parent_died_before_it_asked_to_die_with_it_ends_at_once() -> None:
    """PR_SET_PDEATHSIG only covers a parent that dies after the request: the child compares its
    parent with the one it was forked from and ends if they differ (here: a pid that is not its parent)."""
    child_limits.prepare()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        try:
            child_limits.enter_child(parent=os.getpid())
        finally:
            os._exit(0)
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 1


def test_slow_isolated_work_is_announced_then_every_few_seconds(monkeypatch) -> None:
    """Issue 36 item 8: a child still working after SLOW_FIRST_S is announced with the stage it named
    (lint-urdf --sim on a humanoid is no longer silent off a terminal); quick work says nothing."""
    from ar3cli.infra import isolation

    said: list[str] = []
    monkeypatch.setattr(isolation, "SLOW_FIRST_S", 0.3)
    monkeypatch.setattr(isolation, "SLOW_EVERY_S", 60.0)
    isolation.announce_slow_work(said.append)
    try:
        assert run_isolated(lambda: 1, "quick.urdf", timeout=30) == 1

        def slow() -> int:
            report_stage("simulating it")
            time.sleep(1.0)
            return 7

        assert run_isolated(slow, "robot.urdf", timeout=30) == 7
    finally:
        isolation.announce_slow_work(None)
    assert len(said) == 1 and said[0].startswith("robot.urdf: still simulating it ("), said
