"""Atomic file writes: a reader, a crash or a kill never sees half a file.

:func:`atomic_write` writes a temporary file in the target's folder (named
``.<name>.ar3cli-tmp-XXXX`` so a stray one is recognisable), fsyncs it, copies the original's
mode bits and renames it over the target: at any moment the target is either the old file or the
new one, never a mix. Every file ar3cli writes (fixed URDFs, SRDFs, pictures, GIFs) goes through it.
"""

from __future__ import annotations

import os
import stat
import tempfile
import time
from pathlib import Path

from ar3cli.errors import UserError

TEMP_MARKER = ".ar3cli-tmp-"
"""Part of every temporary file name written by :func:`atomic_write`."""

SLOW_WRITE_ENV = "AR3CLI_TEST_SLOW_WRITE"
"""For tests only: seconds to sleep between chunks of the temporary file, so a test can kill
the process mid-write and check that the target is intact."""


def check_writable(path: Path) -> Path:
    """The real target (symlinks followed) if ar3cli may replace it; UserError otherwise.

    Callers that write several files check them all first, so a run writes all or nothing.
    """
    path = Path(os.path.realpath(path))
    if path.is_dir():
        raise UserError(f"{path}: is a directory; give a file name")
    if not path.parent.is_dir():
        raise UserError(f"{path}: folder {path.parent} does not exist")
    if path.exists() and not path.stat().st_mode & stat.S_IWUSR:
        # a rename would replace it anyway (it needs only a writable folder): respect the intent
        raise UserError(f"{path}: is read-only; make it writable first (chmod u+w) if it should change")
    return path


def atomic_write(path: Path, data: bytes, validate=None, durable: bool = True) -> None:
    """Replace ``path`` with ``data`` atomically; ``validate(temp_path)`` may raise to abort.

    The temporary file lives in the same folder (so the rename is atomic on one filesystem),
    is fsynced before the rename (and the folder after it) unless not ``durable`` (a cache: losing
    the newest entries in a power cut costs only time, and a cold lint writes a file per shard),
    and gets the original's mode bits. On any failure it is
    removed and the original is untouched; an OS error becomes a one-line :class:`UserError`.
    A symlink is written through (its target changes, the link stays a link).
    """
    path = check_writable(path)
    directory = path.parent
    try:
        mode = path.stat().st_mode & 0o7777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    try:
        handle, temp_name = tempfile.mkstemp(prefix=f".{path.name}{TEMP_MARKER}", dir=directory)
    except OSError as exc:
        raise UserError(f"{path}: cannot write in {directory}: {exc.strerror or exc}") from None
    temp = Path(temp_name)
    try:
        with os.fdopen(handle, "wb") as stream:
            _write_chunks(stream, data)
            stream.flush()
            if durable:
                os.fsync(stream.fileno())
        os.chmod(temp, mode)
        if validate is not None:
            validate(temp)
        os.replace(temp, path)
    except OSError as exc:
        temp.unlink(missing_ok=True)
        raise UserError(f"{path}: cannot write: {exc.strerror or exc}") from None
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
    if durable:
        _fsync_directory(directory)


def _write_chunks(stream, data: bytes) -> None:
    delay = float(os.environ.get(SLOW_WRITE_ENV, "0") or 0)
    if delay <= 0:
        stream.write(data)
        return
    chunk = max(1, len(data) // 10)
    for start in range(0, len(data), chunk):
        stream.write(data[start:start + chunk])
        stream.flush()
        time.sleep(delay)


def _fsync_directory(directory: Path) -> None:
    """Make the rename itself durable (best effort; not every platform allows it)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def stale_temps(directory: Path) -> list[Path]:
    """Leftover temporary files of a killed run in ``directory`` (safe to delete)."""
    return sorted(p for p in Path(directory).glob(f".*{TEMP_MARKER}*") if p.is_file())
