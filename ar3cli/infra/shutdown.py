"""SIGTERM handled like Ctrl-C: children stopped, temporary folders removed, exit code 143.

A CI cancel, ``timeout`` and ``docker stop`` send SIGTERM. Python's default is to die at once: no
``finally`` runs, forked workers went on at 99% CPU for a minute and a half and the temporary
folder stayed. :func:`terminate_like_interrupt` makes SIGTERM raise :class:`Terminated`, a
KeyboardInterrupt, so every path that cleans up after Ctrl-C cleans up after it too; the
application turns it into exit code 143 (128 + SIGTERM) where Ctrl-C gives 130.

Only the first SIGTERM interrupts: a second one (a process group signalled twice, an impatient
caller) must not cut the cleanup short, which it would by raising inside a ``finally``. A
disposition set by whoever started ar3cli (SIGTERM ignored) is left alone.
"""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Iterator

EXIT_TERMINATED = 128 + signal.SIGTERM


class Terminated(KeyboardInterrupt):
    """Raised by SIGTERM: a request to stop, handled as Ctrl-C is (but not a Ctrl-C: the children
    did not get it too, so they need not be given time to react to it first)."""


_received = False


def received() -> bool:
    """True once this process got SIGTERM (while :func:`terminate_like_interrupt` was in force)."""
    return _received


def _raise_once(_signal_number: int, _frame: object) -> None:
    global _received
    if _received:
        return  # already stopping: let the cleanup finish
    _received = True
    raise Terminated


@contextlib.contextmanager
def terminate_like_interrupt() -> Iterator[None]:
    """SIGTERM raises :class:`Terminated` (once) inside the block; the previous handler after it.
    Does nothing where SIGTERM is ignored, or when called off the main thread (signal handlers
    can only be set there)."""
    global _received
    try:
        previous = signal.getsignal(signal.SIGTERM)
        if previous is signal.SIG_IGN:
            yield
            return
        signal.signal(signal.SIGTERM, _raise_once)
    except ValueError:  # not the main thread
        yield
        return
    _received = False
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous if previous is not None else signal.SIG_DFL)


def in_child() -> None:
    """In a forked child: SIGTERM (how a parent asks a child to stop) raises :class:`Terminated`
    once, whatever the parent had; so its ``finally`` blocks run (a PyBullet session removes its
    folder) and a second SIGTERM does not interrupt them."""
    global _received
    _received = False
    signal.signal(signal.SIGTERM, _raise_once)


def settle_after(exc: BaseException) -> bool:
    """Whether children should be left a moment to stop on their own after ``exc``: after Ctrl-C
    (the whole process group got it), not after SIGTERM (only this process did)."""
    return isinstance(exc, KeyboardInterrupt) and not isinstance(exc, Terminated)
