"""Lint results remembered between runs: a file that has not changed is not checked again.

``pre-commit run --all-files``, a developer re-running a lint, or an editor linting on save
checks the same unchanged models again and again. Like ruff, ar3cli keeps each file's findings
and reuses them while nothing they depend on has changed:

* the file's path (absolute, with every symlink resolved, and as displayed), the selected rules and
  every option, the ``ROS_PACKAGE_PATH`` / ``AMENT_PREFIX_PATH`` environment, and ar3cli itself
  (version and the size and time of each of its source files), all hashed into the key: one
  entry per file;
* the file's bytes (a hash of them, checked on every hit);
* every path the package resolver looked at (meshes found or missing, ``package.xml`` files,
  package folders), with its state (times, size, mode, or absence) *when it was looked at*:
  checked again on every hit, so a mesh that is edited, appears or disappears, or a
  ``package.xml`` that now names a package, makes the result stale, even when the change happened
  while the file was being checked. The rules read no other file than these and the model itself.

Only static lints of ``.urdf`` files that loaded are remembered: xacro expansion reads includes
that ar3cli does not see, and ``--sim`` results depend on PyBullet. ``--no-cache`` or
``AR3CLI_NO_CACHE=1`` turn it off; the store is ``<cache dir>/lint-results-v1/`` (sharded by folder)
(:mod:`ar3cli.infra.file_cache`).
"""

from __future__ import annotations

import hashlib
import os
import sys
from collections.abc import Mapping
from pathlib import Path

from ar3cli import __version__
from ar3cli.findings import Finding, Severity
from ar3cli.infra.file_cache import MISSING, PathState, file_facts, path_state

MAX_RESULTS = 2_000
"""Remembered files: each shard of the store keeps its newest quarter of this (a folder's files share
a shard, see :mod:`ar3cli.infra.file_cache`). A run reads the shards of the folders it lints (0.5
to 2.5 kB a file)."""

_STORE = file_facts("lint-results", version=1, max_entries=MAX_RESULTS)
_PACKAGE_DIR = Path(__file__).resolve().parents[1]
"""The whole ar3cli package (every module of it may change a finding)."""
_ENVIRONMENT = ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH")


def code_fingerprint() -> str:
    """ar3cli's version plus the size and time of each of its source files: an edited rule (or
    a reinstall) makes every remembered result stale. (``os.scandir``: ``os.walk`` costs 10 ms.)"""
    parts = []
    folders = [str(_PACKAGE_DIR)]
    while folders:
        with os.scandir(folders.pop()) as entries:
            for entry in entries:
                if entry.name.endswith(".py"):
                    status = entry.stat()
                    parts.append(f"{entry.path}:{status.st_mtime_ns}:{status.st_size}")
                elif entry.name != "__pycache__" and entry.is_dir():
                    folders.append(entry.path)
    return "\n".join([__version__, sys.version, _lxml_version(), *sorted(parts)])


def _lxml_version() -> str:
    """lxml's version without importing lxml.etree (a fully cached run never parses XML)."""
    import lxml

    return str(getattr(lxml, "__version__", ""))


class ResultCache:
    """Remembered findings for one lint run's settings (rules, options, environment)."""

    @classmethod
    def for_settings(cls, rules: list[str], package_paths: Mapping[str, Path],
                     xacro_args: Mapping[str, str], targets: tuple[str, ...] = ()) -> ResultCache:
        """The cache for a run with these rule codes and options (package folders made absolute:
        a relative one means another folder from another working directory; the target engines set
        the severity of target-bound rules). What the configuration suppresses or re-grades is
        applied after the cache (``lint.engine.settle``), so it is no part of the key."""
        return cls(repr((list(rules), sorted(targets),
                         sorted((name, os.path.abspath(folder)) for name, folder in package_paths.items()),
                         sorted(xacro_args.items()))))

    def __init__(self, settings: str) -> None:
        """``settings``: everything about the run that can change a file's findings, as text."""
        context = [code_fingerprint(), settings, *(f"{name}={os.environ.get(name, '')}" for name in _ENVIRONMENT)]
        self._context = hashlib.sha256("\n".join(context).encode("utf-8", "surrogateescape")).digest()

    def _key(self, path: Path, shown: str) -> str:
        """One entry per file and settings: a new version of a file replaces the old one. The path
        absolute (normalised as text), with every symlink resolved, and as displayed:
        ``current/robot.urdf`` through a re-pointed ``current`` link, or ``link/../robot.urdf``,
        is another file."""
        digest = hashlib.sha256(self._context)
        for part in (os.path.abspath(path), os.path.realpath(path), shown):
            digest.update(part.encode("utf-8", "surrogateescape") + b"\0")
        return digest.hexdigest()

    def get(self, path: Path, shown: str) -> tuple[list[Finding], list[Finding], str] | None:
        """The findings remembered for this file, those its own comments suppress and the SHA-256
        of its bytes, or None when it must be checked."""
        entry = _STORE.lookup(self._key(path, shown), near=path)
        content = _read(path) if entry is not MISSING else None  # a file never seen is not read twice
        if content is None:
            return None
        try:
            if entry["content"] != hashlib.sha256(content).hexdigest():
                return None
            if any(_as_stored(path_state(dependency)) != state for dependency, state in entry["depends"].items()):
                return None
            return ([_finding(shown, *fields) for fields in entry["findings"]],
                    [_finding(shown, *fields) for fields in entry["suppressed"]], entry["content"])
        except (KeyError, TypeError, ValueError, AttributeError):  # none, or damaged: check the file
            return None

    def put(self, path: Path, shown: str, content: bytes, findings: list[Finding],
            depends: Mapping[str, PathState | None], suppressed: list[Finding] = ()) -> None:
        """Remember the findings of ``path`` as it was when read (``content``), those its own comments
        ``suppressed``, and the state of every path they depended on *when it was looked at* (a path
        that changes while the file is being checked then makes the entry stale at once)."""
        _STORE.store(self._key(path, shown), near=path, value={
            "content": hashlib.sha256(content).hexdigest(),
            "depends": {dependency: _as_stored(state) for dependency, state in depends.items()},
            "findings": [[f.rule, f.severity.value, f.message, f.line, f.column, f.hint] for f in findings],
            "suppressed": [[f.rule, f.severity.value, f.message, f.line, f.column, f.hint] for f in suppressed],
        })


def _as_stored(state: PathState | None) -> list[int] | None:
    """A state as JSON keeps it (a list)."""
    return list(state) if state is not None else None


def _finding(shown: str, rule, severity, message, line, column, hint) -> Finding:
    """A remembered finding, its fields checked (a damaged store must not crash the output)."""
    if not (isinstance(rule, str) and isinstance(message, str) and isinstance(hint, str)
            and type(line) is int and type(column) is int):
        raise TypeError("damaged entry")
    return Finding(rule, Severity(severity), message, shown, line, column, hint)


def _read(path: Path) -> bytes | None:
    """The file's bytes as the loader would read them (same size limit), or None."""
    from ar3cli.errors import UserError
    from ar3cli.infra.safe_read import read_bytes

    try:
        return read_bytes(path)
    except UserError:
        return None
