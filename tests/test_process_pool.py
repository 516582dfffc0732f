"""Forked workers: same results in the same order for any number of processes, and failures that
surface as one line, never a hang or a stray process."""

from __future__ import annotations

import json
import os
import signal

import pytest

from ar3cli.errors import UserError
from ar3cli.infra import process_pool
from ar3cli.infra.process_pool import map_in_processes, worker_count
from tests.conftest import cache_entries

pytestmark = pytest.mark.skipif(not process_pool.can_fork(), reason="forked workers are used on Linux only")
several_cpus = pytest.mark.skipif(process_pool.available_cpus() < 2,
                                  reason="--jobs is limited to one process per CPU: with one CPU nothing is forked")


def children() -> set[int]:
    """Process ids of this process's children, live or zombie (Linux: /proc)."""
    found: set[int] = set()
    for task in os.listdir("/proc/self/task"):
        with open(f"/proc/self/task/{task}/children", encoding="ascii") as listing:
            found.update(int(pid) for pid in listing.read().split())
    return found


@pytest.fixture
def no_children_left():
    """Fails the test when it leaves a child process (running or unreaped) behind."""
    before = children()
    yield
    assert children() <= before


def square_with_pid(item: int) -> tuple[int, int]:
    return item * item, os.getpid()


@pytest.mark.parametrize("workers", [1, 2, 3, 7])
def test_results_come_back_in_order_whatever_the_number_of_processes(workers: int, no_children_left) -> None:
    results = map_in_processes(square_with_pid, list(range(20)), workers)
    assert [value for value, _ in results] == [i * i for i in range(20)]
    assert len({pid for _, pid in results}) == workers  # really spread: one pid per process


def test_errors_in_a_child_are_raised_here(no_children_left) -> None:
    def user_error(item: int) -> int:
        if item == 1:  # in the child's share (items[1::2])
            raise UserError("robot.urdf: something the user can fix", exit_code=2)
        return item

    with pytest.raises(UserError, match="something the user can fix"):
        map_in_processes(user_error, [0, 1, 2, 3], 2)

    def bug(item: int) -> int:
        if item == 3:
            raise KeyError("oops")
        return item

    with pytest.raises(RuntimeError, match="in a test worker process: KeyError"):
        map_in_processes(bug, [0, 1, 2, 3], 2, what="a test worker")


def test_a_result_that_cannot_be_pickled_is_an_internal_error_not_a_crash(no_children_left) -> None:
    import threading

    def lock(item: int):
        return threading.Lock() if item == 1 else item

    with pytest.raises(RuntimeError, match="in a test worker process: cannot send the result back: TypeError: cannot pickle"):
        map_in_processes(lock, [0, 1], 2, what="a test worker")


def test_a_child_that_dies_is_a_one_line_error_not_a_hang(no_children_left) -> None:
    def crash(item: int) -> int:
        if item == 1:
            os.kill(os.getpid(), signal.SIGKILL)  # as a segfault in C code would end it
        return item

    with pytest.raises(UserError, match="a lint worker process died .* rerun with --jobs 1"):
        map_in_processes(crash, [0, 1, 2, 3], 2, what="a lint worker")


def test_worker_count(monkeypatch) -> None:
    monkeypatch.setattr(process_pool, "available_cpus", lambda: 4)
    assert worker_count(3, items=100, min_items_per_worker=24) == 3  # asked for: used
    assert worker_count(8, items=2, min_items_per_worker=24) == 2  # never more than the items
    assert worker_count(2000, items=1000, min_items_per_worker=24) == 4  # nor than the CPUs
    assert worker_count(None, items=23, min_items_per_worker=24) == 1  # too few to repay a fork
    assert worker_count(None, items=50, min_items_per_worker=24) == 2
    assert worker_count(None, items=1000, min_items_per_worker=24) == 4  # one per CPU
    monkeypatch.setattr(process_pool, "can_fork", lambda: False)
    assert worker_count(None, items=1000, min_items_per_worker=24) == 1


@several_cpus
def test_lint_output_and_caches_do_not_depend_on_jobs(cli, tmp_path, pybullet_data_dir) -> None:
    """The same JSON for --jobs 1 and 3 on 30 real models; what the children learnt is saved."""
    models = sorted(str(p) for p in pybullet_data_dir.rglob("*.urdf") if "random_urdfs" not in p.parts)[:30]
    outputs = {}
    for jobs in (1, 3):
        cache = tmp_path / f"cache{jobs}"
        result = cli("lint-urdf", "--no-config", "-f", "json", "--jobs", str(jobs), *models,
                     env={"AR3CLI_CACHE_DIR": str(cache)})
        assert result.code in (0, 1) and result.stderr == "", result.stderr
        outputs[jobs] = result.stdout
        remembered = cache_entries(cache, "lint-results-v1")
        loaded = [f for f in json.loads(result.stdout)["files"] if f["loaded"]]
        assert len(remembered) == len(loaded) > 20
    assert outputs[1] == outputs[3]


def test_when_the_system_refuses_a_process_this_one_does_the_work(monkeypatch, no_children_left) -> None:
    calls = []
    real_fork = os.fork

    def fork_twice_then_refuse():
        calls.append(1)
        if len(calls) > 2:
            raise BlockingIOError(11, "Resource temporarily unavailable")
        return real_fork()

    monkeypatch.setattr(os, "fork", fork_twice_then_refuse)
    results = map_in_processes(square_with_pid, list(range(30)), 6)
    assert [value for value, _ in results] == [i * i for i in range(30)]
    assert len({pid for _, pid in results}) == 3  # this process and the two children it got


ORPHAN_SCRIPT = """
import os, signal, sys, time
from ar3cli.infra.process_pool import map_in_processes
PARENT = os.getpid()
def work(item):
    if os.getpid() != PARENT:
        open(sys.argv[1], "a").write(f"{os.getpid()}\\n")
    time.sleep(0.1)
    if os.getpid() == PARENT and item == 4:
        deadline = time.monotonic() + 20
        while not os.path.exists(sys.argv[1]) and time.monotonic() < deadline:
            time.sleep(0.01)  # the child has begun (a slow machine may start it late)
        os.kill(PARENT, signal.SIGKILL)  # as `kill -9` or a timeout would end it
    return item
map_in_processes(work, list(range(1000)), 2)
"""


def test_a_child_whose_parent_is_killed_stops(tmp_path) -> None:
    import subprocess
    import sys
    import time

    from tests.conftest import REPO

    record = tmp_path / "child.txt"
    run = subprocess.run([sys.executable, "-c", ORPHAN_SCRIPT, str(record)], env={**os.environ, "PYTHONPATH": str(REPO)},
                         timeout=60)
    assert run.returncode == -signal.SIGKILL
    child = int(record.read_text().split()[0])
    deadline = time.monotonic() + 20  # it stops within 0.1 s; its 500 items would take 50 s
    while time.monotonic() < deadline and _alive(child):
        time.sleep(0.05)
    assert not _alive(child)


def _alive(pid: int) -> bool:
    """Running (a zombie waiting for a reaper counts as ended)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as status:
            return status.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


@several_cpus
def test_facts_a_child_learnt_are_saved_even_if_this_process_never_needed_that_cache(cli, tmp_path,
                                                                                  pybullet_data_dir) -> None:
    """The parent lints files without meshes (it never loads the mesh cache); the child lints the
    KUKA, whose mesh boxes must still reach the parent's store."""
    models = [pybullet_data_dir / "cartpole.urdf", pybullet_data_dir / "block.urdf",
              pybullet_data_dir / "kuka_iiwa" / "model.urdf"]
    cache = tmp_path / "cache"
    result = cli("lint-urdf", "--no-config", "--select", "I007", "--jobs", "2", *map(str, models),
                 env={"AR3CLI_CACHE_DIR": str(cache)})
    assert result.code in (0, 1), result.stderr
    boxes = cache_entries(cache, "mesh-bounds-v2")
    assert any("kuka_iiwa" in key for key in boxes)


@several_cpus
def test_ctrl_c_during_a_parallel_sim_lint_leaves_no_temporary_folder(tmp_path, pybullet_data_dir) -> None:
    """Ctrl-C reaches every process of the group; children get time to close their PyBullet
    sessions (which remove their temporary copies) before they are stopped."""
    import subprocess
    import sys
    import time

    from tests.conftest import REPO

    names = ["r2d2.urdf", "kuka_iiwa/model.urdf", "franka_panda/panda.urdf", "quadruped/minitaur.urdf",
             "a1/a1.urdf", "laikago/laikago.urdf", "husky/husky.urdf", "racecar/racecar.urdf"]
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    env = {**os.environ, "PYTHONPATH": str(REPO), "TMPDIR": str(temporary), "AR3CLI_CACHE_DIR": str(tmp_path / "c")}
    for delay in (0.05, 0.4):
        run = subprocess.Popen([sys.executable, "-m", "ar3cli", "lint-urdf", "--sim", "--jobs", "2", "-f", "json",
                                *(str(pybullet_data_dir / name) for name in names)],
                               env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
        while not any(temporary.iterdir()) and run.poll() is None:  # a session is open: it is linting
            time.sleep(0.01)
        time.sleep(delay)
        os.killpg(run.pid, signal.SIGINT)
        _, stderr = run.communicate(timeout=60)
        assert run.returncode in (130, 1), stderr  # 1: it finished first
        assert "Traceback" not in stderr.decode()
        assert run.returncode == 1 or stderr.decode().strip().splitlines() == ["ar3cli: interrupted"]
        assert sorted(p.name for p in temporary.iterdir()) == []


def test_a_child_being_stopped_gets_to_clean_up(tmp_path, no_children_left) -> None:
    """When this process fails, a child is asked to stop with SIGTERM (its finally blocks run: a
    PyBullet session removes its temporary folder), not killed outright."""
    import time

    marker, started = tmp_path / "cleaned", tmp_path / "started"

    def work(item: int) -> int:
        if item == 0:  # this process's share: it fails while the child works
            deadline = time.monotonic() + 30
            while not started.exists() and time.monotonic() < deadline:  # not before (a slow machine
                time.sleep(0.01)  # once let the SIGINT arrive before the child reached its try block)
            raise ValueError("this process failed")
        try:
            started.write_text("yes")
            time.sleep(30)
        finally:
            time.sleep(0.2)
            marker.write_text("done")
        return item

    # Whatever this process does with SIGINT: a shell starts a background job (`cmd &`, a CI step)
    # with SIGINT ignored, which a forked child inherits (asked with SIGINT, it was killed, not stopped).
    for disposition in (signal.default_int_handler, signal.SIG_IGN):
        marker.unlink(missing_ok=True)
        started.unlink(missing_ok=True)
        previous = signal.signal(signal.SIGINT, disposition)
        try:
            with pytest.raises(ValueError, match="this process failed"):
                map_in_processes(work, [0, 1], 2)
        finally:
            signal.signal(signal.SIGINT, previous)
        assert marker.read_text() == "done"


def test_children_keep_this_processs_sigint_disposition() -> None:
    """A background job (SIGINT ignored) stays uninterruptible, children included: a SIGINT that
    reaches a child does not turn the whole run into 'interrupted'."""
    import time

    def work(item: int) -> int:
        if item == 1:  # the child's share
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)
        return 2 * item

    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        assert map_in_processes(work, [0, 1], 2) == [0, 2]
    finally:
        signal.signal(signal.SIGINT, previous)
