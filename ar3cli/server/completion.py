"""Completion: URDF element and attribute names from the schema, link and joint names, joint types.

The names are the schema lint's S016-S020 rules check against (:data:`ar3cli.lint.rules.schema.SCHEMA`,
URDF 1.2): after ``<`` the children the enclosing element may have, in a start tag the attributes
it may have and does not yet. Inside ``<parent link="">`` / ``<child link="">`` the robot's link
names, in ``<mimic joint="">`` its joint names (from the latest analysis: for xacro, the expanded
names), in ``<joint type="">`` the URDF joint types. A xacro file also gets xacro's elements and
``xacro:NAME`` for the macros it can call (its own and those of the files it includes).
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

from lsprotocol import types

from ar3cli.server.cursor import cursor_at, open_elements
from ar3cli.server.diagnostics import to_range
from ar3cli.server.ranges import LineIndex

if TYPE_CHECKING:
    from ar3cli.analysis.robot import RobotAnalysis

MAX_ITEMS = 1000
"""Items in one answer (a 30,000-link robot's names are marked incomplete rather than all sent)."""
XACRO_ELEMENTS = ("xacro:include", "xacro:macro", "xacro:property", "xacro:arg", "xacro:if", "xacro:unless",
                  "xacro:insert_block")
_MACRO = re.compile(r"""<xacro:macro\b[^>]*?\bname\s*=\s*(["'])([^"']+)\1""")


def macro_names(texts: list[str]) -> list[str]:
    """The macros the texts define (``<xacro:macro name="...">``), each once."""
    return list(dict.fromkeys(match.group(2) for text in texts for match in _MACRO.finditer(text)))


def completions(text: str, position: types.Position, encoding: str, analyses: list[RobotAnalysis],
                xacro_texts: list[str] | None = None) -> types.CompletionList:
    """What may be typed at ``position``; ``xacro_texts`` (a xacro file: its text and its includes')
    adds xacro's elements and macros."""
    from ar3cli.lint.rules.schema import SCHEMA

    index = LineIndex(text, encoding)
    offset = index.offset(position.line, position.character)
    cursor = cursor_at(text, offset)
    replace = to_range(index, cursor.word_start, offset) if cursor.word_start >= 0 else None
    names: list[str] = []
    kind = types.CompletionItemKind.Property
    if cursor.kind == "tag":
        parents = [name for name in open_elements(text, cursor.tag_start) if not name.startswith("xacro:")]
        parent = parents[-1] if parents else None
        names = sorted(SCHEMA[parent][1]) if parent in SCHEMA else ([] if parent else ["robot"])
        if xacro_texts is not None:
            names += [*XACRO_ELEMENTS, *(f"xacro:{name}" for name in macro_names(xacro_texts))]
        kind = types.CompletionItemKind.Class
    elif cursor.kind == "attribute" and cursor.tag in SCHEMA:
        names = sorted(SCHEMA[cursor.tag][0] - (cursor.present - {cursor.attribute}))
    elif cursor.kind == "value":
        names, kind = _values(cursor.tag, cursor.attribute, analyses)
    items = [types.CompletionItem(label=name, kind=kind,
                                  text_edit=types.TextEdit(replace, name) if replace is not None else None)
             for name in names[:MAX_ITEMS]]
    return types.CompletionList(is_incomplete=len(names) > MAX_ITEMS, items=items)


def _values(tag: str, attribute: str, analyses: list[RobotAnalysis]) -> tuple[list[str], types.CompletionItemKind]:
    from ar3cli.urdf.model import URDF_JOINT_TYPES

    if tag == "joint" and attribute == "type":
        return list(URDF_JOINT_TYPES), types.CompletionItemKind.EnumMember
    model = next((analysis.model for analysis in analyses if analysis.model is not None), None)
    if model is None:
        return [], types.CompletionItemKind.Reference
    if (tag, attribute) in (("parent", "link"), ("child", "link"), ("gazebo", "reference")):
        return list(dict.fromkeys(link.name for link in model.links)), types.CompletionItemKind.Reference
    if (tag, attribute) == ("mimic", "joint"):
        return list(dict.fromkeys(joint.name for joint in model.joints)), types.CompletionItemKind.Reference
    return [], types.CompletionItemKind.Reference
