"""Code actions: the fixes with one right answer, and an ignore comment, as workspace edits.

A fix is the fixer's own plan (:mod:`ar3cli.fix`), run on the model of the buffer as the command
runs it on the file, its splices on the byte-preserving editor (:class:`~ar3cli.urdf.edits.Document`)
sent as text edits, not a rewritten file: every other byte of the buffer stays as it was. The
fixers offered are those whose answer needs nothing the user must choose (the rule's ``fixed_by``
names the command with no option): ``fix-joints`` (inverted limits swapped, degrees to radians, an
axis normalised), ``fix-continuous`` (fake limits removed from a continuous joint), and
``fix-mesh-paths`` when the package holding the mesh is known (``--package-path``, or the
``package.xml`` above the robot file). A quick fix changes the element its finding is about; a
"fix all" action applies the fixer to the whole buffer. Fixers refuse xacro (fixing the expansion
does not fix the source), and so does this module: a xacro file gets the ignore comment only.

The ignore comment is ``<!-- ar3cli: ignore[CODE] -->`` inserted as the first child of the finding's
element (of its parent for an empty element such as ``<limit .../>``), which is how lint-urdf
suppresses a finding (``docs/rules.md``); a finding on no element is ignored for the file
(``ignore-file[CODE]`` under ``<robot>``). Its text is computed on the buffer as it is now.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from lsprotocol import types

from ar3cli.server.diagnostics import to_range
from ar3cli.server.ranges import LineIndex

if TYPE_CHECKING:
    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.urdf.edits import Document

ONE_ANSWER = ("fix-joints", "fix-continuous")
"""Fixers whose plan needs no option from the user for the findings it fixes without one."""
NEEDS_PACKAGE = "fix-mesh-paths"
"""The fixer that needs the package a mesh belongs to: offered where that package is known."""
NOT_LOADED = ("F001", "F002", "F003", "F004")
"""Findings on a file that did not load: no comment in it can suppress them."""
TARGET = {"fix-joints": ("joint",), "fix-continuous": ("joint",), "fix-mesh-paths": ("mesh", "texture")}
"""The element a quick fix edits: the finding's own element or its nearest ancestor with this tag."""


@dataclass(frozen=True)
class Planned:
    """A fixer's plan on one buffer: its splices and what it says it changed."""

    document: Document
    changes: list[Any]


def fixer_of(code: str, packages_known: bool) -> str | None:
    """The fixer whose quick fix a finding of rule ``code`` gets (None: none with one right answer)."""
    from ar3cli.lint.fix_hints import fixed_by

    spec = fixed_by(code)
    if not spec:
        return None
    command, *options = spec.split()
    if command in ONE_ANSWER and not options:
        return command
    if command == NEEDS_PACKAGE and packages_known:
        return command
    return None


def known_packages(analysis: RobotAnalysis) -> dict[str, str]:
    """Package name -> folder for fix-mesh-paths: the robot's own (the package.xml above the file)
    and every ``--package-path`` given to the server."""
    from ar3cli.urdf.packages import enclosing_package

    found = {}
    own = enclosing_package(analysis.path.parent)
    if own is not None:
        found[own[0]] = str(own[1])
    found.update({name: str(folder) for name, folder in analysis.settings.packages.items() if folder.is_dir()})
    return found


def plan(analysis: RobotAnalysis, command: str) -> Planned | None:
    """The plan of ``command`` on the analysis' model (kept with the analysis: a cursor moving over
    the same buffer asks again and again); None when it cannot be planned (a xacro file, a buffer
    the editor cannot map to byte positions)."""
    model = analysis.model
    if model is None or model.is_xacro:
        return None

    def compute() -> Planned | None:
        from ar3cli.errors import UserError
        from ar3cli.urdf.edits import Document

        try:
            fixer, options = _fixer(command, analysis)
            document = Document(model.source_bytes)
            document.bind(model.root)
            made = fixer.plan(model, document, options)
        except UserError:
            return None
        return Planned(document, made.changes)

    return analysis.answer(("server-fix", command), compute)


def _fixer(command: str, analysis: RobotAnalysis) -> tuple[Any, Any]:
    """The fixer of ``command`` and the options it runs with here (no joint_limits.yaml, no
    effort or velocity invented, no verification: the user saves and may run the command)."""
    if command == "fix-joints":
        from ar3cli.fix.joints_plan import FIXER

        return FIXER, FIXER.options(verify=False)
    if command == "fix-continuous":
        from ar3cli.fix.continuous_plan import FIXER

        return FIXER, FIXER.options(verify=False)
    from ar3cli.fix.mesh_paths_plan import FIXER

    return FIXER, FIXER.options(package=[f"{name}={folder}" for name, folder in known_packages(analysis).items()],
                                verify=False)


def element_at(model: Any, line: int, column: int) -> Any:
    """The model's element a finding at ``line``/``column`` is on (the engine located it there:
    its start tag's line and :meth:`~ar3cli.urdf.model.Model.column_of`)."""
    if line <= 0:
        return None
    candidates = [element for element in model.root.iter() if isinstance(element.tag, str)
                  and element.sourceline == line]
    for element in candidates:
        if model.column_of(element) == column:
            return element
    return candidates[0] if len(candidates) == 1 else None


def _target(element: Any, tags: tuple[str, ...]) -> Any:
    while element is not None and element.tag not in tags:
        element = element.getparent()
    return element


def text_edits(document: Document, index: LineIndex, within: tuple[int, int] | None = None) -> list[types.TextEdit]:
    """The document's splices (those inside the byte range ``within``, when given) as text edits."""
    edits = []
    for start, end, new in document.splices:
        if within is not None and not (within[0] <= start and end <= within[1]):
            continue
        span = to_range(index, index.from_bytes(document.data, start), index.from_bytes(document.data, end))
        edits.append(types.TextEdit(span, new.decode("utf-8", "replace")))
    return edits


def _action(title: str, uri: str, edits: list[types.TextEdit], diagnostics: list[types.Diagnostic],
            preferred: bool = False) -> types.CodeAction:
    return types.CodeAction(title=title, kind=types.CodeActionKind.QuickFix, diagnostics=diagnostics or None,
                            edit=types.WorkspaceEdit(changes={uri: edits}), is_preferred=preferred or None)


def _describe(changes: list[Any], line_range: tuple[int, int] | None) -> str:
    """What a plan's changes (those on lines ``line_range``) do, in a few words."""
    shown = [change for change in changes if line_range is None or line_range[0] <= change.line <= line_range[1]]
    words = [f"{change.field} {change.old if change.old is not None else '(none)'} -> "
             f"{change.new if change.new is not None else '(removed)'}" for change in shown[:3]]
    more = f" and {len(shown) - 3} more" if len(shown) > 3 else ""
    return ", ".join(words) + more


def fix_actions(uri: str, text: str, analysis: RobotAnalysis | None, diagnostics: list[types.Diagnostic],
                encoding: str) -> list[types.CodeAction]:
    """The quick fixes for ``diagnostics`` (those the editor asks about), and a "fix all" per fixer
    when the buffer has more than one finding it fixes; none unless ``analysis`` is of this very text."""
    if analysis is None or analysis.model is None or analysis.model.is_xacro or analysis.model.edited_away or \
            analysis.model.source_bytes != text.encode("utf-8"):
        return []
    from collections import Counter

    from ar3cli.analysis.findings import static_findings

    index = LineIndex(text, encoding)
    known = bool(analysis.answer(("server-packages",), lambda: known_packages(analysis)))
    actions: list[types.CodeAction] = []
    seen: set[tuple[str, int]] = set()
    for item in diagnostics:
        command = fixer_of(_rule(item), known)
        planned = plan(analysis, command) if command else None
        data = item.data if isinstance(item.data, dict) else {}
        element = element_at(analysis.model, int(data.get("line", 0)), int(data.get("column", 0))) if planned else None
        target = _target(element, TARGET[command]) if command and element is not None else None
        if planned is None or target is None:
            continue
        span = planned.document.span(target)
        edits = text_edits(planned.document, index, (span.start, span.end))
        if not edits or (command, span.start) in seen:
            continue
        seen.add((command, span.start))
        first = target.sourceline or 0
        what = _describe(planned.changes, (first, first + planned.document.data.count(b"\n", span.start, span.end)))
        actions.append(_action(f"{command}: {what}" if what else f"Fix {_rule(item)} with {command}", uri, edits,
                               [item], preferred=True))
    try:
        found = static_findings(analysis).findings
    except Exception:  # noqa: BLE001 - a broken rule: the diagnostics say so; no "fix all" then
        found = []
    counts = Counter(command for finding in found if (command := fixer_of(finding.rule, known)))
    for command, count in sorted(counts.items()):
        planned = plan(analysis, command) if count > 1 else None
        edits = text_edits(planned.document, index) if planned is not None else []
        if edits:
            actions.append(_action(f"{command}: fix all {count} findings it fixes in this file", uri, edits, []))
    return actions


def ignore_actions(uri: str, text: str, diagnostics: list[types.Diagnostic], encoding: str) -> list[types.CodeAction]:
    """An ignore comment for each of ``diagnostics`` (ar3cli's, on a file that loaded), on the
    buffer as it is now (a buffer whose markup is unbalanced gets none)."""
    from ar3cli.errors import UserError
    from ar3cli.urdf.edits import Document

    actions = []
    index = LineIndex(text, encoding)
    data = text.encode("utf-8")
    for item in diagnostics:
        code = _rule(item)
        if not code or code in NOT_LOADED:
            continue
        try:
            document = Document(data)  # one per action: each holds its own splice
        except UserError:
            return []
        if not document.spans:
            return []
        offset = len(text[:index.offset(item.range.start.line, item.range.start.character)].encode("utf-8"))
        position = bisect.bisect_right([span.start for span in document.spans], offset) - 1
        span = document.spans[position] if position >= 0 else None
        if span is not None and span.start <= offset < span.tag_end:
            holder = span.parent if span.self_closing else span
            comment, where = f"<!-- ar3cli: ignore[{code}] -->", f"in <{holder.tag}>" if holder else ""
        else:
            holder = document.spans[0]
            comment, where = f"<!-- ar3cli: ignore-file[{code}] -->", "in this file"
        if holder is None or holder.self_closing:
            continue
        document.insert_child(holder, [comment], before=holder.children[0] if holder.children else None)
        actions.append(_action(f"Ignore {code} {where} (ar3cli: ignore comment)", uri, text_edits(document, index),
                               [item]))
    return actions


def _rule(item: types.Diagnostic) -> str:
    return str(item.code) if item.code is not None and item.source == "ar3cli" else ""
