"""Read a file that may be anything a user passes (a FIFO, a device, a huge file) without hanging.

Every file ar3cli reads is read here: robot files and xacro includes, YAML inputs, ``package.xml``,
SRDF, meshes, and the on-disk caches. :func:`read_bytes` opens without blocking, checks the open
descriptor (a regular file, not larger than the caller's limit), and never reads more than the
limit even when the file grows meanwhile; :func:`read_head` reads only a file's first bytes the same
way. Every problem is a one-line :class:`UserError`.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from ar3cli.errors import UserError

MAX_FILE_BYTES = 50 * 1024 * 1024
"""Files larger than this are refused: no real URDF comes close (the largest in pybullet_data is ~1 MB)."""

ROBOT_FILE = "a .urdf or .xacro file"
"""What :func:`read_bytes` expects unless told otherwise (the wording of its messages)."""


def kind_of(mode: int) -> str:
    """What a file that is not a regular file is, for a message: "a FIFO", "a device", "a socket",
    "a folder" (from its ``st_mode``)."""
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISDIR(mode):
        return "a folder"
    return "not a regular file"


def read_bytes(path: Path, *, limit: int | None = None, what: str = ROBOT_FILE) -> bytes:
    """Return the file's bytes, or raise a one-line :class:`UserError` saying why not.

    ``limit`` is the largest size accepted, in bytes (:data:`MAX_FILE_BYTES` when not given); ``what``
    says what the file should be, with its article ("a YAML file", "a mesh"), for the messages.
    The file is opened without blocking
    and checked on the open descriptor: a FIFO, a device or a terminal (which would wait forever or
    never end) is refused even if it replaced a regular file a moment ago, and at most ``limit`` + 1
    bytes are read, so a file growing while it is read cannot exceed the limit either.
    """
    limit = MAX_FILE_BYTES if limit is None else limit
    with _open_regular(path, what) as handle:
        size = os.fstat(handle.fileno()).st_size
        if size > limit:
            raise UserError(too_large(path, size, limit, what))
        try:
            data = handle.read(limit + 1)
        except OSError as exc:
            raise UserError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    if len(data) > limit:
        raise UserError(too_large(path, len(data), limit, what))
    return data


def read_head(path: Path, count: int, *, what: str = "a file") -> bytes:
    """The first ``count`` bytes of a regular file (fewer if it is shorter); UserError as :func:`read_bytes`."""
    with _open_regular(path, what) as handle:
        try:
            return handle.read(count)
        except OSError as exc:
            raise UserError(f"{path}: cannot read: {exc.strerror or exc}") from exc


def too_large(path: Path, size: int, limit: int, what: str) -> str:
    """The message for a file over its limit: its size and the limit in MB, and what it should be."""
    return (f"{path}: file is {size / 1e6:.0f} MB, larger than the {limit / 1024 / 1024:g} MB limit for "
            f"{_plural(what)}; is this really {what}?")


def _plural(what: str) -> str:
    if what == ROBOT_FILE:
        return "robot descriptions"
    noun = what.split(" ", 1)[1] if what.startswith(("a ", "an ")) else what
    if noun.endswith("s"):
        return noun
    return noun + ("es" if noun.endswith(("sh", "ch", "x")) else "s")


def _open_regular(path: Path, what: str):
    """An open binary handle on ``path``, checked to be a regular file (opened without blocking)."""
    try:
        descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
    except FileNotFoundError:
        raise UserError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise UserError(f"{path}: is a directory, expected {what}") from None
    except OSError as exc:
        raise UserError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    mode = os.fstat(descriptor).st_mode
    if not stat.S_ISREG(mode):
        os.close(descriptor)
        if stat.S_ISDIR(mode):
            raise UserError(f"{path}: is a directory, expected {what}")
        raise UserError(f"{path}: not a regular file (a pipe, socket or device); expected {what}")
    return os.fdopen(descriptor, "rb")
