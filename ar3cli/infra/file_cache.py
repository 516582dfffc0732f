"""A small on-disk cache of facts about files that are slow to compute (mesh bounding boxes).

A pre-commit hook or a CI step lints the same meshes again and again; reading 50 MB of OBJ and
STL text takes longer than all the rules together. Facts are keyed by the file's absolute path
(not resolved through symlinks: realpath costs more than the lookup it serves), modification and
status-change times (ns) and size, so an edited mesh is read again. The cache is one JSON file per
kind of fact, written atomically at exit and only when something new was learnt, merged under a
lock with what other ar3cli processes saved meanwhile (pre-commit runs several at once); a corrupt
or unreadable cache is ignored (and rebuilt). ``AR3CLI_NO_CACHE=1`` turns it off;
``AR3CLI_CACHE_DIR`` moves it (default ``$XDG_CACHE_HOME/ar3cli`` or ``~/.cache/ar3cli``).

A forked worker process (:mod:`ar3cli.infra.process_pool`) never saves: it hands what it learnt to its
parent (:func:`take_learned`), which merges it (:func:`merge_learned`) and saves once.
"""

from __future__ import annotations

import atexit
import contextlib
import json
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

MAX_ENTRIES = 20_000
"""Beyond this many entries the least recently stored are dropped when saving (the cache stays small)."""

MISSING = object()

PathState = tuple[int, int, int, int]
"""What a path looks like now: (modification time, status-change time (ns), size, mode). The
status-change time moves on every write, chmod or rename and cannot be set back (``touch -r``
can restore a modification time, not this)."""


def path_state(path: str) -> PathState | None:
    """The state of ``path`` (symlinks followed), or None when nothing is there."""
    try:
        status = os.stat(path)
    except (OSError, ValueError):
        return None
    return status.st_mtime_ns, status.st_ctime_ns, status.st_size, status.st_mode


_OPEN: dict[str, FileFacts] = {}
"""This process's caches by name, for handing what a worker learnt to its parent."""


def cache_dir() -> Path | None:
    """Where caches live, or None when caching is turned off."""
    if os.environ.get("AR3CLI_NO_CACHE"):
        return None
    if os.environ.get("AR3CLI_CACHE_DIR"):
        return Path(os.environ["AR3CLI_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "ar3cli"


class FileFacts:
    """Facts (JSON values) about files, persisted in ``<cache dir>/<name>-v<version>.json``.

    Keys are built from a file's path and stat (:meth:`get` / :meth:`put`) or given whole by the
    caller (:meth:`lookup` / :meth:`store`). At most ``max_entries`` are kept.
    """

    def __init__(self, name: str, version: int, max_entries: int = MAX_ENTRIES) -> None:
        self.name = name
        self.version = version
        self.max_entries = max_entries
        self._entries: dict[str, Any] | None = None
        self._dirty = False
        self._changed: dict[str, Any] = {}
        """Entries stored or merged by this process: what :meth:`save` writes."""
        self._learned: dict[str, Any] = {}
        """Entries stored since :func:`take_learned` last asked (a worker's answer to its parent)."""
        _OPEN[name] = self

    def _key(self, path: Path, status: os.stat_result) -> str:
        return f"{os.path.abspath(path)}|{status.st_mtime_ns}|{status.st_ctime_ns}|{status.st_size}"

    def _file(self) -> Path | None:
        folder = cache_dir()
        return folder / f"{self.name}-v{self.version}.json" if folder else None

    def _load(self) -> dict[str, Any]:
        if self._entries is None:
            location = self._file()
            self._entries = _read_entries(location) if location is not None else {}
        return self._entries

    def get(self, path: Path, status: os.stat_result) -> Any:
        """The stored fact for this version of ``path``, or :data:`MISSING`."""
        return self.lookup(self._key(path, status))

    def put(self, path: Path, status: os.stat_result, value: Any) -> None:
        """Remember ``value`` (JSON-serialisable) for this version of ``path``; saved at exit."""
        self.store(self._key(path, status), value)

    def lookup(self, key: str) -> Any:
        """The value stored under ``key``, or :data:`MISSING`."""
        return self._load().get(key, MISSING)

    def store(self, key: str, value: Any) -> None:
        """Remember ``value`` (JSON-serialisable) under ``key``; saved at exit."""
        self._learned[key] = value
        self._merge({key: value})

    def _merge(self, entries: dict[str, Any]) -> None:
        loaded = self._load()
        for key, value in entries.items():
            loaded.pop(key, None)  # stored again: it moves to the end, the newest
            loaded[key] = value
        self._changed.update(entries)
        if not self._dirty and self._file() is not None:
            atexit.register(self.save)
        self._dirty = True

    def save(self) -> None:
        """Write what this process stored into the cache file, atomically and under a lock, on top
        of what is there now (other processes may have saved since this one read it); only the
        newest :attr:`max_entries` are kept. Failures are silent (a cache is optional)."""
        location = self._file()
        if not self._dirty or location is None:
            return
        try:
            from ar3cli.infra.atomic import atomic_write

            location.parent.mkdir(parents=True, exist_ok=True)
            with _locked(location.with_name(location.name + ".lock")):
                entries = _read_entries(location)
                for key, value in self._changed.items():
                    entries.pop(key, None)
                    entries[key] = value
                if len(entries) > self.max_entries:
                    entries = dict(list(entries.items())[-self.max_entries:])
                atomic_write(location, json.dumps(entries, separators=(",", ":")).encode("utf-8"))
            self._dirty = False
        except Exception:  # noqa: BLE001 - a read-only home must never break a lint
            pass


def _read_entries(location: Path) -> dict[str, Any]:
    """The cache file's entries; {} when there is none, or a damaged one (junk, JSON nested
    thousands deep, a pipe in its place: read like a robot file, regular files only)."""
    from ar3cli.errors import UserError
    from ar3cli.infra.safe_read import read_bytes

    try:
        loaded = json.loads(read_bytes(location))
    except (UserError, ValueError, RecursionError):
        return {}
    return loaded if isinstance(loaded, dict) else {}


@contextlib.contextmanager
def _locked(lock_path: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``lock_path`` (POSIX ``flock``; elsewhere no lock)."""
    try:
        import fcntl
    except ImportError:  # Windows: concurrent saves may drop each other's new entries
        yield
        return
    with open(lock_path, "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def file_facts(name: str, version: int, max_entries: int = MAX_ENTRIES) -> FileFacts:
    """This process's cache ``name`` (created on first use): one object per cache, however it is
    reached (a module that owns it, or facts handed over by a worker before that module loaded)."""
    existing = _OPEN.get(name)
    if existing is not None and existing.version == version:
        return existing
    return FileFacts(name, version, max_entries)


def load_all() -> None:
    """Read every cache this process has opened now, before forking workers: the children then
    share the entries (copy-on-write) instead of each parsing the same files again."""
    for facts in _OPEN.values():
        facts._load()


def take_learned() -> dict[str, dict[str, Any]]:
    """What this process's caches learnt since the last call (a worker's gift to its parent)."""
    learned = {name: {"version": facts.version, "max_entries": facts.max_entries, "entries": facts._learned}
               for name, facts in _OPEN.items() if facts._learned}
    for facts in _OPEN.values():
        facts._learned = {}
    return learned


def merge_learned(learned: dict[str, dict[str, Any]]) -> None:
    """Add what a worker learnt (:func:`take_learned`) to this process's caches, saved at exit."""
    for name, gift in learned.items():
        file_facts(name, gift["version"], gift["max_entries"])._merge(gift["entries"])
