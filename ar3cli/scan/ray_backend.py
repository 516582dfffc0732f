"""The Ray backend: batches of files as Ray tasks, rows streamed back to the driver, which stores them.

Each task is :func:`~ar3cli.scan.worker.check_batch`: the same forked worker, per-file limit and
crash containment as the local backend, so the rows are the same file for file (timings aside);
pybullet runs only inside it (each file's ``--sim`` checks in their own forked child, hence their
own pybullet client). At most :data:`IN_FLIGHT_PER_CPU` batches per CPU are submitted at a time,
so the driver's memory does not grow with the dataset. ``address`` joins a running cluster
(``ray start --head`` elsewhere; every node needs ar3cli installed and the files at the same
paths); without it a local Ray is started with ``jobs`` CPUs and shut down at the end (``address=
"local"``: a cluster running on this machine is not joined by accident).

Joining a cluster (measured with Ray 2.60): ``ray start --head`` enables token authentication by
default and keeps the token in ``~/.ray/auth_token``, but a driver given an explicit address never
turns authentication on by itself, so it was refused ("InvalidAuthToken") after 21 s of C++ warnings;
:func:`join_settings` asks for token mode when a token is at hand (Ray's own rule for a local
cluster) and never overrides an ``RAY_AUTH_MODE`` the user set. An address nobody listens on took
Ray 3.5 minutes of warnings: it is tried first with a plain TCP connection (:func:`check_reachable`),
and Ray's own output while it starts is kept off the terminal and quoted only when it fails.
"""

from __future__ import annotations

import importlib.util
import os
import socket
from collections.abc import Iterator
from pathlib import Path

from ar3cli.errors import UserError
from ar3cli.scan.record import Row
from ar3cli.scan.worker import ScanSettings, check_batch

IN_FLIGHT_PER_CPU = 2
MAX_BATCH = 32
"""Files per task at most (a static check is ~2 ms a file, a task's round trip ~5-10 ms);
smaller scans use smaller batches so that every CPU gets work."""


REACH_TIMEOUT_S = 5.0
"""Seconds a TCP connection to the head may take before the address is called unreachable."""
GCS_WAIT_S = "5"
"""Ray's ``RAY_gcs_server_port_wait_time_s`` (attempts ~1 s apart to reach the head's GCS) unless the
user set it: Ray's default 20 attempts made a refused token 21 s of warnings; 5 made it 7 s. The head
already answered on TCP (:func:`check_reachable`), so 5 s is for a head still starting."""
TOKEN_ENVIRONMENT = ("RAY_AUTH_TOKEN", "RAY_AUTH_TOKEN_PATH")


def join_settings(address: str | None) -> None:
    """Set what Ray reads from the environment to join ``address`` (before Ray is imported): token
    authentication when a token is at hand and ``RAY_AUTH_MODE`` is not set, and a shorter wait
    for the head's GCS (:data:`GCS_WAIT_S`). Nothing for a local Ray."""
    if not address:
        return
    os.environ.setdefault("RAY_gcs_server_port_wait_time_s", GCS_WAIT_S)
    if "RAY_AUTH_MODE" in os.environ:
        return
    token_file = Path(os.environ.get("RAY_AUTH_TOKEN_PATH") or Path.home() / ".ray" / "auth_token")
    if os.environ.get("RAY_AUTH_TOKEN") or token_file.is_file():
        os.environ["RAY_AUTH_MODE"] = "token"


def check_reachable(address: str) -> None:
    """A one-line UserError when nothing accepts a TCP connection at ``HOST:PORT`` within seconds;
    other forms (``auto``, ``ray://...``) are left to Ray."""
    host, separator, port = address.rpartition(":")
    if not separator or not port.isdigit() or "://" in address:
        return
    try:
        socket.create_connection((host.strip("[]") or "127.0.0.1", int(port)), timeout=REACH_TIMEOUT_S).close()
    except OSError as exc:
        raise UserError(f"cannot reach Ray at {address}: {exc.strerror or exc}; is a head running there "
                        "(ray start --head --port PORT)?") from None


def _why_ray_failed(exc: Exception, said: str) -> str:
    """The sentence that explains a failed ``ray.init``: Ray's own exception, or what it printed."""
    if "InvalidAuthToken" in said or "Authentication token" in said:
        return ("the cluster wants an authentication token: run where `ray start --head` ran (~/.ray/auth_token), "
                "or set RAY_AUTH_TOKEN to the head's `ray get-auth-token`")
    return " ".join(str(exc).split()) or type(exc).__name__


def require_ray() -> None:
    """A one-line UserError (exit 2) when Ray is not installed."""
    if importlib.util.find_spec("ray") is None:
        raise UserError("--backend ray needs Ray, which is not installed: pip install 'ar3cli[ray]'")


def ray_rows(todo: dict[str, str], settings: ScanSettings, jobs: int | None, timeout: float | None,
             address: str | None) -> Iterator[Row]:
    """The rows of ``todo`` (absolute path -> content hash) as the cluster finishes each batch."""
    require_ray()
    if address:
        check_reachable(address)
    join_settings(address)
    import logging

    import ray

    from ar3cli.infra.fd_capture import redirected_fds
    from ar3cli.infra.process_pool import available_cpus

    started_here = not ray.is_initialized()
    if started_here:
        options = {"include_dashboard": False, "log_to_driver": False, "logging_level": logging.ERROR}
        with redirected_fds((1, 2)) as said:  # Ray's C++ and Python start-up chatter
            try:
                if address:
                    ray.init(address=address, **options)
                else:
                    ray.init(address="local", num_cpus=jobs or available_cpus(), **options)
                failure = None
            except Exception as exc:  # noqa: BLE001 - any failure to start or reach Ray is the user's to fix
                failure = exc
        if failure is not None:
            raise UserError(f"cannot {'join' if address else 'start'} Ray{f' at {address}' if address else ''}: "
                            f"{_why_ray_failed(failure, said.text)}") from None
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
        with redirected_fds((1, 2)):
            for reference in running:
                ray.cancel(reference, force=True)
            if started_here:
                ray.shutdown()
