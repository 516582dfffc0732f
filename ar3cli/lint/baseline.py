"""Baselines: accept the findings a project has today, fail only on new ones.

``lint-urdf --write-baseline FILE`` records every finding of the run; ``--baseline FILE`` then
drops the findings the file records, so a legacy robot description can be linted in CI from
today on without fixing its past first (ruff's and phpstan's way of adopting a linter).

A finding is recorded by its file, its rule and a **fingerprint** that survives edits elsewhere
in the file: a hash of the rule code, the message's shape (:func:`~ar3cli.lint.engine.message_shape`:
names, paths and numbers replaced by ``#``) and the quoted names in the message (the link, joint
or mesh it is about). The line and column are left out, so a link added above does not turn
every finding below it into a "new" one; numbers are left out too, so changing a bad mass from
0 to -1 on the same link is still the same, known problem. Renaming the link makes it a new
finding. Findings with the same fingerprint in one file are counted: a baseline that holds two
is used up by two, and a third is new.

Paths in the file are relative to the baseline file's folder (POSIX separators), so the baseline
works from any working directory and in any clone of the repository.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import re
from collections import Counter
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError
from ar3cli.findings import Finding
from ar3cli.lint.engine import LintResult, Suppressed, message_shape

VERSION = 1
_QUOTED = re.compile(r"""'([^']*)'|"([^"]*)\"""")


def fingerprint(finding: Finding) -> str:
    """16 hex digits naming the finding without its position (see the module's docstring)."""
    names = [single if single is not None else double for single, double in _QUOTED.findall(finding.message)]
    text = "\0".join([finding.rule, message_shape(finding.message), *names])
    return hashlib.sha256(text.encode("utf-8", "surrogateescape")).hexdigest()[:16]


def baseline_key(shown: str, folder: Path) -> str:
    """A finding's path as the baseline holds it: relative to ``folder``, symlinks resolved."""
    real = os.path.realpath(shown)
    try:
        relative = os.path.relpath(real, os.path.realpath(folder))
    except ValueError:  # another drive on Windows
        return Path(real).as_posix()
    return Path(relative).as_posix()


def write_baseline(path: Path, results: list[LintResult], follow_symlinks: bool = False) -> tuple[int, int]:
    """Write every finding of ``results`` to the baseline ``path`` (atomically; a symlink only with
    ``follow_symlinks``); returns the number of findings and of files that have some."""
    from ar3cli.infra.atomic import atomic_write

    folder = Path(os.path.abspath(path)).parent
    counts: Counter[tuple[str, str, str]] = Counter()
    examples: dict[tuple[str, str, str], str] = {}
    for finding in (f for result in results for f in result.findings):
        key = (baseline_key(finding.path, folder), finding.rule, fingerprint(finding))
        counts[key] += 1
        examples.setdefault(key, finding.message)
    files: dict[str, list[dict[str, Any]]] = {}
    for (file, rule, mark), count in sorted(counts.items(), key=lambda item: (*item[0][:2], examples[item[0]],
                                                                              item[0][2])):
        files.setdefault(file, []).append({"rule": rule, "fingerprint": mark, "count": count,
                                           "message": examples[(file, rule, mark)]})
    document = {"ar3cli-baseline": VERSION,
                "fingerprint": "rule + message shape + quoted names; no line numbers",
                "files": files}
    atomic_write(Path(path), (json.dumps(document, indent=2, ensure_ascii=False) + "\n").encode("utf-8"),
                 follow_symlinks=follow_symlinks)
    return sum(counts.values()), len(files)


@dataclasses.dataclass
class Baseline:
    """A baseline read from ``path``: (file, rule, fingerprint) -> how many findings it accepts."""

    path: Path
    entries: Counter[tuple[str, str, str]]

    @property
    def folder(self) -> Path:
        return Path(os.path.abspath(self.path)).parent


def read_baseline(path: Path) -> Baseline:
    """Read a baseline file; anything wrong with it is a one-line :class:`UserError` (exit 2)."""
    from ar3cli.infra.safe_read import read_bytes

    try:
        document = json.loads(read_bytes(Path(path)).decode("utf-8"))
    except UserError as exc:
        raise UserError(f"cannot read the baseline: {exc.message}") from None
    except (UnicodeDecodeError, ValueError) as exc:
        raise UserError(f"{path}: cannot read the baseline: not JSON ({exc})") from None
    if not isinstance(document, dict) or document.get("ar3cli-baseline") != VERSION \
            or not isinstance(document.get("files"), dict):
        raise UserError(f"{path}: cannot read the baseline: not an ar3cli baseline (version {VERSION}); "
                        "write one with --write-baseline")
    entries: Counter[tuple[str, str, str]] = Counter()
    for file, items in document["files"].items():
        if not isinstance(items, list):
            raise UserError(f"{path}: cannot read the baseline: the entry of {file!r} is not a list")
        for item in items:
            try:
                count = int(item.get("count", 1))
                entries[(str(file), str(item["rule"]), str(item["fingerprint"]))] += max(count, 0)
            except (AttributeError, KeyError, TypeError, ValueError):
                raise UserError(f"{path}: cannot read the baseline: a finding of {file!r} has no rule, "
                                "fingerprint or count") from None
    return Baseline(Path(path), entries)


def apply_baseline(results: list[LintResult], baseline: Baseline) -> tuple[list[LintResult], int, int]:
    """``results`` without the findings the baseline accepts (kept among each result's suppressed
    ones, by ``baseline``); also how many were dropped and how many baseline entries of the files
    linted in this run were not used (fixed since)."""
    left = Counter(baseline.entries)
    keys: dict[str, str] = {}
    kept_results = []
    dropped = 0
    seen: set[str] = set()
    for result in results:
        seen.add(keys.setdefault(result.path, baseline_key(result.path, baseline.folder)))
        kept, held = [], list(result.suppressed)
        for finding in result.findings:
            file = keys.setdefault(finding.path, baseline_key(finding.path, baseline.folder))
            seen.add(file)
            key = (file, finding.rule, fingerprint(finding))
            if left[key] > 0:
                left[key] -= 1
                dropped += 1
                held.append(Suppressed(finding, "baseline"))
            else:
                kept.append(finding)
        kept_results.append(dataclasses.replace(result, findings=kept, suppressed=held))
    unused = sum(count for (file, _, _), count in left.items() if file in seen and count > 0)
    return kept_results, dropped, unused
