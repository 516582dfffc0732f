"""Read-only git: the one way ar3cli runs git (``lint-urdf --changed-since``, ``diff REV:path``).

Every call is ``git -C ROOT -c diff.autoRefreshIndex=false ...`` with ``GIT_OPTIONAL_LOCKS=0``, so
not even the index's stat cache is rewritten, and with a 5-minute limit; a missing git or a git
that hangs is a one-line :class:`~ar3cli.errors.UserError` that says what needed it.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

from ar3cli.errors import UserError

TIMEOUT_S = 300


def run_git(root: Path | str, *args: str, purpose: str, stdin: str | None = None) -> subprocess.CompletedProcess:
    """Run ``git -C root ARGS`` read-only and capture its output (bytes; ``stdin`` text is fed in).
    ``purpose`` names what needs git in the errors (``--changed-since``, ``reading a git revision``)."""
    environment = {**os.environ, "GIT_OPTIONAL_LOCKS": "0", "LC_ALL": "C"}
    try:
        return subprocess.run(["git", "-C", str(root), "-c", "diff.autoRefreshIndex=false", *args],
                              capture_output=True, env=environment, stdin=subprocess.DEVNULL if stdin is None else None,
                              input=stdin.encode("utf-8", "surrogateescape") if stdin is not None else None,
                              timeout=TIMEOUT_S)
    except FileNotFoundError:
        raise UserError(f"{purpose} needs git, and no git command was found") from None
    except subprocess.TimeoutExpired:
        raise UserError(f"{purpose}: git took longer than {TIMEOUT_S // 60} minutes in {root}") from None
