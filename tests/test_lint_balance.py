"""How lint-urdf deals its files to --jobs processes: by size, every file once (engine.balanced_order),
and how many processes it starts by default (engine._workers)."""

from ar3cli.infra import process_pool
from ar3cli.lint.engine import BYTES_PER_WORKER, FILES_PER_WORKER, _workers, balanced_order


def shares(sizes: list[int], workers: int) -> list[int]:
    """The bytes each process gets when map_in_processes deals ``balanced_order`` round-robin."""
    order = balanced_order(sizes, workers)
    return [sum(sizes[index] for index in order[worker::workers]) for worker in range(workers)]


def test_every_file_is_dealt_exactly_once() -> None:
    sizes = [5, 900, 3, 3, 70, 0, 12, 12, 4000]
    for workers in (1, 2, 3, 4, 9, 12):
        assert sorted(balanced_order(sizes, workers)) == list(range(len(sizes)))


def test_big_robots_are_shared_out_not_dealt_in_command_line_order() -> None:
    # two big robots first, then small ones: round-robin in the given order gives both big ones to
    # the first process; the snake draft gives one to each
    sizes = [1000, 10, 1000, 10, 10, 10]
    plain = [sum(sizes[0::2]), sum(sizes[1::2])]
    assert plain == [2010, 30]
    assert shares(sizes, 2) == [1020, 1020]


def test_one_worker_keeps_a_complete_order() -> None:
    assert balanced_order([3, 1, 2], 1) == [0, 2, 1]
    assert balanced_order([], 2) == []


def test_default_processes_follow_the_files_or_their_bytes(monkeypatch) -> None:
    monkeypatch.setattr(process_pool, "can_fork", lambda: True)
    monkeypatch.setattr(process_pool, "available_cpus", lambda: 4)
    small = [1000] * (2 * FILES_PER_WORKER)
    assert _workers(None, small, sim=False) == 2  # one per FILES_PER_WORKER files
    big = [BYTES_PER_WORKER] * 3
    assert _workers(None, big, sim=False) == 3  # three large robots: one process per BYTES_PER_WORKER
    assert _workers(None, [10 * BYTES_PER_WORKER], sim=False) == 1  # never more processes than files
    assert _workers(None, [1000] * 5, sim=False) == 1  # a few small files: not worth a fork
    assert _workers(1, big, sim=False) == 1  # --jobs decides
    assert _workers(None, [1000] * 4, sim=True) == 2  # --sim: one per two files, whatever their size
