"""The one exception type that turns into a one-line message and an exit code.

Commands never print tracebacks for bad input: anything the user can act on is raised as
:class:`UserError` and rendered by the CLI as ``ar3cli: error: <message>`` on stderr.
"""

from __future__ import annotations

EXIT_OK = 0
EXIT_PROBLEMS = 1
EXIT_USAGE = 2
EXIT_INTERNAL = 3
"""A bug in ar3cli (an unexpected exception), reported in one line."""


class UserError(Exception):
    """A problem the user can fix: missing file, bad XML, unresolvable mesh, bad option.

    ``message`` is one line saying what, where (file:line when known) and what to do.
    """

    def __init__(self, message: str, exit_code: int = EXIT_USAGE) -> None:
        super().__init__(message)
        self.message = " ".join(message.split("\n")).strip()
        self.exit_code = exit_code

    def __str__(self) -> str:
        return self.message
