"""Spread a list of independent jobs over forked processes; results come back in input order.

A bulk lint is pure Python, one file at a time. On Linux, ``os.fork`` copies this process in about
a millisecond, with everything already imported and loaded, so a few more processes pay off from
a couple of dozen files on (``multiprocessing`` and ``concurrent.futures`` cost ~30 ms to import and
start, as much as linting 20 files). This process takes a share of the work itself; each child
sends its results back pickled through a pipe and ends with ``os._exit`` (no atexit handler runs
twice, no inherited output buffer is flushed twice). Elsewhere (Windows, macOS: forking is not
safe there) everything runs in this process.

Every child lives under :mod:`ar3cli.infra.child_limits` (memory cap, death with its parent) and
stops cleanly on SIGTERM (:mod:`ar3cli.infra.shutdown`).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from collections.abc import Callable, Iterator, Sequence
from typing import BinaryIO, TypeVar

from ar3cli.errors import UserError
from ar3cli.infra import child_limits, shutdown
from ar3cli.infra.outcome import capture, pickled, read_until, unwrap

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
    """Processes to use: one per ``min_items_per_worker`` items, at most one per CPU (and
    :data:`MAX_AUTO_WORKERS`), 1 where forking is not available; ``requested`` overrides the rule
    but not the limits of one per item and one per CPU (more would only compete for them)."""
    if not can_fork():
        return 1
    if requested is not None:
        return max(1, min(requested, items, available_cpus()))
    return max(1, min(available_cpus(), MAX_AUTO_WORKERS, items // min_items_per_worker))


def map_in_processes(function: Callable[[Item], Result], items: Sequence[Item], workers: int,
                     what: str = "a worker", timeout: float | None = None) -> list[Result]:
    """``[function(item) for item in items]`` with the items dealt round-robin to ``workers``
    processes, this one included. Results must pickle. A child's UserError is raised here as it
    is, any other exception as a RuntimeError (an internal error); a child that dies (a crash in C
    code) becomes a one-line UserError naming ``what`` was running. Never a hang: if this process
    fails or is interrupted, the children are stopped (given time to clean up first); a child whose
    parent died is killed (:func:`~ar3cli.infra.child_limits.enter_child`). A child gets ``timeout``
    seconds per item (None: the command's ``--timeout``), plus the time to stop a child of its own,
    before it is stopped and that is a one-line UserError. When the system refuses another process
    or pipe, this process takes that share itself."""
    if workers <= 1 or len(items) <= 1 or not can_fork():
        return [function(item) for item in items]
    import time

    workers = min(workers, len(items))
    per_item = child_limits.timeout() if timeout is None else timeout
    children: dict[int, tuple[int, BinaryIO]] = {}  # share number -> (pid, the pipe it answers through)
    deadlines: dict[int, float | None] = {}
    settle = False
    child_limits.prepare()
    try:
        for number in range(1, workers):
            share_size = len(items[number::workers])
            deadlines[number] = None if per_item is None else time.monotonic() + share_size * (per_item + STOP_SECONDS)
            with interrupts_deferred() as mask:  # a Ctrl-C now would lose the new child's pid
                child = _start_child(function, items[number::workers], [pipe for _, pipe in children.values()], mask)
                if child is not None:
                    children[number] = child
            if child is None:
                break  # the system refuses more processes: this one takes the shares left over
        shares = {number: [function(item) for item in items[number::workers]]
                  for number in range(workers) if number not in children}
        for number, (pid, pipe) in list(children.items()):
            data, finished = read_until(pipe.fileno(), deadlines[number])
            if not finished:
                raise UserError(f"{what} process timed out after {per_item:g} s per item; raise --timeout "
                                "(0: no limit) if the input is just large")
            pipe.close()
            os.waitpid(pid, 0)
            del children[number]
            shares[number] = _unpack(data, what)
    except KeyboardInterrupt as exc:
        settle = shutdown.settle_after(exc)
        raise
    finally:
        stop_children(list(children.values()), settle=settle)  # this process failed or was interrupted
    results: list[Result] = [None] * len(items)  # type: ignore[list-item]
    for number, share in shares.items():
        results[number::workers] = share
    return results


@contextlib.contextmanager
def interrupts_deferred() -> Iterator[set[signal.Signals]]:
    """SIGINT and SIGTERM held back (delivered on leaving); yields the mask to restore in a forked child."""
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield previous
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def child_signals(mask: set[signal.Signals], parent: int) -> None:
    """In a forked child, first: the limits of :func:`~ar3cli.infra.child_limits.enter_child` (it
    dies with ``parent``), SIGTERM raises KeyboardInterrupt (:func:`~ar3cli.infra.shutdown.in_child`),
    then the parent's signal ``mask`` is restored. SIGTERM is how :func:`stop_children` asks a child
    to stop so that its ``finally`` blocks run (a PyBullet session removes its folder). SIGINT stays
    as the parent had it: a background job (``ar3cli ... &``, a CI step) is started with SIGINT
    ignored, and so stays uninterruptible, children included; asking with SIGINT found such a
    child deaf, and it was killed 3 s later without cleaning up."""
    child_limits.enter_child(parent)
    shutdown.in_child()
    signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def fork_child(mask: set[signal.Signals], run: Callable[[], None]) -> int:
    """Fork a child that sets up its signals (:func:`child_signals`: it dies with this process, restores
    ``mask``), runs ``run()`` and exits without returning, whatever happens; the child's pid, in the parent.
    OSError when the system refuses a process."""
    parent = os.getpid()
    pid = os.fork()
    if pid == 0:  # the child: never returns
        try:
            child_signals(mask, parent)
            run()
        finally:
            os._exit(0)
    return pid


def _start_child(function: Callable[[Item], Result], share: Sequence[Item], siblings: list[BinaryIO],
                 mask: set[signal.Signals]) -> tuple[int, BinaryIO] | None:
    """Fork a child that runs ``function`` over ``share`` and pickles the outcome into a pipe;
    None when the system refuses a pipe or a process (too many open files or processes). The child
    restores the signal ``mask`` and closes its copies of the ``siblings``' pipes: only the parent
    may hold a reader, so a child whose parent died gets EPIPE instead of waiting on a full pipe."""
    try:
        read_end, write_end = os.pipe()
    except OSError:
        return None
    parent = os.getpid()

    def in_child() -> None:
        os.close(read_end)
        for pipe in siblings:
            pipe.close()
        answer = pickled(capture(lambda: [_unless_orphaned(parent, function, item) for item in share]))
        with os.fdopen(write_end, "wb") as pipe:
            pipe.write(answer)

    try:
        pid = fork_child(mask, in_child)
    except OSError:
        os.close(read_end)
        os.close(write_end)
        return None
    os.close(write_end)
    return pid, os.fdopen(read_end, "rb")


def _unless_orphaned(parent: int, function: Callable[[Item], Result], item: Item) -> Result:
    """``function(item)`` in a child, which first ends itself if its parent is gone (killed)."""
    if os.getppid() != parent:
        os._exit(1)
    return function(item)


def _unpack(data: bytes, what: str) -> list[Result]:
    """The child's results; its failure is raised here as it would have been in this process."""
    import pickle

    try:
        outcome = pickle.loads(data)
    except Exception:  # noqa: BLE001 - an empty or cut answer: the child died
        raise UserError(f"{what} process died (a crash in a C library?); rerun with --jobs 1 to see "
                        "which input causes it") from None
    return unwrap(outcome, f"in {what} process: ")


SETTLE_SECONDS = 0.5
"""After Ctrl-C (which the children get too) a child is left this long to clean up on its own
(a PyBullet session removes its temporary folder) before it is asked to stop."""
STOP_SECONDS = 3.0
"""A child asked to stop (SIGTERM, see :func:`child_signals`) gets this long before it is killed."""


def stop_children(children: list[tuple[int, BinaryIO]], settle: bool) -> None:
    """End the remaining children: closed pipes, a moment to finish after Ctrl-C (``settle``),
    SIGTERM (which a forked child turns into KeyboardInterrupt), then SIGKILL. A second Ctrl-C
    meanwhile (or SIGTERM) waits until they are gone (a few seconds at most), so none is left running."""
    if not children:
        return
    with interrupts_deferred():
        for _, pipe in children:
            pipe.close()  # a child still writing its answer gets EPIPE and ends
        running = {pid for pid, _ in children}
        steps = ((None, SETTLE_SECONDS if settle else 0.0), (signal.SIGTERM, STOP_SECONDS), (signal.SIGKILL, None))
        for action, seconds in steps:
            for pid in running if action else ():
                with contextlib.suppress(ProcessLookupError):
                    os.kill(pid, action)
            running = _reap(running, seconds)
            if not running:
                return


def _reap(pids: set[int], seconds: float | None) -> set[int]:
    """Wait up to ``seconds`` (None: as long as it takes) for ``pids`` to end; those still running."""
    import time

    deadline = None if seconds is None else time.monotonic() + seconds
    running = set(pids)
    while running:
        for pid in list(running):
            try:
                done, _ = os.waitpid(pid, 0 if deadline is None else os.WNOHANG)
            except ChildProcessError:
                done = pid
            if done:
                running.discard(pid)
        if running and deadline is not None:
            if time.monotonic() >= deadline:
                break
            time.sleep(0.01)
    return running
