"""The outline (the kinematic tree as document symbols) and go to definition.

Outline: each root link, the joints below it and the links they carry, nested as the robot is (a
joint's ``detail`` is its type, a link's its mass). A xacro file's links and joints are shown where
they were written when that is in the file itself; one a macro of an included file made is shown
at ``<robot>``, its detail naming the file and line of the macro. Nesting stops at
:data:`MAX_DEPTH` levels (deeper links follow flat): editors and JSON libraries recurse.

Go to definition, from the name under the cursor in the buffer:
- ``<parent link>``, ``<child link>``, ``<gazebo reference>``: the ``<link>`` of that name;
  ``<mimic joint>``: the ``<joint>``. In the buffer when it is written there, else (xacro) where
  the analysis' element was written (an included file's macro, say).
- ``<xacro:NAME ...>``: the ``<xacro:macro name="NAME">``; a name in ``${...}``: the
  ``<xacro:property>`` (or macro parameter's macro); ``$(arg NAME)``: the ``<xacro:arg>``; in the
  buffer, the files it includes and the files that include it.
- ``<xacro:include filename>``: the file (``$(find PKG)`` resolved as xacro does here, through the
  package resolver; a name built from other substitutions is matched against the files xacro read).
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lsprotocol import types

from ar3cli.server.cursor import cursor_at, expression_at, identifier_at
from ar3cli.server.diagnostics import to_range
from ar3cli.server.ranges import LineIndex, tag_at, tag_near

if TYPE_CHECKING:
    from ar3cli.analysis.robot import RobotAnalysis

MAX_DEPTH = 64
"""Levels of nesting in the outline (a 64-joint chain nests fully); deeper links are listed flat."""
XACRO_BUILTINS = frozenset({"macro", "property", "include", "if", "unless", "arg", "insert_block", "call",
                            "element", "attribute", "eval", "eval-text"})
"""xacro's own elements: ``<xacro:NAME>`` with any other NAME calls a macro."""
REFERENCES = {("parent", "link"): "link", ("child", "link"): "link", ("gazebo", "reference"): "link",
              ("mimic", "joint"): "joint"}
"""(element, attribute) whose value names the link or joint to go to."""
TextOf = Callable[[str], "str | None"]
"""A file's current text by absolute path: the editor's buffer when it is open, else the disk."""


def _definition_pattern(tag: str, name: str) -> re.Pattern[str]:
    return re.compile(rf"""<{re.escape(tag)}\b[^>]*?\bname\s*=\s*(["']){re.escape(name)}\1""")


# ---- outline ---------------------------------------------------------------------------------------
def document_symbols(analysis: RobotAnalysis, text: str, encoding: str) -> list[types.DocumentSymbol]:
    """The kinematic tree of the analysis' robot, placed on ``text`` (the text the analysis read)."""
    model = analysis.model
    if model is None:
        return []
    index = LineIndex(text, encoding)
    place = _placer(analysis, index)

    def link_symbol(link: Any) -> types.DocumentSymbol:
        mass = link.inertial.mass if link.inertial is not None else None
        detail = f"{mass:g} kg" if mass is not None else "no inertial"
        return _symbol(link.name, types.SymbolKind.Class, detail, link.element, place)

    roots = [link_symbol(link) for link in model.root_links()]
    stack = [(symbol, 0) for symbol in reversed(roots)]
    seen = {symbol.name for symbol in roots}
    flat_at: dict[int, types.DocumentSymbol] = {}
    while stack:
        parent, depth = stack.pop()
        holder = parent if depth < MAX_DEPTH else flat_at.setdefault(MAX_DEPTH, parent)
        for joint in model.child_joints(parent.name):
            joint_symbol = _symbol(joint.name, types.SymbolKind.Method, joint.type, joint.element, place)
            holder.children = [*(holder.children or []), joint_symbol]
            child = model.link(joint.child) if joint.child else None
            if child is None or child.name in seen:
                continue
            seen.add(child.name)
            child_symbol = link_symbol(child)
            joint_symbol.children = [child_symbol]
            stack.append((child_symbol, depth + 1))
    return roots + [link_symbol(link) for link in model.links if link.name not in seen]  # in a loop


def _symbol(name: str, kind: types.SymbolKind, detail: str, element: Any,
            place: Callable[[Any], tuple[types.Range, types.Range, str]]) -> types.DocumentSymbol:
    from ar3cli.output.report import printable

    whole, selection, where = place(element)
    return types.DocumentSymbol(name=printable(name) or "(no name)", kind=kind,
                                detail=detail + (f" ({where})" if where else ""), range=whole,
                                selection_range=selection)


def _placer(analysis: RobotAnalysis, index: LineIndex) -> Callable[[Any], tuple[types.Range, types.Range, str]]:
    """element -> (its range, its name's range, where it was written when that is another file)."""
    model = analysis.model
    own = os.path.abspath(analysis.path)
    locator = None
    if model.is_xacro:
        from ar3cli.lint.engine import Locator

        locator = Locator(model, analysis.shown_path)
    root = tag_at(index.text, _first_tag(index.text, "robot"))

    def place(element: Any) -> tuple[types.Range, types.Range, str]:
        line, column, elsewhere = element.sourceline or 0, model.column_of(element), ""
        if locator is not None:
            from ar3cli.lint.rules.base import Hit

            shown, line, column = locator.locate(Hit("", element))
            if os.path.abspath(shown) != own:
                elsewhere, line, column = f"{shown}:{line}", 0, 0
        tag = tag_near(index, line, column) if line else None
        if tag is None:
            tag = root
        if tag is None:
            empty = to_range(index, 0, 0)
            return empty, empty, elsewhere
        end = _element_end(index.text, tag)
        name = tag.attributes.get("name")
        selection = to_range(index, name[0], name[1]) if name and not elsewhere else to_range(index, tag.start, tag.end)
        return to_range(index, tag.start, end), selection, elsewhere

    return place


def _first_tag(text: str, name: str) -> int:
    match = re.search(rf"<{name}\b", text)
    return match.start() if match else -1


def _element_end(text: str, tag: Any) -> int:
    """Where an element ends: after its start tag when it is empty, else after its end tag (links and
    joints do not nest in themselves)."""
    if text[tag.end - 2:tag.end] == "/>":
        return tag.end
    close = text.find(f"</{tag.name}", tag.end)
    if close < 0:
        return tag.end
    end = text.find(">", close)
    return end + 1 if end >= 0 else tag.end


# ---- go to definition ------------------------------------------------------------------------------
def definition(path: Path, text: str, position: types.Position, encoding: str, analyses: list[RobotAnalysis],
               related: list[str], text_of: TextOf) -> list[types.Location]:
    """Where the name at ``position`` of ``text`` (the buffer of ``path``) is defined; ``related``
    are the other files to search for xacro definitions (those it includes and those including it)."""
    index = LineIndex(text, encoding)
    offset = index.offset(position.line, position.character)
    cursor = cursor_at(text, offset)
    if cursor.kind == "value" and (cursor.tag, cursor.attribute) in REFERENCES and cursor.value:
        return _element_definition(path, text, REFERENCES[cursor.tag, cursor.attribute], cursor.value, analyses,
                                   text_of, encoding)
    if cursor.kind == "value" and cursor.tag == "xacro:include" and cursor.attribute == "filename":
        return [_file_location(target) for target in include_targets(cursor.value, path, analyses, related)]
    if cursor.kind == "tag" and cursor.tag.startswith("xacro:") and cursor.tag[6:] not in XACRO_BUILTINS:
        name = cursor.tag[6:]  # seg.segment: the macro segment of a file included with ns="seg"
        return _xacro_definitions("macro", name, path, text, related, text_of, encoding) or (
            _xacro_definitions("macro", name.rsplit(".", 1)[1], path, text, related, text_of, encoding)
            if "." in name else [])
    expression = expression_at(text, offset)
    name = identifier_at(text, offset)
    if expression is None or name is None:
        return []
    if expression[0].startswith("$(arg"):
        return _xacro_definitions("arg", name, path, text, related, text_of, encoding)
    if expression[0].startswith("$("):
        return []
    found = _xacro_definitions("property", name, path, text, related, text_of, encoding)
    return found or _macro_parameter(name, path, text, offset, encoding)


def _element_definition(path: Path, text: str, tag: str, name: str, analyses: list[RobotAnalysis], text_of: TextOf,
                        encoding: str) -> list[types.Location]:
    written = _definition_pattern(tag, name).search(text)
    if written is not None:
        return [_location(path, LineIndex(text, encoding), written.start())]
    for analysis in analyses:
        model = analysis.model
        element = None if model is None else (model.link(name) if tag == "link" else model.joint(name))
        if element is None:
            continue
        if not model.is_xacro:
            return []  # a URDF buffer that no longer says it: nothing to go to
        from ar3cli.lint.engine import Locator
        from ar3cli.lint.rules.base import Hit

        shown, line, column = Locator(model, analysis.shown_path).locate(Hit("", element.element))
        where = Path(os.path.abspath(shown))
        target_text = text if where == path else text_of(str(where))
        if target_text is None or not line:
            return [_file_location(where)]
        target_index = LineIndex(target_text, encoding)
        found = tag_near(target_index, line, column)
        return [_location(where, target_index, found.start if found else target_index.line_start(line - 1))]
    return []


def _xacro_definitions(kind: str, name: str, path: Path, text: str, related: list[str], text_of: TextOf,
                       encoding: str) -> list[types.Location]:
    """``<xacro:KIND name="NAME">`` in the buffer, then in the related files (each read once)."""
    pattern = _definition_pattern(f"xacro:{kind}", name)
    for where, content in [(str(path), text), *((other, None) for other in related if other != str(path))]:
        content = content if content is not None else text_of(where)
        if content is None:
            continue
        found = pattern.search(content)
        if found is not None:
            return [_location(Path(where), LineIndex(content, encoding), found.start())]
    return []


def _macro_parameter(name: str, path: Path, text: str, offset: int, encoding: str) -> list[types.Location]:
    """A ``${name}`` inside a macro body that names one of the macro's ``params``: the macro."""
    start = text.rfind("<xacro:macro", 0, offset)
    if start < 0 or text.find("</xacro:macro>", start, offset) >= 0:
        return []
    tag = tag_at(text, start)
    params = tag.attributes.get("params") if tag is not None else None
    if params is None:
        return []
    names = [re.sub(r"[*:=].*$", "", word.lstrip("*")) for word in params[2].split()]
    return [_location(path, LineIndex(text, encoding), start)] if name in names else []


def include_targets(filename: str, path: Path, analyses: list[RobotAnalysis], related: list[str]) -> list[Path]:
    """The file a ``<xacro:include filename>`` names: ``$(find PKG)/rest`` through the package
    resolver, a plain path relative to the including file; a name with other substitutions is matched
    by its literal end against the files xacro read."""
    text = filename.strip()
    candidate = None
    find = re.fullmatch(r"\$\(find\s+([^)\s]+)\s*\)(.*)", text)
    if find is not None:
        resolver = next((analysis.model.resolver for analysis in analyses if analysis.model is not None), None)
        if resolver is None:
            from ar3cli.urdf.packages import PackageResolver

            resolver = PackageResolver(path.parent)
        folder, _ = resolver.find_package(find.group(1))
        if folder is not None:
            candidate = Path(folder) / find.group(2).lstrip("/")
    elif "$" not in text and text:
        candidate = Path(text) if os.path.isabs(text) else path.parent / text
    if candidate is not None and candidate.is_file():
        return [candidate]
    tail = re.split(r"\$\{[^}]*\}|\$\([^)]*\)", text)[-1]
    if len(tail.strip("/")) < 3:
        return []
    return [Path(name) for name in related if name.endswith(tail)][:1]


def _location(path: Path, index: LineIndex, offset: int) -> types.Location:
    from pygls.uris import from_fs_path

    tag = tag_at(index.text, offset)
    name = tag.attributes.get("name") if tag is not None else None
    start, end = (name[0], name[1]) if name else (offset, tag.end if tag is not None else offset)
    return types.Location(from_fs_path(str(path)) or "", to_range(index, start, end))


def _file_location(path: Path) -> types.Location:
    from pygls.uris import from_fs_path

    return types.Location(from_fs_path(str(path)) or "", types.Range(types.Position(0, 0), types.Position(0, 0)))
