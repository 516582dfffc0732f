"""The scan store: one SQLite file, one row per scanned file, written as results arrive.

Only the driver (the process running ``ar3cli scan``) writes: workers, local or on a Ray cluster,
send their rows back to it, so SQLite's single writer is never contended. The journal is WAL
(readers such as ``scan-report`` never block the writer) and rows are committed in small batches,
each one transaction: a scan killed at any moment (SIGKILL, power cut) leaves every committed row
whole and loses at most the batch in flight, which the next run checks again. ``path`` is the
primary key, so a file is never stored twice; a changed file replaces its row.
"""

from __future__ import annotations

import json
import os
import sqlite3
import stat
from collections.abc import Iterable, Iterator
from pathlib import Path

from ar3cli.errors import UserError
from ar3cli.infra.atomic import check_writable
from ar3cli.scan.record import LOADED, Row, status_of

SCHEMA_VERSION = 1
_COLUMNS = ("path", "sha256", "settings", "status", "findings", "message", "dof", "mass", "links", "joints",
            "load_seconds", "check_seconds", "errors", "warnings", "infos", "scanned_at")
_SCHEMA = """
CREATE TABLE IF NOT EXISTS files (
    path TEXT PRIMARY KEY,      -- absolute path of the robot file
    sha256 TEXT NOT NULL,       -- of the bytes that were checked
    settings TEXT NOT NULL,     -- what was checked (rules, --sim, ar3cli version): other settings rescan
    status TEXT NOT NULL,       -- clean | findings | error | crash | timeout
    findings TEXT NOT NULL,     -- JSON list of findings
    message TEXT NOT NULL,      -- why the check did not finish, else ''
    dof INTEGER, mass REAL, links INTEGER, joints INTEGER,
    load_seconds REAL, check_seconds REAL,
    errors INTEGER NOT NULL, warnings INTEGER NOT NULL, infos INTEGER NOT NULL,
    scanned_at REAL NOT NULL    -- unix time the row was written
);
CREATE INDEX IF NOT EXISTS files_status ON files(status);
"""


def storable(text: str) -> str:
    """``text`` as the store keeps it: a file name that is not UTF-8 (Python holds its bytes as lone
    surrogates, which SQLite cannot take) with those bytes written ``\\xff``, as ar3cli shows them;
    every other text as it is."""
    try:
        text.encode("utf-8")
        return text
    except UnicodeEncodeError:
        pass
    try:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    except UnicodeEncodeError:  # a surrogate that is no file-name byte
        return text.encode("utf-8", "backslashreplace").decode("utf-8")


SIDE_FILES = ("-wal", "-shm", "-journal")
"""The files SQLite keeps beside the store (write-ahead log, its index, the rollback journal)."""


def _check_writable(path: Path) -> None:
    """The safe-write rules for a store SQLite writes in place (:mod:`ar3cli.infra.atomic`): the store
    and the files SQLite keeps beside it may not be symbolic links (a link planted as
    ``scan.sqlite-wal`` would have SQLite write through it), FIFOs, devices or read-only files;
    UserError (exit 2) before anything is opened. An existing store keeps its mode, owner and group
    (SQLite writes into it)."""
    check_writable(path)
    for suffix in SIDE_FILES:
        side = Path(f"{path}{suffix}")
        try:
            mode = os.lstat(side).st_mode
        except FileNotFoundError:
            continue
        except OSError as exc:
            raise UserError(f"{side}: cannot write: {exc.strerror or exc}") from None
        if stat.S_ISLNK(mode) or not stat.S_ISREG(mode):
            raise UserError(f"{side}: SQLite's {suffix[1:]} file of the store is not a regular file (a symbolic link, "
                            "FIFO or device); refusing to write through it: remove it")


class Store:
    """An open scan store; use as a context manager. ``readonly`` opens an existing store for a report."""

    def __init__(self, path: Path, readonly: bool = False) -> None:
        self.path = Path(path)
        if readonly and not self.path.is_file():
            raise UserError(f"{path}: no such scan store (make one with 'ar3cli scan ROOT --store {path}')")
        try:
            if readonly:
                self.db = sqlite3.connect(f"{self.path.resolve().as_uri()}?mode=ro", uri=True)
            else:
                _check_writable(self.path)
                self.db = sqlite3.connect(self.path, timeout=30)
                self.db.execute("PRAGMA journal_mode=WAL")
                self.db.execute("PRAGMA synchronous=NORMAL")  # WAL: a commit survives a killed process
                self.db.executescript(_SCHEMA)
                self.db.execute(f"PRAGMA user_version={SCHEMA_VERSION}")
            self.db.execute("SELECT count(*) FROM files").fetchone()
        except sqlite3.DatabaseError as exc:
            raise UserError(f"{path}: not a scan store ({exc})") from None

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def close(self) -> None:
        self.db.close()

    def known(self) -> dict[str, tuple[str, str]]:
        """Every stored path -> (sha256, settings): what a resumed scan need not check again."""
        return {path: (sha, settings) for path, sha, settings in self.db.execute("SELECT path, sha256, settings FROM files")}

    def put(self, rows: Iterable[Row], now: float) -> int:
        """Write ``rows`` in one transaction (all or none); a row replaces the one with its path."""
        values = [(storable(row.path), row.sha256, row.settings, row.status, row.findings_json(), storable(row.message),
                   row.dof,
                   row.mass, row.links, row.joints, row.load_seconds, row.check_seconds,
                   *(row.counts()[level] for level in ("error", "warning", "info")), now) for row in rows]
        marks = ", ".join("?" * len(_COLUMNS))
        with self.db:
            self.db.executemany(f"INSERT OR REPLACE INTO files ({', '.join(_COLUMNS)}) VALUES ({marks})", values)
        return len(values)

    def rows(self) -> Iterator[Row]:
        """Every stored row, by path."""
        query = f"SELECT {', '.join(_COLUMNS[:12])} FROM files ORDER BY path"
        try:
            for record in self.db.execute(query):
                row = Row(*record[:4], json.loads(record[4]), *record[5:])  # type: ignore[arg-type]
                if row.status in LOADED:  # a store written when "clean" meant no finding at all reads as today
                    row.status = status_of(True, row.findings, None)
                yield row
        except sqlite3.DatabaseError as exc:
            raise UserError(f"{self.path}: cannot read the scan store ({exc})") from None

    def count(self) -> int:
        return self.db.execute("SELECT count(*) FROM files").fetchone()[0]
