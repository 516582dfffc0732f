"""pybullet work kept alive in a forked child between questions: load once, then ask many times.

:func:`~ar3cli.sim.session.run_pybullet` forks a child per piece of work: right for a command, too
slow for a viewer that asks "which links touch?" at every slider move (loading the robot again each
time costs 0.1-1 s). A :class:`KeptChild` forks once, runs ``setup()`` there (load the robot), and
then answers each :meth:`KeptChild.ask` with ``answer(state, request)`` in the same child, through a
pair of pipes (requests and answers are pickled; a few milliseconds per question).

It keeps :func:`run_pybullet`'s promises: the child lives under :mod:`ar3cli.infra.child_limits`
(memory cap, death with its parent) with its temporary files in a folder this process removes; a
crash of pybullet's C code is a one-line :class:`~ar3cli.infra.isolation.CrashError` (``robot.urdf:
pybullet crashed (SIGSEGV) while checking contacts``), a child that does not answer in time is
stopped (:class:`~ar3cli.infra.isolation.ChildTimeoutError`), and a UserError the work raises comes
back as it was. After a crash or a timeout every later question raises the same error at once: the
caller shows it and goes on without pybullet.

The parent's death signal (``PR_SET_PDEATHSIG``) fires when the *thread* that forked the child ends:
open a KeptChild from a thread that lives as long as the child should (a viewer's worker thread).
Questions may come from any thread; they are answered one at a time.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import shutil
import struct
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from typing import Any, BinaryIO, Generic, TypeVar

from ar3cli.errors import UserError

State = TypeVar("State")

ASK_TIMEOUT_S = 60.0
"""Seconds one question may take before the child is stopped: a question is one pose (about a
millisecond for the largest robots of example-robot-data), so only a hung child reaches it."""
_LENGTH = struct.Struct("<Q")


class KeptChild(Generic[State]):
    """A forked child holding ``setup()``'s state; :meth:`ask` runs ``answer(state, request)`` there.

    ``subject`` (the file) and ``cause()`` (the element known to crash pybullet, asked after a crash)
    make the crash line, as :func:`~ar3cli.sim.session.run_pybullet` does; ``loading`` and ``asking``
    say what the child was doing (``while loading it``, ``while checking contacts``). The constructor
    returns once the setup is done, and raises its UserError (or the crash) when it fails; ``timeout``
    is the setup's limit (None: the command's ``--timeout``).
    """

    def __init__(self, setup: Callable[[], State], answer: Callable[[State, Any], Any], subject: str,
                 cause: Callable[[], str | None] | None = None, loading: str = "loading it",
                 asking: str = "answering", timeout: float | None = None) -> None:
        from ar3cli.infra import child_limits
        from ar3cli.infra.process_pool import can_fork

        self.subject, self.cause, self.asking = subject, cause, asking
        self.error: UserError | None = None
        self._lock = threading.Lock()
        self._pid: int | None = None
        self._requests: BinaryIO | None = None
        self._answers: BinaryIO | None = None
        self._closed = False
        self._in_process = not can_fork()
        self._state: State | None = None
        self._answer = answer
        self._folder = tempfile.mkdtemp(prefix="ar3cli-")
        if self._in_process:  # Windows, macOS: the work runs here, as run_isolated does there
            try:
                self._state = setup()
            except BaseException:
                self.close()
                raise
            return
        seconds = child_limits.timeout() if timeout is None else timeout
        try:
            self._start(setup)
            self._receive(loading, seconds)
        except BaseException:
            self.close()
            raise

    # ---- the parent's side ----------------------------------------------------------------------
    def ask(self, request: Any) -> Any:
        """``answer(state, request)`` computed in the child (its UserError raised here as it was)."""
        with self._lock:
            if self.error is not None:
                raise self.error
            if self._closed:
                raise UserError(f"{self.subject}: the pybullet child is closed")
            if self._in_process:
                return self._answer(self._state, request)  # type: ignore[arg-type]
            with contextlib.suppress(OSError):  # the child is gone: its exit status says why
                _send(self._requests, request)  # type: ignore[arg-type]
            try:
                return self._receive(self.asking, ASK_TIMEOUT_S)
            except UserError as exc:
                from ar3cli.infra.isolation import CrashError

                if isinstance(exc, CrashError):
                    self.error = exc
                raise

    def close(self) -> None:
        """Stop the child (its pipe closed, then SIGTERM, then SIGKILL) and remove its folder; twice is fine."""
        from ar3cli.infra.process_pool import stop_children

        self._closed = True
        pid, self._pid = self._pid, None
        requests, self._requests = self._requests, None
        answers, self._answers = self._answers, None
        if requests is not None:
            with contextlib.suppress(OSError):
                requests.close()  # the child reads the end of its requests and leaves
        if pid is not None and answers is not None:
            stop_children([(pid, answers)], settle=False)
        elif answers is not None:
            answers.close()
        shutil.rmtree(self._folder, ignore_errors=True)

    def __enter__(self) -> KeptChild[State]:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def _start(self, setup: Callable[[], State]) -> None:
        from ar3cli.infra import child_limits
        from ar3cli.infra.process_pool import fork_child, interrupts_deferred

        for stream in (sys.stdout, sys.stderr):
            stream.flush()  # what is buffered now must not be written twice
        child_limits.prepare()
        request_read, request_write = os.pipe()
        answer_read, answer_write = os.pipe()
        def in_child() -> None:
            os.close(request_write)
            os.close(answer_read)
            self._serve(setup, os.fdopen(request_read, "rb"), os.fdopen(answer_write, "wb"))

        with interrupts_deferred() as mask:  # a Ctrl-C between fork and bookkeeping would lose the child
            try:
                pid = fork_child(mask, in_child)
            except OSError as exc:
                for fd in (request_read, request_write, answer_read, answer_write):
                    os.close(fd)
                raise UserError(f"cannot start a process for pybullet: {exc.strerror or exc}") from None
            self._pid = pid
        os.close(request_read)
        os.close(answer_write)
        self._requests = os.fdopen(request_write, "wb")
        self._answers = os.fdopen(answer_read, "rb")

    def _receive(self, stage: str, seconds: float | None) -> Any:
        """The child's next answer; a child that died or did not answer in ``seconds`` is a CrashError."""
        from ar3cli.infra.isolation import ChildTimeoutError
        from ar3cli.infra.outcome import unwrap

        assert self._answers is not None
        deadline = None if seconds is None or seconds <= 0 else time.monotonic() + seconds
        message = _read_message(self._answers.fileno(), deadline)
        if message is None:
            self._crashed(stage)
        if message is _TIMED_OUT:
            self.close()
            self.error = ChildTimeoutError(f"{self.subject}: timed out after {seconds:g} s while {stage}",
                                           "timeout", stage)
            raise self.error
        try:
            outcome = pickle.loads(message)  # type: ignore[arg-type]
        except Exception:  # noqa: BLE001 - a message cut short: the child died writing it
            self._crashed(stage)
        return unwrap(outcome)

    def _crashed(self, stage: str) -> None:
        """Reap the dead child and raise its crash line (what run_pybullet says of a crash)."""
        from ar3cli.infra.isolation import _unpack as crash_of

        pid, self._pid = self._pid, None
        status = 0
        if pid is not None:
            with contextlib.suppress(ChildProcessError):
                status = os.waitpid(pid, 0)[1]
        self.close()
        try:
            crash_of(None, stage, status, self.subject, self.cause)
        except UserError as exc:
            self.error = exc
            raise

    # ---- the child's side -----------------------------------------------------------------------
    def _serve(self, setup: Callable[[], State], requests: BinaryIO, answers: BinaryIO) -> None:
        """The child's whole life: set up, answer each request, leave when the requests end."""
        import faulthandler

        from ar3cli.infra.outcome import capture, pickled

        faulthandler.disable()  # a crash is reported by the parent in one line, not as a stack dump
        sys.stdout.flush()
        os.dup2(2, 1)  # stdout is the parent's (it may carry JSON): whatever the child prints goes to stderr
        tempfile.tempdir = self._folder
        state: Any = None

        def set_up() -> None:
            nonlocal state
            state = setup()

        try:
            outcome = capture(set_up)
            _write_message(answers, pickled(outcome))
            if outcome[0] != "ok":
                return
            while True:
                request = _read_request(requests)
                if request is _END:
                    return
                _write_message(answers, pickled(capture(lambda request=request: self._answer(state, request))))
        except (KeyboardInterrupt, BrokenPipeError, OSError):
            return
        finally:
            closing = getattr(state, "close", None)
            if callable(closing):
                with contextlib.suppress(Exception):
                    closing()


_END = object()
_TIMED_OUT = object()


def _send(pipe: BinaryIO, request: Any) -> None:
    _write_message(pipe, pickle.dumps(request, protocol=pickle.HIGHEST_PROTOCOL))


def _write_message(pipe: BinaryIO, data: bytes) -> None:
    pipe.write(_LENGTH.pack(len(data)) + data)
    pipe.flush()


def _read_request(pipe: BinaryIO) -> Any:
    """The next request (blocking), :data:`_END` when the parent closed the pipe."""
    head = pipe.read(_LENGTH.size)
    if len(head) < _LENGTH.size:
        return _END
    (size,) = _LENGTH.unpack(head)
    data = pipe.read(size)
    if len(data) < size:
        return _END
    return pickle.loads(data)


def _read_message(fd: int, deadline: float | None) -> bytes | object | None:
    """One length-prefixed message from ``fd``: its bytes, None at the end of the pipe (the child
    died), :data:`_TIMED_OUT` when ``deadline`` (``time.monotonic()``) passed first."""
    import select

    chunks: list[bytes] = []
    have = 0
    total: int | None = None  # header and body, once the header is in
    while total is None or have < total:
        if deadline is not None:
            ready, _, _ = select.select([fd], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                return _TIMED_OUT
        chunk = os.read(fd, _LENGTH.size - have if total is None else min(1 << 20, total - have))
        if not chunk:
            return None
        chunks.append(chunk)
        have += len(chunk)
        if total is None and have == _LENGTH.size:
            total = _LENGTH.size + _LENGTH.unpack(b"".join(chunks))[0]
    return b"".join(chunks)[_LENGTH.size:]
