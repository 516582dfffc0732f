"""Byte-preserving edits of an XML file.

The fixers must change only the elements they fix: every comment, attribute order, quote
character, indentation, blank line, line ending and the XML declaration stay byte for byte.
lxml knows each element's source line but not its byte span, so :class:`Document` scans the
ORIGINAL bytes itself: tags from the start of the file, nesting tracked, comments / CDATA /
processing instructions / DOCTYPE skipped, quoted attribute values (which may contain ``>``)
respected. Elements come out in document order, which is the order of ``root.iter()`` over
lxml elements, so an lxml element is mapped to its span by its index in that order.

Edits are collected as non-overlapping splices ``(start, end, new_bytes)`` and applied in one
go by :meth:`Document.apply`. New text is ASCII, so it is valid in any ASCII-compatible
encoding the file may declare. Writing the result is :func:`ar3cli.infra.atomic.atomic_write`'s job.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass, field

from ar3cli.errors import UserError

_NAME = re.compile(rb"[^\s/>=]+")
_ATTRIBUTE = re.compile(rb"""(\s+)([^\s/>=]+)(\s*=\s*)(?:"([^"]*)"|'([^']*)')""")


@dataclass
class Attribute:
    """One attribute in a start tag: spans of the whole ``␣name="value"`` and of the value."""

    name: str
    start: int  # of the leading whitespace
    end: int  # after the closing quote
    value_start: int
    value_end: int
    quote: bytes


@dataclass
class Span:
    """Byte span of one element in the original file.

    ``start``..``tag_end`` is the start tag (``tag_end`` after its ``>``), ``start``..``end`` the
    whole element; ``attrs_end`` is where a new attribute would go (before ``/>`` or ``>``).
    """

    tag: str
    start: int
    tag_end: int
    attrs_end: int
    end: int = -1
    self_closing: bool = False
    attributes: dict[str, Attribute] = field(default_factory=dict)
    children: list[Span] = field(default_factory=list)
    parent: Span | None = None


class Document:
    """The original bytes of a file, its element spans and a list of pending splices."""

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.spans: list[Span] = _scan(data)
        self.newline = b"\r\n" if b"\r\n" in data else b"\n"
        self._splices: list[tuple[int, int, bytes]] = []
        self.quote = _dominant_quote(self.spans)
        self.indent_unit = _indent_unit(data, self.spans)

    # ---- mapping lxml elements to spans ----------------------------------------------------
    def bind(self, root) -> dict[str, Span]:
        """Map the path (``/robot/link[3]/inertial``) of every lxml element under ``root`` to its span.

        Paths, not ``id()``: lxml creates a new Python proxy each time an element is looked up.
        Raises when the scan and the parse disagree (then no edit is safe).
        """
        elements = [e for e in root.iter() if isinstance(e.tag, str)]
        if len(elements) != len(self.spans) or any(_written_tag(e) != s.tag for e, s in zip(elements, self.spans)):
            raise UserError("cannot map the file's elements to byte positions safely; refusing to edit it")
        self._tree = root.getroottree()
        self._by_path = {self._tree.getpath(e): s for e, s in zip(elements, self.spans)}
        return self._by_path

    def span(self, element) -> Span:
        """The span of an lxml element (after :meth:`bind`)."""
        return self._by_path[self._tree.getpath(element)]

    def refusal(self, element, attributes=(), same_for_every_use: bool = False) -> str | None:
        """Why ``element`` cannot be edited here (reading or writing ``attributes``): never, in a file
        whose elements are the model's; a xacro source says when the value is not literal text there
        (:class:`~ar3cli.urdf.xacro_edits.XacroDocument`)."""
        return None

    def user_line(self, line: int) -> int:
        """The line the user sees for the model's line ``line``: the same one here (a xacro maps it)."""
        return line

    # ---- text helpers ------------------------------------------------------------------------
    def indentation(self, span: Span) -> bytes:
        """The whitespace before ``span`` on its line (empty when other text precedes it)."""
        line_start = self.data.rfind(b"\n", 0, span.start) + 1
        prefix = self.data[line_start:span.start]
        return prefix if not prefix.strip() else b""

    def child_indentation(self, span: Span) -> bytes:
        """Indentation for a new child of ``span``: that of its children, else one unit deeper."""
        for child in span.children:
            indent = self.indentation(child)
            if indent:
                return indent
        return self.indentation(span) + self.indent_unit

    def format_attr(self, name: str, value: str) -> bytes:
        """``name="value"`` with the file's usual quote character."""
        quote = self.quote.decode()
        return f"{name}={quote}{_escape(value, quote)}{quote}".encode()

    # ---- splices -------------------------------------------------------------------------------
    def splice(self, start: int, end: int, new: bytes) -> None:
        """Replace ``data[start:end]`` with ``new`` (applied by :meth:`apply`)."""
        self._splices.append((start, end, new))

    def set_attribute(self, span: Span, name: str, value: str) -> None:
        """Change one attribute's value (keeping its quote char) or append the attribute."""
        attribute = span.attributes.get(name)
        if attribute is not None:
            self.splice(attribute.value_start, attribute.value_end, _escape(value, attribute.quote.decode()).encode())
        else:
            self.splice(span.attrs_end, span.attrs_end, b" " + self.format_attr(name, value))

    def remove_attribute(self, span: Span, name: str) -> None:
        """Remove an attribute together with its leading whitespace."""
        attribute = span.attributes.get(name)
        if attribute is not None:
            self.splice(attribute.start, attribute.end, b"")

    def remove_element(self, span: Span) -> None:
        """Remove an element; when it stands alone on its line, the whole line goes with it."""
        line_start = self.data.rfind(b"\n", 0, span.start) + 1
        line_end = self.data.find(b"\n", span.end)
        line_end = len(self.data) if line_end < 0 else line_end + 1
        alone = not self.data[line_start:span.start].strip() and not self.data[span.end:line_end].strip()
        if alone:
            self.splice(line_start, line_end, b"")
        else:
            self.splice(span.start, span.end, b"")

    def insert_child(self, parent: Span, lines: list[str], after: Span | None = None,
                     before: Span | None = None) -> None:
        """Insert a new child element given as text lines (relative indentation in units of 2 spaces).

        It goes after ``after`` (default: the parent's last child) or before ``before``, on its own
        line with the siblings' indentation and the file's line ending. When the siblings share
        one line (``<inertial><mass/><inertia/></inertial>``) a one-line child joins them with a
        space. A self-closing parent is expanded.
        """
        indent = self.child_indentation(parent)
        anchor = before or after or (parent.children[-1] if parent.children else None)
        inline = anchor is not None and len(lines) == 1 and b"\n" not in self.data[parent.start:anchor.end]
        if inline:
            text = self._relative_indent(lines[0])
            if before is not None:
                self.splice(before.start, before.start, text + b" ")
            else:
                self.splice(anchor.end, anchor.end, b" " + text)
            return
        body = self.newline.join(indent + self._relative_indent(line) for line in lines)
        if before is not None:
            own_indent = self.indentation(before)
            start = before.start - len(own_indent)
            self.splice(start, start, body + self.newline)
        elif anchor is not None:
            self.splice(anchor.end, anchor.end, self.newline + body)
        elif parent.self_closing:
            close = self.newline + self.indentation(parent) + f"</{parent.tag}>".encode()
            self.splice(parent.attrs_end, parent.tag_end, b">" + self.newline + body + close)
        else:  # <parent ...></parent> or <parent ...>  </parent>: keep what was inside after the child
            self.splice(parent.tag_end, parent.tag_end, self.newline + body + (
                self.newline + self.indentation(parent) if b"\n" not in self.data[parent.tag_end:parent.end] else b""))

    def _relative_indent(self, line: str) -> bytes:
        stripped = line.lstrip(" ")
        depth = (len(line) - len(stripped)) // 2
        return self.indent_unit * depth + stripped.encode()

    def apply(self) -> bytes:
        """The new bytes with every splice applied; overlapping splices are a bug."""
        result = self.data
        ordered = sorted(self._splices, key=lambda s: (s[0], s[1]))
        for (_, end_a, _), (start_b, _, _) in zip(ordered, ordered[1:]):
            if start_b < end_a:
                raise AssertionError("overlapping edits")
        for start, end, new in reversed(ordered):
            result = result[:start] + new + result[end:]
        return result

    @property
    def changed(self) -> bool:
        return bool(self._splices)

    @property
    def splices(self) -> list[tuple[int, int, bytes]]:
        """The pending splices ``(start, end, new)`` in file order, as :meth:`apply` makes them: what
        an editor applies as text edits instead of the whole new file (``ar3cli server``'s quick fixes)."""
        return sorted(self._splices, key=lambda s: (s[0], s[1]))


def _escape(value: str, quote: str) -> str:
    """An attribute value escaped for a given quote character."""
    return value.replace("&", "&amp;").replace("<", "&lt;").replace(quote, "&quot;" if quote == '"' else "&apos;")


# ---- the scanner -----------------------------------------------------------------------------
def _scan(data: bytes) -> list[Span]:
    """Element spans in document order; stops after the root element closes."""
    spans: list[Span] = []
    stack: list[Span] = []
    position = 3 if data.startswith(b"\xef\xbb\xbf") else 0
    length = len(data)
    while True:
        position = data.find(b"<", position)
        if position < 0:
            break
        if data.startswith(b"<!--", position):
            position = _find_end(data, b"-->", position + 4)
        elif data.startswith(b"<![CDATA[", position):
            position = _find_end(data, b"]]>", position + 9)
        elif data.startswith(b"<?", position):
            position = _find_end(data, b"?>", position + 2)
        elif data.startswith(b"<!", position):
            position = _skip_declaration(data, position)
        elif data.startswith(b"</", position):
            close = _find_end(data, b">", position + 2)
            if not stack:
                raise UserError("unbalanced end tag; refusing to edit the file")
            span = stack.pop()
            span.end = close
            position = close
            if not stack:
                break
        else:
            span, position = _start_tag(data, position, length)
            if stack:
                span.parent = stack[-1]
                stack[-1].children.append(span)
            spans.append(span)
            if span.self_closing:
                span.end = span.tag_end
                if not stack:
                    break
            else:
                stack.append(span)
    if stack:
        raise UserError("unclosed element; refusing to edit the file")
    return spans


def _find_end(data: bytes, marker: bytes, start: int) -> int:
    index = data.find(marker, start)
    if index < 0:
        raise UserError("unterminated markup; refusing to edit the file")
    return index + len(marker)


def _skip_declaration(data: bytes, position: int) -> int:
    """Skip ``<!DOCTYPE ...>`` including an internal subset in brackets and quoted strings."""
    depth = 0
    index = position + 2
    while index < len(data):
        char = data[index:index + 1]
        if char in (b'"', b"'"):
            index = _find_end(data, char, index + 1)
            continue
        if char == b"[":
            depth += 1
        elif char == b"]":
            depth -= 1
        elif char == b">" and depth <= 0:
            return index + 1
        index += 1
    raise UserError("unterminated declaration; refusing to edit the file")


def _written_tag(element) -> str:
    """The element's name as the file spells it: ``prefix:name`` for a namespaced element (lxml's
    ``tag`` is ``{uri}name``, as in PR2's ``<controller:gazebo_ros_controller_manager>``)."""
    if not element.tag.startswith("{"):
        return element.tag
    local = element.tag.rpartition("}")[2]
    return f"{element.prefix}:{local}" if element.prefix else local


def _start_tag(data: bytes, position: int, length: int) -> tuple[Span, int]:
    name = _NAME.match(data, position + 1)
    if name is None:
        raise UserError("malformed start tag; refusing to edit the file")
    index = name.end()
    attributes: dict[str, Attribute] = {}
    while True:
        match = _ATTRIBUTE.match(data, index)
        if match is None:
            break
        quote_group = 4 if match.group(4) is not None else 5
        attributes[match.group(2).decode("latin-1")] = Attribute(
            match.group(2).decode("latin-1"), match.start(), match.end(), match.start(quote_group),
            match.end(quote_group), b'"' if quote_group == 4 else b"'")
        index = match.end()
    attrs_end = index
    while index < length and data[index:index + 1] in b" \t\r\n":
        index += 1
    if data.startswith(b"/>", index):
        return Span(name.group(0).decode("latin-1"), position, index + 2, attrs_end, self_closing=True,
                    attributes=attributes), index + 2
    if data.startswith(b">", index):
        return Span(name.group(0).decode("latin-1"), position, index + 1, attrs_end, attributes=attributes), index + 1
    raise UserError("malformed start tag; refusing to edit the file")


def _dominant_quote(spans: list[Span]) -> bytes:
    counts = Counter(a.quote for s in spans for a in s.attributes.values())
    return counts.most_common(1)[0][0] if counts else b'"'


def _indent_unit(data: bytes, spans: list[Span]) -> bytes:
    """The file's usual indentation step (child indent minus parent indent); two spaces by default."""
    counts: Counter[bytes] = Counter()
    for span in spans:
        if span.parent is None:
            continue
        line_start = data.rfind(b"\n", 0, span.start) + 1
        mine = data[line_start:span.start]
        parent_start = data.rfind(b"\n", 0, span.parent.start) + 1
        theirs = data[parent_start:span.parent.start]
        if mine.strip() or theirs.strip() or not mine.startswith(theirs) or len(mine) == len(theirs):
            continue
        counts[mine[len(theirs):]] += 1
    return counts.most_common(1)[0][0] if counts else b"  "
