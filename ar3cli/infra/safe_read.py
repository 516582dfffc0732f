"""Read a file that may be anything a user passes (a FIFO, a device, a huge file) without hanging.

Robot files and the on-disk caches are read through :func:`read_bytes`: opened without blocking,
checked on the open descriptor, size-capped; every problem is a one-line UserError.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from ar3cli.errors import UserError

MAX_FILE_BYTES = 50 * 1024 * 1024
"""Files larger than this are refused: no real URDF comes close (the largest in pybullet_data is ~1 MB)."""


def read_bytes(path: Path) -> bytes:
    """Return the file's bytes, or raise a one-line :class:`UserError` saying why not.

    The file is opened without blocking and checked on the open descriptor: a FIFO or a terminal
    (which would wait forever) is refused even if it replaced a regular file a moment ago.
    """
    if not path.exists():
        raise UserError(f"{path}: no such file")
    if path.is_dir():
        raise UserError(f"{path}: is a directory, expected a .urdf or .xacro file")
    try:
        descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise UserError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    with os.fdopen(descriptor, "rb") as handle:
        status = os.fstat(descriptor)
        if not stat.S_ISREG(status.st_mode):
            raise UserError(f"{path}: not a regular file (a pipe, socket or device); expected a .urdf or .xacro file")
        if status.st_size > MAX_FILE_BYTES:
            raise UserError(
                f"{path}: file is {status.st_size / 1e6:.0f} MB, larger than the {MAX_FILE_BYTES // 1024 // 1024} MB "
                "limit for robot descriptions; is this really a URDF?"
            )
        try:
            return handle.read()
        except OSError as exc:
            raise UserError(f"{path}: cannot read: {exc.strerror or exc}") from exc


