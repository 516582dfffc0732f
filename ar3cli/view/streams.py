"""Standard streams that a forked child can still use, in a process whose other threads write to them.

The viewer forks pybullet children (the kept contact checker, the simulated lint) while other threads
run: its own (progress lines on stderr), viser's (a warning, a logged connection error). A fork copies
only the forking thread; a lock another thread held at that moment stays locked in the child forever.
Python's buffered ``sys.stderr`` has such a lock, and every pybullet child flushes stderr first thing
(:func:`ar3cli.sim.capture.capture_fds`): a child forked while another thread was in the middle of a
write waited forever, and the simulated lint of the viewer timed out after 120 s (2 of 16 robots of
benchmarks/view_real_robots.py in one run, never the same two).

:func:`fork_safe_streams` replaces ``sys.stdout`` and ``sys.stderr`` with wrappers that write and flush
under one lock, and makes every ``os.fork`` in this process take that lock first (``os.register_at_fork``):
a fork waits for a write in progress, and no thread writes while one happens. Writes that bypass
``sys.stdout``/``sys.stderr`` (an object that kept a reference to the original stream from before) are
not covered; nothing in the viewer's threads does that.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
from collections.abc import Iterator
from typing import Any, TextIO

_LOCK = threading.Lock()
_active = 0
_registered = False


class _Guarded:
    """A text stream whose ``write``, ``writelines`` and ``flush`` hold the streams' lock."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        with _LOCK:
            return self._stream.write(text)

    def writelines(self, lines: Any) -> None:
        with _LOCK:
            self._stream.writelines(lines)

    def flush(self) -> None:
        with _LOCK:
            self._stream.flush()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


_forking = threading.local()
"""Whether this thread took the lock for the fork it is making (released after it, in both processes)."""


def _before_fork() -> None:
    if _active:
        _LOCK.acquire()
        _forking.held = True


def _after_fork() -> None:
    if getattr(_forking, "held", False):
        _forking.held = False
        _LOCK.release()


@contextlib.contextmanager
def fork_safe_streams() -> Iterator[None]:
    """``sys.stdout`` and ``sys.stderr`` guarded (see the module's docstring) inside the block."""
    global _active, _registered
    if not _registered:
        os.register_at_fork(before=_before_fork, after_in_parent=_after_fork, after_in_child=_after_fork)
        _registered = True
    stdout, stderr = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = _Guarded(stdout), _Guarded(stderr)  # type: ignore[assignment]
    _active += 1
    try:
        yield
    finally:
        _active -= 1
        sys.stdout, sys.stderr = stdout, stderr
