"""The Ray backend: batches of files as Ray tasks, rows streamed back to the driver, which stores them.

Each task is :func:`~ar3cli.scan.worker.check_batch`: the same forked worker, per-file limit and
crash containment as the local backend, so the rows are the same file for file (timings aside);
pybullet runs only inside it (each file's ``--sim`` checks in their own forked child, hence their
own pybullet client). At most :data:`IN_FLIGHT_PER_CPU` batches per CPU are submitted at a time,
so the driver's memory does not grow with the dataset. ``address`` joins a running cluster
(``ray start --head`` elsewhere; every node needs ar3cli installed and the files at the same
paths); without it a local Ray is started with ``jobs`` CPUs and shut down at the end.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Iterator

from ar3cli.errors import UserError
from ar3cli.scan.record import Row
from ar3cli.scan.worker import ScanSettings, check_batch

IN_FLIGHT_PER_CPU = 2
MAX_BATCH = 32
"""Files per task at most (a static check is ~2 ms a file, a task's round trip ~5-10 ms);
smaller scans use smaller batches so that every CPU gets work."""


def require_ray() -> None:
    """A one-line UserError (exit 2) when Ray is not installed."""
    if importlib.util.find_spec("ray") is None:
        raise UserError("--backend ray needs Ray, which is not installed: pip install 'ar3cli[ray]'")


def ray_rows(todo: dict[str, str], settings: ScanSettings, jobs: int | None, timeout: float | None,
             address: str | None) -> Iterator[Row]:
    """The rows of ``todo`` (absolute path -> content hash) as the cluster finishes each batch."""
    require_ray()
    import logging

    import ray

    from ar3cli.infra.process_pool import available_cpus

    started_here = not ray.is_initialized()
    if started_here:
        options = {"include_dashboard": False, "log_to_driver": False, "logging_level": logging.ERROR}
        try:
            if address:
                ray.init(address=address, **options)
            else:
                ray.init(num_cpus=jobs or available_cpus(), **options)
        except Exception as exc:  # noqa: BLE001 - any failure to start or reach Ray is the user's to fix
            raise UserError(f"cannot start Ray{f' at {address}' if address else ''}: {exc}") from None
    cpus = max(1, int(ray.cluster_resources().get("CPU", 1)))
    items = list(todo.items())
    size = max(1, min(MAX_BATCH, len(items) // (cpus * 4)))
    batches = [items[start:start + size] for start in range(0, len(items), size)][::-1]
    task = ray.remote(num_cpus=1, max_retries=1)(check_batch)
    running: dict = {}
    try:
        while batches or running:
            while batches and len(running) < cpus * IN_FLIGHT_PER_CPU:
                batch = batches.pop()
                running[task.remote(batch, settings, timeout)] = batch
            done, _ = ray.wait(list(running), num_returns=1)
            batch = running.pop(done[0])
            try:
                rows = ray.get(done[0])
            except Exception as exc:  # noqa: BLE001 - the task's worker died (out of memory, node lost)
                message = f"the Ray task died: {type(exc).__name__}"
                rows = [Row(path, sha, settings.key, "crash", message=message) for path, sha in batch]
            yield from rows
    finally:
        for reference in running:
            ray.cancel(reference, force=True)
        if started_here:
            ray.shutdown()
