"""Atomic, link-safe file writes: a reader, a crash or a kill never sees half a file, and a link
planted where ar3cli writes never redirects the write.

:func:`atomic_write` writes a temporary file in the target's folder (named
``.<name>.ar3cli-tmp-<pid>-XXXX``: recognisable, and owned by a process one can ask about), fsyncs
it, gives it the original's mode bits (and owner and group where the caller may), and renames it
over the target: at any moment the target is either the old file or the new one, never a mix.
Every file ar3cli writes (fixed URDFs, part meshes, SRDFs, pictures, GIFs, baselines, the cache)
goes through it.

Links: ar3cli lints strangers' pull requests, so an output path (``-o robot.png``) may be a
symlink the pull request planted (``robot.png -> ~/.bashrc``). :func:`check_writable` refuses a
path whose last component is a symlink unless the caller passes ``follow_symlinks`` (the
``--follow-symlinks`` option); then the link's target is written, atomically, in the target's own
folder. The rename itself never follows a link (it replaces the name), so a link planted after
the check cannot redirect the write either. Folders higher up are the user's choice and are
followed (``/tmp`` is a link on some systems).

Stale temporary files: a run killed by ``kill -9`` runs no cleanup, so its temporary file stays.
The first write of a process in a folder removes the temporary files there whose owning pid is no
longer running (or that are older than :data:`STALE_AGE`, whatever their pid says); a live run's
file is never touched.
"""

from __future__ import annotations

import contextlib
import os
import re
import stat
import tempfile
import time
from pathlib import Path

from ar3cli.errors import UserError
from ar3cli.infra.safe_read import kind_of

TEMP_MARKER = ".ar3cli-tmp-"
"""Part of every temporary file name written by :func:`atomic_write`."""

STALE_AGE = 24 * 3600.0
"""Seconds after which a temporary file is stale even if a process with its pid is running (the
pid was reused, or the file came from another machine sharing the folder). A write takes
milliseconds to minutes (fix-collision verifies in PyBullet before the rename), never a day."""

SLOW_WRITE_ENV = "AR3CLI_TEST_SLOW_WRITE"
"""For tests only: seconds to sleep between chunks of the temporary file, so a test can kill
the process mid-write and check that the target is intact."""

FOLLOW_HINT = "--follow-symlinks"
"""The option that allows writing through a link, named in the refusal."""

_PID = re.compile(re.escape(TEMP_MARKER) + r"(\d+)-")
_cleaned: set[str] = set()
"""Folders this process has already swept for stale temporary files (one sweep per folder)."""


def check_writable(path: Path, follow_symlinks: bool = False) -> Path:
    """The file to write for ``path`` if ar3cli may replace it; UserError otherwise.

    A symlink as the last component is refused unless ``follow_symlinks`` (then its target is the
    file to write). An existing file the caller may not write (``os.access``) is refused even when
    its folder would allow the rename, and so is one with no write bit at all (root may write
    anything, but the bits say the owner wants it left alone). Callers that write several files
    check them all first, so a run writes all or nothing.
    """
    path = Path(path)
    try:
        is_link = stat.S_ISLNK(os.lstat(path).st_mode)
    except FileNotFoundError:
        is_link = False
    except OSError as exc:  # ENAMETOOLONG, ELOOP, EACCES on a folder above: one line, not a traceback
        raise UserError(f"{path}: cannot write: {exc.strerror or exc}") from None
    if is_link:
        target = os.path.realpath(path)
        if not follow_symlinks:
            raise UserError(f"{path}: is a symbolic link (to {target}); refusing to write through it: "
                            f"remove it, or give {FOLLOW_HINT} to write {target}")
        path = Path(target)
    else:
        path = Path(os.path.join(os.path.realpath(path.parent), path.name))
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as exc:
        raise UserError(f"{path}: cannot write: {exc.strerror or exc}") from None
    if mode is not None and stat.S_ISDIR(mode):
        raise UserError(f"{path}: is a directory; give a file name")
    if mode is not None and not stat.S_ISREG(mode):
        raise UserError(f"{path}: exists and is not a regular file ({kind_of(mode)}); refusing to replace it: "
                        "give the name of a file")
    if not path.parent.is_dir():
        raise UserError(f"{path}: folder {path.parent} does not exist")
    if mode is not None and (not os.access(path, os.W_OK) or not mode & 0o222):
        # a rename would replace it anyway (it needs only a writable folder): respect the intent
        raise UserError(f"{path}: is read-only for you; make it writable first (chmod u+w) if it should change")
    return path


def atomic_write(path: Path, data: bytes, validate=None, durable: bool = True, *, follow_symlinks: bool = False,
                 expect: bytes | None = None) -> None:
    """Replace ``path`` with ``data`` atomically; ``validate(temp_path)`` may raise to abort.

    The temporary file lives in the same folder (so the rename is atomic on one filesystem),
    is fsynced before the rename (and the folder after it) unless not ``durable`` (a cache: losing
    the newest entries in a power cut costs only time, and a cold lint writes a file per shard),
    and gets the original's mode bits, owner and group (owner and group only where the caller may
    set them). ``expect``: the bytes the caller read and edited; when the file holds something
    else just before the rename (someone saved it meanwhile), nothing is replaced and the error
    says "changed while fixing, run again". On any failure the temporary file is removed and the
    original is untouched; an OS error becomes a one-line :class:`UserError`. Links: see
    :func:`check_writable`.
    """
    path = check_writable(path, follow_symlinks)
    directory = path.parent
    remove_stale_temps(directory)
    try:
        old = path.stat()
    except FileNotFoundError:
        old = None
    if old is not None:
        mode = old.st_mode & 0o7777
    else:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    try:
        handle, temp_name = tempfile.mkstemp(prefix=f".{path.name}{TEMP_MARKER}{os.getpid()}-", dir=directory)
    except OSError as exc:
        raise UserError(f"{path}: cannot write in {directory}: {exc.strerror or exc}") from None
    temp = Path(temp_name)
    try:
        with os.fdopen(handle, "wb") as stream:
            _write_chunks(stream, data)
            stream.flush()
            if durable:
                os.fsync(stream.fileno())
        if old is not None:
            _keep_owner(temp, old)
        os.chmod(temp, mode)
        if validate is not None:
            validate(temp)
        if expect is not None:
            _refuse_if_changed(path, expect)
        os.replace(temp, path)
    except OSError as exc:
        temp.unlink(missing_ok=True)
        raise UserError(f"{path}: cannot write: {exc.strerror or exc}") from None
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
    if durable:
        _fsync_directory(directory)


def _keep_owner(temp: Path, old: os.stat_result) -> None:
    """Give the temporary file the original's owner and group where permitted (root may; a user
    may set a group they belong to); otherwise it stays the caller's, as any editor would leave it."""
    mine = temp.stat()
    if (mine.st_uid, mine.st_gid) == (old.st_uid, old.st_gid):
        return
    try:
        os.chown(temp, old.st_uid, old.st_gid)
    except OSError:
        with contextlib.suppress(OSError):
            os.chown(temp, -1, old.st_gid)


def _refuse_if_changed(path: Path, expect: bytes) -> None:
    """UserError when ``path`` no longer holds ``expect`` (read without following a link)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        current = None
    else:
        with os.fdopen(fd, "rb") as stream:
            if not stat.S_ISREG(os.fstat(stream.fileno()).st_mode):
                current = None
            else:
                current = stream.read(len(expect) + 1)
    if current != expect:
        raise UserError(f"{path}: changed while fixing, run again (nothing was written)")


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


def temp_files(directory: Path) -> list[Path]:
    """Every temporary file of :func:`atomic_write` in ``directory`` (links and folders left out)."""
    try:
        return sorted(p for p in Path(directory).glob(f".*{TEMP_MARKER}*") if p.is_file() and not p.is_symlink())
    except OSError:
        return []


def stale_temps(directory: Path, now: float | None = None) -> list[Path]:
    """Temporary files in ``directory`` left by a run that is gone: the pid in the name is not
    running, or the file is older than :data:`STALE_AGE` (a name without a pid, from an older
    ar3cli, counts by age alone)."""
    now = time.time() if now is None else now
    stale = []
    for temp in temp_files(directory):
        match = _PID.search(temp.name)
        try:
            age = now - temp.lstat().st_mtime
        except OSError:
            continue
        if age > STALE_AGE or (match is not None and not _running(int(match.group(1)))):
            stale.append(temp)
    return stale


def remove_stale_temps(directory: Path) -> list[Path]:
    """Delete :func:`stale_temps` of ``directory``, once per folder and process; the files removed.
    Failures are ignored (a file someone else owns in a shared folder is theirs to remove)."""
    key = os.path.realpath(directory)
    if key in _cleaned:
        return []
    _cleaned.add(key)
    removed = []
    for temp in stale_temps(directory):
        try:
            temp.unlink()
        except OSError:
            continue
        removed.append(temp)
    return removed


def _running(pid: int) -> bool:
    """True when a process ``pid`` exists (ours or another user's)."""
    if pid <= 0:
        return True  # not a pid we wrote: leave it to the age rule
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, OSError):
        return True
    return True
