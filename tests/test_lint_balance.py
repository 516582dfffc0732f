"""How many processes lint-urdf starts by default (engine._workers); they take the files one at a
time, largest first (infra/streaming_pool.py)."""

from ar3cli.infra import process_pool
from ar3cli.lint.engine import BYTES_PER_WORKER, FILES_PER_WORKER, _workers


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
