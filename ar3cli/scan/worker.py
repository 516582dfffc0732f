"""The per-file check of a scan, as it runs in a worker (a forked process, or a Ray task's).

The check itself is the linter, handed in as a :data:`LintFunction` by the command layer (a
feature does not import another feature): given the file and the Model this module loaded (None
when it did not load), it returns the linter's per-file result (``loaded``, ``findings``,
``error``). Loading here, once, gives the metrics (DOF, mass, links) and the load time without
parsing the file twice.
"""

from __future__ import annotations

import hashlib
import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError
from ar3cli.scan.record import Row, model_metrics, status_of

LintFunction = Callable[[Path, Any], Any]
"""``lint(path, model_or_None) -> result`` with ``result.loaded``, ``result.findings`` (Finding
objects) and ``result.error`` (a crash that cut the check short, or None). It must pickle (Ray
sends it to its workers): a module-level function, or a ``functools.partial`` of one."""


@dataclass(frozen=True)
class ScanSettings:
    """What every worker needs besides the file: how to load it, the linter, and the row's settings key."""

    lint: LintFunction
    key: str
    """Names what was checked (rules, --sim, version): a stored row with another key is checked again."""
    package_paths: Mapping[str, Path] = field(default_factory=dict)
    xacro_args: Mapping[str, str] = field(default_factory=dict)
    cwd: str = ""
    """The driver's working folder: findings name files relative to it, on any machine that has it."""


def content_hash(path: str) -> str:
    """SHA-256 of the file's bytes, read as the linter reads them; "" when it cannot be read."""
    from ar3cli.infra.safe_read import read_bytes

    try:
        return hashlib.sha256(read_bytes(Path(path))).hexdigest()
    except UserError:
        return ""


def check_file(path: str, settings: ScanSettings) -> Row:
    """Load and lint one file; every failure of the file is a row, never an exception."""
    from ar3cli.infra.safe_read import read_bytes
    from ar3cli.urdf.model import load_model

    if settings.cwd and os.getcwd() != settings.cwd and os.path.isdir(settings.cwd):
        os.chdir(settings.cwd)
    start = time.perf_counter()
    sha, model, metrics, load_seconds = "", None, {}, None
    try:
        source = read_bytes(Path(path))
        sha = hashlib.sha256(source).hexdigest()
        model = load_model(path, settings.package_paths, settings.xacro_args, source=source)
        load_seconds = time.perf_counter() - start
        metrics = model_metrics(model)
    except (UserError, RecursionError):
        pass  # the linter reports why as an F finding
    try:
        result = settings.lint(Path(path), model)
    except UserError as exc:
        return Row(path, sha, settings.key, "error", message=exc.message, **metrics)
    findings = [finding.to_dict() for finding in result.findings]
    return Row(path, sha, settings.key, status_of(result.loaded, findings, result.error), findings,
               result.error or "", load_seconds=load_seconds, check_seconds=time.perf_counter() - start, **metrics)


def row_from_outcome(path: str, outcome: tuple[str, Any], sha: str, key: str) -> Row | None:
    """The row of a pool outcome: the worker's row, or one saying it crashed, timed out or failed
    (``sha`` is the driver's hash then); None when the worker was interrupted (not checked)."""
    kind, payload = outcome
    if kind == "ok":
        return payload
    if kind == "interrupted":
        return None
    if kind == "user-error":
        payload = payload[0]
    elif kind == "error":
        payload = f"internal error in ar3cli: {payload}"
    status = kind if kind in ("crash", "timeout") else "error"
    return Row(path, sha, key, status, message=str(payload))


def check_batch(paths: list[tuple[str, str]], settings: ScanSettings, timeout: float | None) -> list[Row]:
    """Check ``(path, sha)`` pairs in one forked worker with the per-file limit: a Ray task's work."""
    from ar3cli.infra.streaming_pool import stream

    shas = dict(paths)
    rows = [row_from_outcome(path, outcome, shas[path], settings.key)
            for path, outcome in stream(lambda item: check_file(item, settings), list(shas), 1, timeout)]
    return [row for row in rows if row is not None]
