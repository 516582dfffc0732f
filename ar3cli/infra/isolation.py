"""Run pybullet work in a forked child, so that a crash in C is a message, not the end of ar3cli.

pybullet is C code; on inputs nobody tested it can die by SIGSEGV or SIGABRT, which Python cannot
catch (``docs/pybullet-facts.md``, section 10). :func:`run_isolated` forks (about a millisecond on
Linux, with everything already imported), runs the work in the child and pickles its answer back
through a pipe. When the child dies instead, the caller gets a one-line :class:`CrashError`
naming the signal and what pybullet was doing then (:func:`report_stage`, which the child calls
as it goes: "loading it", "rendering it", ...).

Limits (:mod:`ar3cli.infra.child_limits`): the child has a capped address space and dies with this
process; this process waits for its answer at most :func:`~ar3cli.infra.child_limits.timeout`
seconds (the command's ``--timeout``), then stops it: ``robot.urdf: timed out after 120 s while
loading it; ...`` (:class:`ChildTimeoutError`). A child out of memory is :class:`OutOfMemoryError`. Both
are CrashErrors: whoever reports a crash as a file's error reports them the same way.

Temporary files: a process killed by a signal runs no ``finally`` and no ``atexit``, so the child
makes its temporary files in a folder this process created, and this process removes it
whatever happened. Where fork is not available (Windows, macOS), the work runs in this process.
"""

from __future__ import annotations

import contextlib
import io
import os
import pickle
import shutil
import signal
import sys
import tempfile
from collections.abc import Callable
from typing import BinaryIO, TypeVar

from ar3cli.errors import EXIT_USAGE, UserError
from ar3cli.infra import child_limits, shutdown
from ar3cli.infra.outcome import OutOfMemory, capture, pickled, read_until, unwrap
from ar3cli.infra.process_pool import can_fork, fork_child, interrupts_deferred, stop_children

Result = TypeVar("Result")

DEFAULT_STAGE = "running it"
_stage_pipe: BinaryIO | None = None
"""In an isolated child: where :func:`report_stage` writes. None everywhere else."""
SLOW_FIRST_S = 2.0
"""An isolated child still working after this long is announced (:func:`announce_slow_work`)..."""
SLOW_EVERY_S = 10.0
"""...and again every this many seconds: one line each, never a flood in a CI log."""
_announce: Callable[[str], None] | None = None


def announce_slow_work(say: Callable[[str], None] | None) -> None:
    """From now on, ``say`` a line when an isolated child works longer than :data:`SLOW_FIRST_S`
    (``robot.urdf: still simulating it (2 s)``), and every :data:`SLOW_EVERY_S` after: a command
    whose single step can take long (lint-urdf --sim on a humanoid: ~7 s) is then not silent off a
    terminal. None turns it off. Forked workers inherit it."""
    global _announce
    _announce = say


def _slow_note(subject: str, stage: str = DEFAULT_STAGE) -> Callable[[list[bytes]], None] | None:
    """The ``tick`` of :func:`~ar3cli.infra.outcome.read_until` that announces slow work, or None."""
    if _announce is None:
        return None
    import time

    started = time.monotonic()
    due = [started + SLOW_FIRST_S]
    say = _announce

    def tick(chunks: list[bytes]) -> None:
        now = time.monotonic()
        if now >= due[0]:
            due[0] = now + SLOW_EVERY_S
            say(f"{subject}: still {_messages(b''.join(chunks), stage)[1]} ({now - started:.0f} s)")

    return tick


class CrashError(UserError):
    """The isolated child died (a signal, or an exit without an answer); exit code 2."""

    def __init__(self, message: str, signal_name: str, stage: str) -> None:
        super().__init__(message, EXIT_USAGE)
        self.signal_name = signal_name
        self.stage = stage


class ChildTimeoutError(CrashError):
    """The isolated child did not answer within the timeout and was stopped; exit code 2."""


class OutOfMemoryError(CrashError):
    """The isolated child reached its memory limit (a MemoryError in Python); exit code 2."""


def report_stage(stage: str) -> None:
    """Tell the parent what the child is about to do (quoted if the child dies); a no-op elsewhere."""
    if _stage_pipe is not None:
        _send(_stage_pipe, ("stage", stage))


def run_limited(work: Callable[[], Result], subject: str, stage: str) -> Result:
    """``work()`` (ar3cli's own work on an untrusted file: a diff, a summary, a fix's plan) in a forked
    child with the limits of every child: the command's ``--timeout`` and the memory cap. A file
    built to take hours or gigabytes is then one line (``robot.urdf: timed out after 120 s while
    comparing it; ...``), never a run that stalls or is killed. ``stage`` says what the work does."""
    return run_isolated(work, subject, library="ar3cli", stage=stage)


def run_isolated(work: Callable[[], Result], subject: str, cause: Callable[[], str | None] | None = None,
                 timeout: float | None = None, meanwhile: Callable[[], None] | None = None,
                 library: str = "pybullet", stage: str = DEFAULT_STAGE) -> Result:
    """``work()`` in a forked child; its result (which must pickle) or its exception comes back.

    A UserError in the child is raised here as it was; any other exception becomes a RuntimeError
    (an internal error); a child that dies raises :class:`CrashError`, e.g.
    ``ur5.urdf: pybullet crashed (SIGSEGV) while loading it``, ``subject`` being the file, followed
    by what ``cause()`` says is the likely reason (asked only after a crash), if anything. A child
    that has not answered after ``timeout`` seconds (None: the command's ``--timeout``; 0 or
    infinity: no limit) is stopped and :class:`ChildTimeoutError` raised; a MemoryError in the child is
    :class:`OutOfMemoryError`. Ctrl-C or SIGTERM stops the child (after Ctrl-C, which it got too,
    it gets a moment to finish; then SIGTERM, then SIGKILL). ``meanwhile()``, if given, runs in this
    process while the child works (after the fork, before waiting; where there is no fork, after
    ``work()``): what the caller needs next, e.g. its report's imports, then costs no wall time.
    """
    if not can_fork():
        result = work()
        if meanwhile is not None:
            meanwhile()
        return result
    import time

    seconds = child_limits.timeout() if timeout is None else (timeout if 0 < timeout < float("inf") else None)
    folder = tempfile.mkdtemp(prefix="ar3cli-")
    child: tuple[int, BinaryIO] | None = None
    settle = False
    try:
        child_limits.prepare()
        with interrupts_deferred() as mask:  # a Ctrl-C between fork and bookkeeping would lose the child
            child = _start(work, folder, mask)
        if meanwhile is not None:
            meanwhile()
        data, finished = read_until(child[1].fileno(), None if seconds is None else time.monotonic() + seconds,
                                    _slow_note(subject, stage))
        answer, stage = _messages(data, stage)
        if not finished:
            raise ChildTimeoutError(f"{subject}: timed out after {seconds:g} s while {stage}; raise --timeout "
                                    "(0: no limit) if the file is just large", "timeout", stage)
        child[1].close()
        status = _reap(child[0])
        child = None
        return _unpack(answer, stage, status, subject, cause, library)
    except KeyboardInterrupt as exc:
        settle = shutdown.settle_after(exc)
        raise
    finally:
        try:
            if child is not None:
                stop_children([child], settle=settle)
        finally:  # a second Ctrl-C, delivered once the child is stopped, must not keep the folder
            shutil.rmtree(folder, ignore_errors=True)


def _start(work: Callable[[], Result], folder: str, mask: set[signal.Signals]) -> tuple[int, BinaryIO]:
    """Fork the child that runs ``work`` with its temporary files in ``folder``."""
    for stream in (sys.stdout, sys.stderr):
        stream.flush()  # what is buffered now must not be written twice
    read_end, write_end = os.pipe()

    def in_child() -> None:
        os.close(read_end)
        _run_child(work, folder, os.fdopen(write_end, "wb"))

    try:
        pid = fork_child(mask, in_child)
    except OSError as exc:
        os.close(read_end)
        os.close(write_end)
        raise UserError(f"cannot start a process for pybullet: {exc.strerror or exc}") from None
    os.close(write_end)
    return pid, os.fdopen(read_end, "rb")


def _run_child(work: Callable[[], Result], folder: str, pipe: BinaryIO) -> None:
    """The child's whole life: run ``work``, send its outcome, flush what it printed."""
    global _stage_pipe
    import faulthandler

    faulthandler.disable()  # a crash is reported by the parent in one line, not as a stack dump
    sys.stdout.flush()
    os.dup2(2, 1)  # stdout is the parent's (it may carry JSON): whatever the child prints goes to stderr
    tempfile.tempdir = folder
    _stage_pipe = pipe
    pipe.write(pickled(capture(work)))
    pipe.flush()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):  # a closed stream must not turn into a crash report
            stream.flush()
    pipe.close()


def _send(pipe: BinaryIO, message: tuple) -> None:
    pipe.write(pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL))
    pipe.flush()


def _messages(data: bytes, stage: str = DEFAULT_STAGE) -> tuple[tuple | None, str]:
    """The child's messages, read to the end: (its final answer or None, the last stage it named,
    else ``stage``)."""
    answer = None
    stream = io.BytesIO(data)
    while True:
        try:
            kind, payload = pickle.load(stream)
        except (EOFError, pickle.UnpicklingError, ValueError, TypeError):
            break  # the end, or a message cut short by the child's death
        if kind == "stage":
            stage = payload
        else:
            answer = (kind, payload)
    return answer, stage


def _reap(pid: int) -> int:
    """Wait for the child; its wait status."""
    while True:
        try:
            return os.waitpid(pid, 0)[1]
        except InterruptedError:  # pragma: no cover - retried by Python itself since 3.5
            continue
        except ChildProcessError:
            return 0


def _unpack(answer: tuple | None, stage: str, status: int, subject: str,
            cause: Callable[[], str | None] | None, library: str = "pybullet") -> Result:
    if answer is not None:
        try:
            return unwrap(answer)
        except OutOfMemory as exc:
            raise OutOfMemoryError(f"{subject}: {exc.message} while {stage}", "MemoryError", stage) from None
    code = os.waitstatus_to_exitcode(status)
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
    else:
        name = f"exit {code}"
    reason = cause() if cause is not None else None
    if reason:
        explanation = f"; {reason}"
    elif name == "SIGABRT" and child_limits.memory_limit() is not None:  # how C++ ends when memory runs out
        explanation = (f": it ran out of memory (the limit of a child process is {child_limits.describe_memory_limit()}; "
                       f"set {child_limits.MEMORY_VARIABLE} to change it), or a bug in {library}'s C code that this "
                       f"file triggers (see 'ar3cli lint-urdf {subject}')")
    else:
        explanation = f": a bug in {library}'s C code that this file triggers (see 'ar3cli lint-urdf {subject}')"
    raise CrashError(f"{subject}: {library} crashed ({name}) while {stage}{explanation}", name, stage)
