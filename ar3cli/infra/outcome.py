"""A call's result or exception as plain data, and back: how a forked child answers its parent.

Both ways of running work in a child (:mod:`ar3cli.infra.process_pool` for shares of a list,
:mod:`ar3cli.infra.isolation` for pybullet work that may crash) send the same answer through a
pipe: ``("ok", result)``, ``("user-error", (message, exit code))``, ``("interrupted", None)`` or
``("error", "Type: text")``, pickled. The parent turns it back into the result or into the
exception as it would have been raised in this process (a bug becomes a RuntimeError: the
traceback stayed in the child).
"""

from __future__ import annotations

import pickle
from collections.abc import Callable
from typing import Any, TypeVar

from ar3cli.errors import UserError

Result = TypeVar("Result")
Outcome = tuple[str, Any]


def capture(work: Callable[[], Result]) -> Outcome:
    """``work()``'s result, or what it raised, as an :data:`Outcome`."""
    try:
        return "ok", work()
    except UserError as exc:
        return "user-error", (exc.message, exc.exit_code)
    except KeyboardInterrupt:
        return "interrupted", None
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
    raise RuntimeError(f"{where}{payload}")
