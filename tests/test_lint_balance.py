"""How lint-urdf deals its files to --jobs processes: by size, every file once (engine.balanced_order)."""

from ar3cli.lint.engine import balanced_order


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
