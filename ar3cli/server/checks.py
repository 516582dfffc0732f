"""One check of one version of one document: lint-urdf's static rules on the buffer, as diagnostics per file.

:func:`check` loads the buffer as a :class:`~ar3cli.analysis.robot.RobotAnalysis` (the same limits as
lint: capped size, no entities, xacro in its policy in a limited child), asks it for lint-urdf's
static findings with the workspace's configuration, and turns them into diagnostics on the files
they are in: the document itself and, for xacro, the files it includes (their text read from disk,
which is what xacro expanded). :func:`sim_check` is the same for the saved file with the PyBullet
rules (``lint-urdf --sim``: in a forked child), keeping only what those rules found.

Nothing here raises for a bad file: a file that does not load is its F finding, and a rule that
raises (a bug in ar3cli) costs that rule's findings and one line in the server's log, not the others.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from lsprotocol import types

from ar3cli.server.diagnostics import diagnostic
from ar3cli.server.ranges import LineIndex

if TYPE_CHECKING:
    from ar3cli.analysis.dependencies import Dependencies
    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.analysis.settings import AnalysisSettings
    from ar3cli.findings import Finding


@dataclass(frozen=True)
class Snapshot:
    """A document's text at one version."""

    uri: str
    path: Path
    version: int | None
    text: str


@dataclass
class Checked:
    """What one check found: the analysis (kept for hover, symbols, definitions and fixes), the
    diagnostics per absolute file path, the files xacro read, and lines for the server's log."""

    snapshot: Snapshot
    analysis: RobotAnalysis | None
    diagnostics: dict[str, list[types.Diagnostic]] = field(default_factory=dict)
    includes: frozenset[str] = frozenset()
    notes: list[str] = field(default_factory=list)
    standalone: bool = True
    """False for a file checked through the open files that include it (no findings of its own)."""
    dependencies: Dependencies | None = None
    """The files the check read, with their state then (kept when the analysis is let go)."""


def check(snapshot: Snapshot, settings: AnalysisSettings, earlier: Checked | None = None,
          encoding: str = "utf-16") -> Checked:
    """lint-urdf's static rules on ``snapshot`` (``earlier``: the check it replaces; a load that
    fails keeps watching its files and knowing its includes)."""
    from ar3cli.analysis.robot import RobotAnalysis

    analysis = RobotAnalysis.load(snapshot.path, settings, text=snapshot.text,
                                  earlier=earlier.analysis if earlier is not None else None, editing=True)
    findings, notes = lint_findings(analysis, sim=False)
    if analysis.model is not None:
        included = analysis.model.expansion.included if analysis.model.expansion is not None else []
        includes = frozenset(os.path.abspath(name) for name in included)
    else:
        includes = earlier.includes if earlier is not None else frozenset()
    from ar3cli.infra.file_cache import take_learned

    take_learned()  # a long-lived process: the mesh facts it learnt stay in its cache; no parent wants a copy
    if is_macro_library(analysis):
        notes.append(f"{snapshot.path}: a xacro macro library (no links of its own): checked through the "
                     "open files that include it")
        findings = [finding for finding in findings if not _own(finding, analysis)]
    return Checked(snapshot, analysis, diagnostics_by_file(findings, analysis, snapshot, encoding), includes, notes,
                   dependencies=analysis.dependencies)


def sim_check(path: Path, settings: AnalysisSettings, encoding: str = "utf-16") -> tuple[
        dict[str, list[types.Diagnostic]], str | None, list[str]]:
    """``lint-urdf --sim``'s PyBullet findings on the saved ``path``, as diagnostics per file, with
    the one-line error when pybullet could not check it (it crashed or timed out) and log lines."""
    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.lint.rules import REGISTRY

    analysis = RobotAnalysis.load(path, settings)
    found, notes = lint_findings(analysis, sim=True)
    error, notes = (notes[0], notes[1:]) if notes else (None, [])
    simulated = [finding for finding in found if (rule := REGISTRY.get(finding.rule)) is not None and rule.needs_sim]
    snapshot = Snapshot("", path, None, read_text(path) or "")
    return diagnostics_by_file(simulated, analysis, snapshot, encoding), error, notes


def lint_findings(analysis: RobotAnalysis, sim: bool) -> tuple[list[Finding], list[str]]:
    """The analysis' lint findings (``lint-urdf``, or ``lint-urdf --sim``) and the notes to log. A rule
    that raises (a bug) costs only its own findings: the engine runs the others and names it in the
    result's error, which becomes a note here; anything else that fails is one note, no findings."""
    from ar3cli.analysis.findings import findings, static_findings

    try:
        answer = (findings if sim else static_findings)(analysis)
    except Exception as exc:  # noqa: BLE001 - one bad file must not stop the server
        return [], [f"{analysis.path}: the check failed ({type(exc).__name__}: {exc})"]
    return list(answer.findings), [answer.result.error] if answer.result.error else []


def is_macro_library(analysis: RobotAnalysis) -> bool:
    """A xacro file of macros that makes no link by itself (``arm.xacro`` included by ``robot.urdf.xacro``):
    alone it is a robot without links (S011), which says nothing about the file. Its findings come
    from the open files that include it."""
    model = analysis.model
    return model is not None and model.is_xacro and not model.links and b"xacro:macro" in model.source_bytes


def _own(finding: Finding, analysis: RobotAnalysis) -> bool:
    return finding.path == analysis.shown_path


def file_of(finding: Finding, analysis: RobotAnalysis) -> str:
    """The absolute path of the file a finding is in (findings name files relative to the current folder)."""
    return str(analysis.path) if _own(finding, analysis) else os.path.abspath(finding.path)


def diagnostics_by_file(findings: list[Finding], analysis: RobotAnalysis, snapshot: Snapshot,
                        encoding: str) -> dict[str, list[types.Diagnostic]]:
    """The findings as diagnostics, per absolute file path; the document's own on ``snapshot``'s text,
    an included file's on its text on disk (an unreadable one's on its first line)."""
    by_file: dict[str, list[types.Diagnostic]] = {str(snapshot.path): []}
    indexes = {str(snapshot.path): LineIndex(snapshot.text, encoding)}
    for finding in findings:
        where = file_of(finding, analysis)
        if where not in indexes:
            indexes[where] = LineIndex(read_text(Path(where)) or "", encoding)
        by_file.setdefault(where, []).append(diagnostic(finding, indexes[where]))
    return by_file


def read_text(path: Path) -> str | None:
    """A file's text through the capped reader (None when it cannot be read)."""
    from ar3cli.errors import UserError
    from ar3cli.infra.safe_read import read_bytes
    from ar3cli.urdf.xmlsource import decode_text

    try:
        return decode_text(read_bytes(path))
    except (UserError, OSError):
        return None
