"""Start the language server on stdin/stdout: the extra checked, the protocol's stream kept clean.

LSP messages travel on stdout, so nothing else may write there: the protocol gets its own copy of
the stdout descriptor, and descriptor 1 then points at stderr, so a print, a C library's output or
a forked child's chatter lands in the editor's log instead of breaking the stream.
"""

from __future__ import annotations

import os
import sys

from ar3cli.errors import UserError
from ar3cli.server.options import ServerOptions

INSTALL_HINT = "pip install 'ar3cli[server]'"


def require_extra() -> None:
    """pygls and lsprotocol are importable, else a one-line UserError (exit 2) naming the pip command."""
    try:
        import lsprotocol  # noqa: F401
        import pygls  # noqa: F401
    except ImportError as exc:
        missing = getattr(exc, "name", None) or "pygls"
        raise UserError(f"the language server needs the 'server' extra ({missing} is not installed); run: "
                        f"{INSTALL_HINT}") from None


def serve(options: ServerOptions) -> None:
    """Serve LSP on stdin/stdout until the editor says exit (or closes the pipe)."""
    require_extra()
    import logging

    from ar3cli.server.protocol import build

    logging.basicConfig(level=logging.WARNING, stream=sys.stderr, format="ar3cli server: %(levelname)s: %(message)s")
    server = build(options)
    _freeze_what_is_loaded()
    sys.stdout.flush()
    protocol_out = os.fdopen(os.dup(sys.stdout.fileno()), "wb")
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())
    server.start_io(sys.stdin.buffer, protocol_out)


def _freeze_what_is_loaded() -> None:
    """Import what every check needs, then move every object alive now out of the garbage
    collector's reach (``gc.freeze``): the modules, lsprotocol's hundreds of classes and the rules
    live as long as the server, and a full collection no longer walks them on every run."""
    import gc

    import ar3cli.analysis.findings  # noqa: F401 - the lint engine and every rule, loaded once here
    import ar3cli.lint.rules  # noqa: F401
    import ar3cli.urdf.model  # noqa: F401

    gc.collect()
    gc.freeze()
