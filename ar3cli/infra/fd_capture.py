"""Capture what C code writes to file descriptors (1, 2) for the duration of a block.

C libraries (pybullet, Ray's core worker) print with ``printf``/``fprintf`` or their own loggers to
the descriptors themselves, which ``contextlib.redirect_stdout`` cannot catch: their text would land
in the middle of a JSON document on stdout or flood a CI log. :func:`redirected_fds` points the
descriptors at a temporary file for the block and gives back what was written.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator, Sequence
from dataclasses import dataclass


@dataclass
class Redirected:
    """What was written to the redirected descriptors (filled in when the block ends)."""

    text: str = ""


@contextlib.contextmanager
def redirected_fds(fds: Sequence[int] = (1, 2)) -> Iterator[Redirected]:
    """Point ``fds`` at one temporary file for the block, then back; safe to nest and exception-safe."""
    redirected = Redirected()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    saved = [os.dup(fd) for fd in fds]
    with tempfile.TemporaryFile(mode="w+b") as sink:
        try:
            for fd in fds:
                os.dup2(sink.fileno(), fd)
            yield redirected
        finally:
            for stream in (sys.stdout, sys.stderr):
                with contextlib.suppress(Exception):
                    stream.flush()
            for fd, copy in zip(fds, saved):
                os.dup2(copy, fd)
                os.close(copy)
            sink.seek(0)
            redirected.text = sink.read().decode("utf-8", "replace")
