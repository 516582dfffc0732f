"""Spread a list of independent jobs over forked processes; results come back in input order.

A bulk lint is pure Python, one file at a time. On Linux, ``os.fork`` copies this process in about
a millisecond, with everything already imported and loaded, so a few more processes pay off from
a couple of dozen files on (``multiprocessing`` and ``concurrent.futures`` cost ~30 ms to import and
start, as much as linting 20 files). This process takes a share of the work itself; each child
sends its results back pickled through a pipe and ends with ``os._exit`` (no atexit handler runs
twice, no inherited output buffer is flushed twice). Elsewhere (Windows, macOS: forking is not
safe there) everything runs in this process.
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Callable, Sequence
from typing import TypeVar

from ar3cli.errors import UserError

Item = TypeVar("Item")
Result = TypeVar("Result")

MAX_AUTO_WORKERS = 8
"""Automatic mode never uses more processes than this, however many CPUs there are."""


def can_fork() -> bool:
    """True on Linux, where forking a process that has imported lxml (or pybullet) is safe."""
    return sys.platform.startswith("linux") and hasattr(os, "fork")


def available_cpus() -> int:
    """CPUs this process may run on (a container's CPU set, not the host's count)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def worker_count(requested: int | None, items: int, min_items_per_worker: int) -> int:
    """Processes to use: ``requested`` when given (at most one per item); otherwise one per CPU as
    long as each gets ``min_items_per_worker`` items, and 1 where forking is not available."""
    if requested is not None:
        return max(1, min(requested, items))
    if not can_fork():
        return 1
    return max(1, min(available_cpus(), MAX_AUTO_WORKERS, items // min_items_per_worker))


def map_in_processes(function: Callable[[Item], Result], items: Sequence[Item], workers: int,
                     what: str = "a worker") -> list[Result]:
    """``[function(item) for item in items]`` with the items dealt round-robin to ``workers``
    processes, this one included. Results must pickle. A child's UserError is raised here as it
    is, any other exception as a RuntimeError (an internal error); a child that dies (a crash in C
    code) becomes a one-line UserError naming ``what`` was running. Never a hang."""
    if workers <= 1 or len(items) <= 1 or not can_fork():
        return [function(item) for item in items]
    workers = min(workers, len(items))
    children: list[tuple[int, int]] = []
    try:
        for index in range(1, workers):
            children.append(_start_child(function, items[index::workers]))
        shares = [[function(item) for item in items[0::workers]]]
        while children:
            data = _read_and_reap(*children[0])
            children.pop(0)
            shares.append(_unpack(data, what))
    finally:
        for pid, pipe in children:  # this process failed or was interrupted: stop the others
            _stop(pid, pipe)
    results: list[Result] = [None] * len(items)  # type: ignore[list-item]
    for index, share in enumerate(shares):
        results[index::workers] = share
    return results


def _start_child(function: Callable[[Item], Result], share: Sequence[Item]) -> tuple[int, int]:
    """Fork a child that runs ``function`` over ``share`` and pickles the outcome into a pipe."""
    import pickle

    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: never returns
        os.close(read_end)
        try:
            try:
                outcome: tuple = ("ok", [function(item) for item in share])
            except UserError as exc:
                outcome = ("user-error", (exc.message, exc.exit_code))
            except BaseException as exc:  # noqa: BLE001 - reported by the parent
                outcome = ("error", f"{type(exc).__name__}: {exc}")
            with os.fdopen(write_end, "wb") as pipe:
                pickle.dump(outcome, pipe, protocol=pickle.HIGHEST_PROTOCOL)
        finally:
            os._exit(0)
    os.close(write_end)
    return pid, read_end


def _read_and_reap(pid: int, pipe: int) -> bytes:
    """Everything the child wrote (read to the end first, so a large answer cannot block it)."""
    with os.fdopen(pipe, "rb") as stream:
        data = stream.read()
    os.waitpid(pid, 0)
    return data


def _unpack(data: bytes, what: str) -> list:
    """The child's results; its failure is raised here as it would have been in this process."""
    import pickle

    try:
        status, payload = pickle.loads(data)
    except Exception:  # noqa: BLE001 - an empty or cut answer: the child died
        raise UserError(f"{what} process died (a crash in a C library?); rerun with --jobs 1 to see "
                        "which input causes it") from None
    if status == "user-error":
        raise UserError(*payload)
    if status != "ok":
        raise RuntimeError(f"in {what} process: {payload}")
    return payload


def _stop(pid: int, pipe: int) -> None:
    try:
        os.kill(pid, signal.SIGTERM)
        os.waitpid(pid, 0)
    except OSError:
        pass
    try:
        os.close(pipe)
    except OSError:
        pass
