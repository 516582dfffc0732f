"""Forked workers that stream results back as each item finishes, with a time limit per item.

:func:`~ar3cli.infra.process_pool.map_in_processes` answers once, in input order, when every share
is done; a lint or a scan of 100,000 files must have each result as it arrives, stop one slow
file without losing the others, and replace a worker that died. Here the parent hands out one item at a time
through a pipe, reads length-prefixed answers with ``select``, and for each item yields
``(item, outcome)``: an :data:`~ar3cli.infra.outcome.Outcome` (``("ok", result)``, ...), or
``("crash", message)`` when the worker died on it, or ``("timeout", message)`` when it ran past
``timeout`` seconds (the worker is then stopped and replaced).

Each worker is its own process group, so that stopping it after a timeout also ends a pybullet
child it may have started (:mod:`ar3cli.infra.isolation`), and Ctrl-C reaches only the parent,
which stops the workers as :func:`~ar3cli.infra.process_pool.stop_children` does everywhere.
A worker whose parent was killed reads end-of-file on its task pipe and ends. Signals and the
answer format are the ones :mod:`ar3cli.infra.process_pool` uses.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import selectors
import signal
import struct
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, BinaryIO

from ar3cli.infra import child_limits, process_pool
from ar3cli.infra.outcome import capture, pickled
from ar3cli.infra.process_pool import child_signals, interrupts_deferred, stop_children

_HEADER = struct.Struct("<Q")


@dataclass
class _Worker:
    pid: int
    tasks: int
    """Write end of the pipe the parent sends item numbers through."""
    answers: int
    """Read end of the pipe the worker answers through."""
    buffer: bytearray = field(default_factory=bytearray)
    item: int | None = None
    started: float = 0.0


def stream(work: Callable[[Any], Any], items: Sequence[Any], workers: int,
           timeout: float | None = None) -> Iterator[tuple[Any, tuple[str, Any]]]:
    """``(item, outcome)`` for every item, in the order they finish (see the module docstring).

    Where fork is not available the items run here, one after the other, without a time limit.
    """
    if not process_pool.can_fork():
        for item in items:
            yield item, capture(lambda item=item: work(item))
        return
    queue = list(range(len(items)))[::-1]  # popped from the end: first item first
    running: dict[int, _Worker] = {}  # answer fd -> worker
    selector = selectors.DefaultSelector()
    interrupted = False
    try:
        for _ in range(max(1, min(workers, len(items)))):
            _add(selector, running, _start(work, items))
        while running:
            for worker in running.values():
                if worker.item is None:
                    _give(worker, queue)
            deadline = min((w.started + timeout for w in running.values() if w.item is not None and timeout),
                           default=None)
            wait = None if deadline is None else max(0.0, deadline - time.monotonic())
            ready = selector.select(wait)
            for key, _ in ready:
                worker = running[key.fd]
                for outcome in _answers(worker):
                    yield items[worker.item], outcome  # type: ignore[index]
                    worker.item = None
                    _give(worker, queue)
                if worker.answers in running and worker.buffer is None:  # end of file: the worker ended
                    lost = worker.item
                    _remove(selector, running, worker)
                    os.close(worker.answers)
                    if worker.tasks >= 0:
                        os.close(worker.tasks)
                    status = _wait(worker.pid)
                    if lost is not None:
                        yield items[lost], ("crash", f"the worker died ({status}) while checking it")
                    if queue and len(running) < workers:
                        _add(selector, running, _start(work, items))
            now = time.monotonic()
            for worker in [w for w in running.values() if w.item is not None and timeout
                           and now - w.started >= timeout]:
                lost = worker.item
                _remove(selector, running, worker)
                _stop(worker, settle=False)
                yield items[lost], ("timeout", f"stopped after the per-file limit of {timeout:g} s")  # type: ignore[index]
                if queue:
                    _add(selector, running, _start(work, items))
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        for worker in list(running.values()):
            _remove(selector, running, worker)
            _stop(worker, settle=interrupted)
        selector.close()


def _start(work: Callable[[Any], Any], items: Sequence[Any]) -> _Worker:
    """Fork a worker: it reads item numbers until end of file and answers each one."""
    task_read, task_write = os.pipe()
    answer_read, answer_write = os.pipe()
    child_limits.prepare()
    parent = os.getpid()
    with interrupts_deferred() as mask:
        pid = os.fork()
        if pid == 0:  # the worker: never returns
            try:
                import faulthandler

                faulthandler.disable()  # a crash is one row, not a stack dump on stderr
                os.setpgid(0, 0)
                child_signals(mask, parent)
                os.close(task_write)
                os.close(answer_read)
                _serve(work, items, task_read, answer_write)
            finally:
                os._exit(0)
    os.close(task_read)
    os.close(answer_write)
    return _Worker(pid, task_write, answer_read)


def _serve(work: Callable[[Any], Any], items: Sequence[Any], tasks: int, answers: int) -> None:
    """The worker's loop: an item number in, its pickled outcome out, until the parent closes the pipe."""
    with os.fdopen(tasks, "rb") as incoming, os.fdopen(answers, "wb") as outgoing:
        while True:
            number = incoming.read(_HEADER.size)
            if len(number) < _HEADER.size:
                return  # the parent is done with this worker, or gone
            item = items[_HEADER.unpack(number)[0]]
            answer = pickled(capture(lambda item=item: work(item)))
            outgoing.write(_HEADER.pack(len(answer)) + answer)
            outgoing.flush()


def _add(selector: selectors.BaseSelector, running: dict[int, _Worker], worker: _Worker) -> None:
    selector.register(worker.answers, selectors.EVENT_READ)
    running[worker.answers] = worker


def _remove(selector: selectors.BaseSelector, running: dict[int, _Worker], worker: _Worker) -> None:
    selector.unregister(worker.answers)
    del running[worker.answers]


def _give(worker: _Worker, queue: list[int]) -> None:
    """Send the worker the next item, or close its task pipe when there is none (it then ends)."""
    if worker.tasks < 0:
        return
    if not queue:
        os.close(worker.tasks)
        worker.tasks = -1
        return
    worker.item = queue.pop()
    worker.started = time.monotonic()
    with contextlib.suppress(BrokenPipeError):  # it died: its end of file says so
        os.write(worker.tasks, _HEADER.pack(worker.item))


def _answers(worker: _Worker) -> Iterator[tuple[str, Any]]:
    """The complete answers now readable from the worker; sets ``buffer`` to None at end of file."""
    data = os.read(worker.answers, 1 << 20)
    if not data:
        worker.buffer = None  # type: ignore[assignment]
        return
    worker.buffer += data
    while len(worker.buffer) >= _HEADER.size:
        size = _HEADER.unpack_from(worker.buffer)[0]
        if len(worker.buffer) < _HEADER.size + size:
            return
        payload = bytes(worker.buffer[_HEADER.size:_HEADER.size + size])
        del worker.buffer[:_HEADER.size + size]
        try:
            yield pickle.loads(payload)
        except Exception:  # noqa: BLE001 - a garbled answer: the worker is broken
            yield "error", "the worker's answer could not be read"


def _wait(pid: int) -> str:
    """Reap the worker; how it ended (``SIGSEGV``, ``exit 1``)."""
    try:
        status = os.waitpid(pid, 0)[1]
    except ChildProcessError:
        return "unknown"
    code = os.waitstatus_to_exitcode(status)
    if code < 0:
        with contextlib.suppress(ValueError):
            return signal.Signals(-code).name
        return f"signal {-code}"
    return f"exit {code}"


def _stop(worker: _Worker, settle: bool) -> None:
    """Stop a worker (a moment to clean up, SIGTERM, then SIGKILL) and anything left in its group."""
    if worker.tasks >= 0:
        os.close(worker.tasks)
        worker.tasks = -1
    pipe: BinaryIO = os.fdopen(worker.answers, "rb")
    stop_children([(worker.pid, pipe)], settle=settle)
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(worker.pid, signal.SIGKILL)
