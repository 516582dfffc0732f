"""The scan driver: decide what to check, hand it to a backend, store the rows as they arrive.

The driver is the store's only writer. It hashes every file, skips those whose row has the same
hash and settings (unless ``rescan``), and commits the rows a backend streams back every
:data:`COMMIT_ROWS` rows or :data:`COMMIT_SECONDS` seconds, whichever comes first. SIGINT and
SIGTERM stop the workers and commit the rows already received before the command exits (130), and a
line says how many files are stored and that running the same command again goes on from there;
SIGKILL loses only the rows not yet committed, which the next run checks again. Off a terminal a
progress line every few seconds (:mod:`ar3cli.output.progress`) shows the scan is alive.
"""

from __future__ import annotations

import contextlib
import os
import signal
import time
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ar3cli.scan.record import STATUSES, Row
from ar3cli.scan.store import Store, storable
from ar3cli.scan.worker import ScanSettings, content_hash

COMMIT_ROWS = 64
"""Rows per transaction at most: one commit costs ~1 ms in WAL mode, a static check ~2 ms a file."""
COMMIT_SECONDS = 1.0
"""A slow scan (--sim) still commits at least this often, so an interruption loses little."""


@dataclass
class ScanSummary:
    """What one run did: files found, skipped (already stored), checked, by status, and its time."""

    store: str
    backend: str
    files: int = 0
    skipped: int = 0
    checked: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    seconds: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        rate = self.checked / self.seconds if self.seconds > 0 else 0.0
        return {"store": self.store, "backend": self.backend, "files": self.files, "skipped": self.skipped,
                "checked": self.checked, "statuses": self.statuses, "seconds": round(self.seconds, 3),
                "files_per_second": round(rate, 2)}


@dataclass(frozen=True)
class Backend:
    """Where the checks run: ``local`` (forked workers on this machine) or ``ray`` (a Ray cluster)."""

    name: str = "local"
    jobs: int | None = None
    timeout: float | None = None
    address: str | None = None


def run_scan(files: list[Path], store_path: Path, settings: ScanSettings, backend: Backend,
             rescan: bool = False) -> ScanSummary:
    """Scan ``files`` into the store at ``store_path``; see the module docstring."""
    from ar3cli.output.progress import progress_bar

    started = time.monotonic()
    summary = ScanSummary(str(store_path), backend.name)
    statuses: Counter[str] = Counter()
    with Store(store_path) as store:
        known = {} if rescan else store.known()
        todo = _to_check(files, known, settings.key)
        summary.files = len({os.path.abspath(path) for path in files})
        summary.skipped = summary.files - len(todo)
        pending: list[Row] = []
        last_commit = time.monotonic()
        interrupted = False
        try:
            with _sigterm_interrupts(), progress_bar("scanning", len(todo), unit="files") as advance:
                for row in _rows(todo, settings, backend):
                    pending.append(row)
                    statuses[row.status] += 1
                    advance(1)
                    if len(pending) >= COMMIT_ROWS or time.monotonic() - last_commit >= COMMIT_SECONDS:
                        store.put(pending, time.time())
                        pending.clear()
                        last_commit = time.monotonic()
        except KeyboardInterrupt:
            interrupted = True
            raise
        finally:
            with _signals_held():  # the rows received are whole: keep them, whatever stopped the run
                store.put(pending, time.time())
                if interrupted:
                    _say_how_to_resume(store, store_path, sum(statuses.values()), len(todo))
    summary.checked = sum(statuses.values())
    summary.statuses = {status: statuses[status] for status in STATUSES}
    summary.seconds = time.monotonic() - started
    return summary


def _say_how_to_resume(store: Store, store_path: Path, checked: int, todo: int) -> None:
    """After Ctrl-C or SIGTERM: what is stored, and that the same command goes on from there."""
    from ar3cli.output.report import log

    log(f"scan: stopped: {checked} of {todo} files checked in this run; {store.count()} files are stored in "
        f"{store_path}. Run the same command again to go on: stored files are not checked again")


def _to_check(files: list[Path], known: dict[str, tuple[str, str]], key: str) -> dict[str, str]:
    """Absolute path -> content hash of every file whose stored row is missing or out of date."""
    todo: dict[str, str] = {}
    for path in files:
        absolute = os.path.abspath(path)
        if absolute in todo:
            continue
        sha = content_hash(absolute)
        if known.get(storable(absolute)) != (sha, key):
            todo[absolute] = sha
    return todo


def _rows(todo: dict[str, str], settings: ScanSettings, backend: Backend) -> Iterator[Row]:
    """The rows of ``todo`` as the backend finishes them."""
    if not todo:
        return
    if backend.name == "ray":
        from ar3cli.scan.ray_backend import ray_rows

        yield from ray_rows(todo, settings, backend.jobs, backend.timeout, backend.address)
        return
    from ar3cli.infra.process_pool import available_cpus
    from ar3cli.infra.streaming_pool import stream
    from ar3cli.scan.worker import check_file, row_from_outcome

    workers = max(1, min(backend.jobs or available_cpus(), available_cpus(), len(todo)))
    for path, outcome in stream(lambda item: check_file(item, settings), list(todo), workers, backend.timeout):
        row = row_from_outcome(path, outcome, todo[path], settings.key)
        if row is not None:
            yield row


@contextlib.contextmanager
def _sigterm_interrupts() -> Iterator[None]:
    """SIGTERM raises KeyboardInterrupt here, as Ctrl-C does, for the duration (then as before)."""
    def stop(_signal: int, _frame: object) -> None:
        raise KeyboardInterrupt

    try:
        previous = signal.signal(signal.SIGTERM, stop)
    except ValueError:  # not the main thread: leave signals alone
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM held back for the duration (delivered on leaving)."""
    held = {signal.SIGINT, signal.SIGTERM}
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
