"""A small on-disk cache of facts about files that are slow to compute (mesh bounding boxes).

A pre-commit hook or a CI step lints the same meshes again and again; reading 50 MB of OBJ and
STL text takes longer than all the rules together. Facts are keyed by the file's absolute path
(not resolved through symlinks: realpath costs more than the lookup it serves), modification and
status-change times (ns) and size, so an edited mesh is read again; within a process also by the
file's identity (device and inode, :func:`identity`), so a file reached by many paths is read once
(120 paths to one 20 MB OBJ through two links to ``.`` were 120 reads). Each kind of fact is a folder
of :data:`SHARDS` JSON files, a folder's facts all in one (a run reads only the ones it needs),
written atomically at exit and only when something new was learnt, merged under a lock with what
other ar3cli processes saved meanwhile (pre-commit runs several at once); a corrupt or unreadable
file is ignored (and rebuilt). ``AR3CLI_NO_CACHE=1`` turns it off;
``AR3CLI_CACHE_DIR`` moves it (default ``$XDG_CACHE_HOME/ar3cli`` or ``~/.cache/ar3cli``).

A forked worker process (:mod:`ar3cli.infra.process_pool`) never saves: it hands what it learnt to its
parent (:func:`take_learned`), which merges it (:func:`merge_learned`) and saves once.
"""

from __future__ import annotations

import atexit
import contextlib
import json
import os
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

MAX_ENTRIES = 20_000
"""A cache's size: each of its :data:`SHARDS` files keeps its newest ``MAX_ENTRIES / 4`` entries."""

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


def identity(status: os.stat_result) -> tuple[int, ...]:
    """A file version's identity, whatever path names it: device, inode, size, modification and
    status-change times (ns). Two paths with the same identity are the same bytes."""
    return status.st_dev, status.st_ino, status.st_size, status.st_mtime_ns, status.st_ctime_ns


_OPEN: dict[str, FileFacts] = {}
"""This process's caches by name, for handing what a worker learnt to its parent."""

COMMON_SHARD = "common"
"""The shard of entries stored without a path to place them by."""
SHARDS = 64
"""Shard files per cache at most: a folder's entries all go to one of them (by a checksum of its
path), so a run that lints one robot parses about 1/64 of the cache, and a cold lint of a large
tree (pybullet_data's 1,000 random_urdfs folders) writes 64 files, not one per folder."""


def cache_dir() -> Path | None:
    """Where caches live, or None when caching is turned off."""
    if os.environ.get("AR3CLI_NO_CACHE"):
        return None
    if os.environ.get("AR3CLI_CACHE_DIR"):
        return Path(os.environ["AR3CLI_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "ar3cli"


def shard_of(near: str | os.PathLike[str] | None) -> str:
    """The shard holding entries about ``near``: the same for every file of a folder (a robot's
    meshes sit together), one of :data:`SHARDS`; :data:`COMMON_SHARD` without a path."""
    if near is None:
        return COMMON_SHARD
    return _placed(os.fspath(near))[1]


def _placed(path: str) -> tuple[str, str]:
    """(absolute path, shard) of ``path``; remembered for absolute paths, which a bulk lint asks
    about again and again (pybullet_data's 95 robots: 1,800 mesh lookups of 200 meshes, each
    computing both twice took a tenth of a cached lint)."""
    if not os.path.isabs(path):  # depends on the current folder: not remembered
        return _place(path)
    found = _PLACED.get(path)
    if found is None:
        if len(_PLACED) >= MAX_ENTRIES:
            _PLACED.clear()
        found = _PLACED[path] = _place(path)
    return found


def _place(path: str) -> tuple[str, str]:
    absolute = os.path.abspath(path)
    folder = os.path.dirname(absolute)
    # a checksum, not a secure hash (hashlib costs an import): folders sharing a shard only share a file
    return absolute, f"{zlib.crc32(folder.encode('utf-8', 'surrogateescape')) % SHARDS:02x}"


_PLACED: dict[str, tuple[str, str]] = {}


class FileFacts:
    """Facts (JSON values) about files, persisted in ``<cache dir>/<name>-v<version>/<shard>.json``.

    Keys are built from a file's path and stat (:meth:`get` / :meth:`put`) or given whole by the
    caller (:meth:`lookup` / :meth:`store`, placed by the file they are about: ``near``). Entries
    are kept in :data:`SHARDS` files, all of a folder's in one, and a run reads only the shards of
    the folders it asks about: with one store file, every run parsed every entry ever saved (4,400
    mesh boxes, 0.9 MB: 12 ms of each lint). At most ``max_entries`` / 4 are kept per shard (a
    folder's entries share one), so about ``16 * max_entries`` in all.
    """

    def __init__(self, name: str, version: int, max_entries: int = MAX_ENTRIES) -> None:
        self.name = name
        self.version = version
        self.max_entries = max_entries
        self._shards: dict[str, dict[str, Any]] = {}
        self._changed: dict[str, dict[str, Any]] = {}
        """Entries stored or merged by this process, by shard: what :meth:`save` writes."""
        self._learned: dict[str, dict[str, Any]] = {}
        """Entries stored since :func:`take_learned` last asked (a worker's answer to its parent)."""
        self._saving = False
        self._by_identity: dict[tuple[int, ...], Any] = {}
        """This process's facts by file identity, whatever path reached the file."""
        _OPEN[name] = self

    @staticmethod
    def _key(absolute: str, status: os.stat_result) -> str:
        return f"{absolute}|{status.st_mtime_ns}|{status.st_ctime_ns}|{status.st_size}"

    def _folder(self) -> Path | None:
        folder = cache_dir()
        return folder / f"{self.name}-v{self.version}" if folder else None

    def _load(self, shard: str) -> dict[str, Any]:
        entries = self._shards.get(shard)
        if entries is None:
            folder = self._folder()
            entries = self._shards[shard] = _read_entries(folder / f"{shard}.json") if folder is not None else {}
        return entries

    def get(self, path: Path, status: os.stat_result) -> Any:
        """The stored fact for this version of ``path``, or :data:`MISSING`. Within a process, a
        file reached by several paths (``a/m.obj``, ``a/b/a/m.obj`` through links to ``.``) is one
        file: the fact learnt through one path answers for all (:func:`identity`)."""
        known = self._by_identity.get(identity(status), MISSING)
        if known is not MISSING:
            return known
        absolute, shard = _placed(os.fspath(path))
        return self._load(shard).get(self._key(absolute, status), MISSING)

    def put(self, path: Path, status: os.stat_result, value: Any) -> None:
        """Remember ``value`` (JSON-serialisable) for this version of ``path``; saved at exit."""
        absolute, _ = _placed(os.fspath(path))
        if len(self._by_identity) >= self.max_entries:
            self._by_identity.clear()
        self._by_identity[identity(status)] = value
        self.store(self._key(absolute, status), value, near=path)

    def lookup(self, key: str, near: str | os.PathLike[str] | None = None) -> Any:
        """The value stored under ``key`` (in the shard of ``near``), or :data:`MISSING`."""
        return self._load(shard_of(near)).get(key, MISSING)

    def store(self, key: str, value: Any, near: str | os.PathLike[str] | None = None) -> None:
        """Remember ``value`` (JSON-serialisable) under ``key``, in the shard of ``near``; saved at exit."""
        shard = shard_of(near)
        self._learned.setdefault(shard, {})[key] = value
        self._merge(shard, {key: value})

    def _merge(self, shard: str, entries: dict[str, Any]) -> None:
        loaded = self._load(shard)
        for key, value in entries.items():
            loaded.pop(key, None)  # stored again: it moves to the end, the newest
            loaded[key] = value
        self._changed.setdefault(shard, {}).update(entries)
        if not self._saving and self._folder() is not None:
            atexit.register(self.save)
            self._saving = True

    def save(self) -> None:
        """Write what this process stored into its shard files, atomically (not fsynced: a cache)
        and under a lock, on top of what is there now (other processes may have saved since this
        one read them); only the newest entries of a shard are kept (see the class). Failures are
        silent (a cache is optional)."""
        folder = self._folder()
        if not self._changed or folder is None:
            return
        try:
            from ar3cli.infra.atomic import atomic_write

            folder.mkdir(parents=True, exist_ok=True)
            with _locked(folder / ".lock"):
                for shard, changed in self._changed.items():
                    location = folder / f"{shard}.json"
                    entries = _read_entries(location)
                    for key, value in changed.items():
                        entries.pop(key, None)
                        entries[key] = value
                    keep = max(1, self.max_entries // 4)
                    if len(entries) > keep:
                        entries = dict(list(entries.items())[-keep:])
                    atomic_write(location, json.dumps(entries, separators=(",", ":")).encode("utf-8"), durable=False)
            self._changed = {}
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


def take_learned() -> dict[str, dict[str, Any]]:
    """What this process's caches learnt since the last call (a worker's gift to its parent)."""
    learned = {name: {"version": facts.version, "max_entries": facts.max_entries, "shards": facts._learned}
               for name, facts in _OPEN.items() if facts._learned}
    for facts in _OPEN.values():
        facts._learned = {}
    return learned


def merge_learned(learned: dict[str, dict[str, Any]]) -> None:
    """Add what a worker learnt (:func:`take_learned`) to this process's caches, saved at exit."""
    for name, gift in learned.items():
        facts = file_facts(name, gift["version"], gift["max_entries"])
        for shard, entries in gift["shards"].items():
            facts._merge(shard, entries)
