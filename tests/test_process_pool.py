"""Forked workers: same results in the same order for any number of processes, and failures that
surface as one line, never a hang or a stray process."""

from __future__ import annotations

import json
import os
import signal

import pytest

from ar3cli import process_pool
from ar3cli.errors import UserError
from ar3cli.process_pool import map_in_processes, worker_count

pytestmark = pytest.mark.skipif(not process_pool.can_fork(), reason="forked workers are used on Linux only")


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
    assert worker_count(None, items=23, min_items_per_worker=24) == 1  # too few to repay a fork
    assert worker_count(None, items=50, min_items_per_worker=24) == 2
    assert worker_count(None, items=1000, min_items_per_worker=24) == 4  # one per CPU
    monkeypatch.setattr(process_pool, "can_fork", lambda: False)
    assert worker_count(None, items=1000, min_items_per_worker=24) == 1


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
        remembered = json.loads((cache / "lint-results-v1.json").read_text())
        loaded = [f for f in json.loads(result.stdout)["files"] if f["loaded"]]
        assert len(remembered) == len(loaded) > 20
    assert outputs[1] == outputs[3]
