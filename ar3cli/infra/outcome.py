"""A call's result or exception as plain data, and back: how a forked child answers its parent.

Both ways of running work in a child (:mod:`ar3cli.infra.process_pool` for shares of a list,
:mod:`ar3cli.infra.isolation` for pybullet work that may crash) send the same answer through a
pipe: ``("ok", result)``, ``("user-error", (message, exit code))``, ``("interrupted", None)``,
``("out-of-memory", "Type: text")`` (the child reached its memory limit, see
:mod:`ar3cli.infra.child_limits`) or ``("error", "Type: text")``, pickled; :func:`read_until` reads it
within a time limit. The parent turns it back into the result or into the
exception as it would have been raised in this process (a bug becomes a RuntimeError: the
traceback stayed in the child).
"""

from __future__ import annotations

import os
import pickle
import time
from collections.abc import Callable
from typing import Any, TypeVar

from ar3cli.errors import UserError

Result = TypeVar("Result")
Outcome = tuple[str, Any]


class OutOfMemory(UserError):
    """A child reached its memory limit (MemoryError in Python); exit code 2."""


def capture(work: Callable[[], Result]) -> Outcome:
    """``work()``'s result, or what it raised, as an :data:`Outcome`."""
    try:
        return "ok", work()
    except UserError as exc:
        return "user-error", (exc.message, exc.exit_code)
    except KeyboardInterrupt:
        return "interrupted", None
    except MemoryError as exc:
        return "out-of-memory", f"{type(exc).__name__}: {exc}"
    except BaseException as exc:  # noqa: BLE001 - reported by the parent as an internal error
        return "error", f"{type(exc).__name__}: {exc}"


def pickled(outcome: Outcome) -> bytes:
    """The outcome as bytes; a result that cannot be pickled (a bug) becomes an error outcome."""
    try:
        return pickle.dumps(outcome, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception as exc:  # noqa: BLE001 - reported by the parent as an internal error
        return pickle.dumps(("error", f"cannot send the result back: {type(exc).__name__}: {exc}"))


def unwrap(outcome: Outcome, where: str = "") -> Any:
    """The result, or the exception raised again here; ``where`` prefixes a bug's message
    (``"in a lint worker process: "``)."""
    kind, payload = outcome
    if kind == "ok":
        return payload
    if kind == "user-error":
        raise UserError(*payload)
    if kind == "interrupted":
        raise KeyboardInterrupt
    if kind == "out-of-memory":
        from ar3cli.infra.child_limits import MEMORY_VARIABLE, describe_memory_limit

        raise OutOfMemory(f"{where}ran out of memory (the limit of a child process is {describe_memory_limit()}; "
                          f"set {MEMORY_VARIABLE} to change it)")
    raise RuntimeError(f"{where}{payload}")


WRITER_GRACE_S = 0.5
TICK_S = 1.0
"""Seconds between two calls of :func:`read_until`'s ``tick`` while it waits."""


def read_until(fd: int, deadline: float | None,
               tick: Callable[[list[bytes]], None] | None = None) -> tuple[bytes, bool]:
    """Everything written to the pipe ``fd`` until its end, or until ``deadline``
    (``time.monotonic()``; None: no limit) passes with nothing more to read: (the bytes, whether
    the end was reached). A writer still writing is not cut off while its data keeps coming: once
    something came, each wait lasts at least :data:`WRITER_GRACE_S` (a large answer fills the pipe,
    and the writer must be scheduled again to write the rest). ``tick(chunks so far)`` is called at
    least every :data:`TICK_S` while waiting (a note that the work is slow)."""
    import select

    chunks: list[bytes] = []
    while True:
        if deadline is not None or tick is not None:
            left = None if deadline is None else max(WRITER_GRACE_S if chunks else 0.0, deadline - time.monotonic())
            wait = left if tick is None else TICK_S if left is None else min(left, TICK_S)
            ready, _, _ = select.select([fd], [], [], wait)
            if tick is not None:
                tick(chunks)
            if not ready:
                if deadline is not None and time.monotonic() >= deadline:
                    return b"".join(chunks), False
                continue
        chunk = os.read(fd, 1 << 16)
        if not chunk:
            return b"".join(chunks), True
        chunks.append(chunk)
