"""Hover: on a finding, its rule's documentation; on a link or joint name, what the robot says about it.

The rule's documentation is the text ``ar3cli lint-urdf --explain CODE`` prints (why it matters,
the fix, the examples, the link). A link's summary (mass, the joint above it and those below it,
centre of mass) and a joint's (type, parent and child, axis, limits, home value) are the analysis
layer's :func:`~ar3cli.analysis.facts.link_facts` and :func:`~ar3cli.analysis.facts.joint_facts`,
the facts ``report`` and ``info`` show. A name is read from the buffer under the cursor (``<link
name>``, ``<joint name>``, ``<parent link>``, ``<child link>``, ``<mimic joint>``, ``<gazebo
reference>``), so hover works on what the user sees even while the latest edit is being checked.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from lsprotocol import types

from ar3cli.server.cursor import cursor_at
from ar3cli.server.diagnostics import to_range
from ar3cli.server.ranges import LineIndex

if TYPE_CHECKING:
    from ar3cli.analysis.robot import RobotAnalysis

NAMES = {("link", "name"): ("link",), ("joint", "name"): ("joint",), ("parent", "link"): ("link",),
         ("child", "link"): ("link",), ("mimic", "joint"): ("joint",), ("gazebo", "reference"): ("link", "joint")}
"""(element, attribute) whose value names a link or a joint, and which of the two it may name."""


def explanation(code: str) -> str:
    """What ``ar3cli lint-urdf --explain CODE`` prints."""
    from ar3cli.lint.engine import find_rule, rule_document
    from ar3cli.output.explain import explain_text

    return explain_text(rule_document(find_rule(code)))


def _contains(item: types.Range, position: types.Position) -> bool:
    start, end = item.start, item.end
    return (start.line, start.character) <= (position.line, position.character) <= (end.line, end.character)


def hover(text: str, position: types.Position, encoding: str, diagnostics: list[types.Diagnostic],
          analyses: list[RobotAnalysis]) -> types.Hover | None:
    """The hover at ``position`` of ``text``: the documentation of the rules whose diagnostics are
    there, else the facts about the link or joint named there, else None."""
    from ar3cli.errors import UserError

    codes = list(dict.fromkeys(str(item.code) for item in diagnostics
                               if item.code is not None and _contains(item.range, position)))
    explained = []
    for code in codes:
        try:
            explained.append(explanation(code))
        except UserError:
            continue
    if explained:
        return types.Hover(types.MarkupContent(types.MarkupKind.PlainText, "\n".join(explained).rstrip("\n")))
    index = LineIndex(text, encoding)
    cursor = cursor_at(text, index.offset(position.line, position.character))
    kinds = NAMES.get((cursor.tag, cursor.attribute)) if cursor.kind == "value" else None
    if not kinds or not cursor.value:
        return None
    lines = facts(cursor.value, kinds, analyses)
    if not lines:
        return None
    from ar3cli.output.report import printable

    span = to_range(index, cursor.value_start, cursor.value_start + len(cursor.value))
    return types.Hover(types.MarkupContent(types.MarkupKind.PlainText, "\n".join(printable(line) for line in lines)),
                       span)


def facts(name: str, kinds: tuple[str, ...], analyses: list[RobotAnalysis]) -> list[str]:
    """The summary lines of the link or joint ``name`` in the first analysis that has it."""
    from ar3cli.analysis.facts import joint_facts, link_facts
    from ar3cli.errors import UserError

    for analysis in analyses:
        for kind in kinds:
            try:
                found = (link_facts if kind == "link" else joint_facts)(analysis, name)
            except UserError:
                found = None
            if found is not None:
                return found.lines()
    return []
