"""Positions in a document's text as LSP counts them, and the range a finding covers.

LSP positions are (line, character), the character counted in the position encoding client and
server agreed on: UTF-16 code units unless the client offered UTF-8 or UTF-32 (pygls chooses).
:class:`LineIndex` turns offsets in a Python string (code points) into such positions and back;
byte offsets (the fixers' editor, :mod:`ar3cli.urdf.edits`, works on bytes) go through
:meth:`LineIndex.from_bytes`.

A finding says where its element starts (line and column of ``<``, 1-based; for xacro, where the
element was written). :func:`finding_span` widens that to what an editor should underline: the
element's start tag, or only the attribute(s) the message names (``lower 1.5 > upper -1.5`` underlines
``lower="1.5" upper="-1.5"``; ``mesh meshes/a.stl: file not found`` the ``filename``). A finding with
a line and no column (a load failure) covers its line; one with neither, the first line.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass

START_TAG = re.compile(r"""<([^\s/>!?"'=<]+)((?:\s+[^\s/>="'<]+\s*=\s*(?:"[^"]*"|'[^']*'))*)\s*/?>""")
"""A complete start tag (or empty-element tag): its name, then its attributes."""
ATTRIBUTE = re.compile(r"""([^\s/>="'<]+)\s*=\s*(?:"([^"]*)"|'([^']*)')""")
"""One attribute inside a start tag: name, then the value in double or single quotes."""
PATH_LIKE = re.compile(r"[/\\.:]")
"""A value a message may quote instead of naming its attribute: a file name, a URI, a number."""


class LineIndex:
    """Line starts of one text, to convert offsets to LSP positions in ``encoding`` and back."""

    def __init__(self, text: str, encoding: str = "utf-16") -> None:
        self.text = text
        self.encoding = encoding
        self.starts = [0]
        find = text.find
        index = find("\n")
        while index >= 0:
            self.starts.append(index + 1)
            index = find("\n", index + 1)
        self._ascii = text.isascii()

    @property
    def line_count(self) -> int:
        return len(self.starts)

    def line_text(self, line: int) -> str:
        """Line ``line`` (0-based) without its line ending; empty past the end."""
        if not 0 <= line < len(self.starts):
            return ""
        end = self.starts[line + 1] - 1 if line + 1 < len(self.starts) else len(self.text)
        return self.text[self.starts[line]:end].rstrip("\r")

    def line_start(self, line: int) -> int:
        return self.starts[min(max(line, 0), len(self.starts) - 1)]

    def units(self, segment: str) -> int:
        """How many code units of the encoding ``segment`` takes."""
        if self.encoding == "utf-32" or segment.isascii():
            return len(segment)
        if self.encoding == "utf-8":
            return len(segment.encode("utf-8", "surrogatepass"))
        return len(segment) + sum(ord(char) > 0xFFFF for char in segment)

    def position(self, offset: int) -> tuple[int, int]:
        """(line, character) of ``offset`` (clamped to the text)."""
        offset = min(max(offset, 0), len(self.text))
        line = bisect.bisect_right(self.starts, offset) - 1
        return line, self.units(self.text[self.starts[line]:offset])

    def offset(self, line: int, character: int) -> int:
        """The offset of a position; a character past the line's end is its end, a line past the
        text's end is the text's end (LSP asks clients and servers to be lenient alike)."""
        if line >= len(self.starts):
            return len(self.text)
        if line < 0:
            return 0
        text = self.line_text(line)
        start = self.starts[line]
        if self.encoding == "utf-32" or text.isascii():
            return start + min(max(character, 0), len(text))
        count = 0
        for index, char in enumerate(text):
            if count >= character:
                return start + index
            count += self.units(char)
        return start + len(text)

    def from_bytes(self, data: bytes, byte_offset: int) -> int:
        """The text offset of a byte offset into ``data`` (this text encoded as UTF-8)."""
        if self._ascii:
            return byte_offset
        return len(data[:byte_offset].decode("utf-8", "replace"))


@dataclass(frozen=True)
class Tag:
    """A start tag found in a text: its name, where it starts and ends, and its attributes as
    name -> (start of the name, end after the closing quote, value)."""

    name: str
    start: int
    end: int
    attributes: dict[str, tuple[int, int, str]]


def tag_at(text: str, start: int) -> Tag | None:
    """The start tag that begins at ``start`` (a ``<``), or None when there is no complete one."""
    match = START_TAG.match(text, start)
    if match is None:
        return None
    attributes: dict[str, tuple[int, int, str]] = {}
    for attribute in ATTRIBUTE.finditer(text, match.start(2), match.end(2)):
        value = attribute.group(2) if attribute.group(2) is not None else attribute.group(3)
        attributes.setdefault(attribute.group(1), (attribute.start(), attribute.end(), value))
    return Tag(match.group(1), match.start(), match.end(), attributes)


def tag_near(index: LineIndex, line: int, column: int) -> Tag | None:
    """The start tag a finding at ``line``/``column`` (1-based) names: the one starting there, else the
    one starting nearest to it on the same line (an expat column counts bytes, ours characters)."""
    text = index.line_text(line - 1)
    if not text:
        return None
    base = index.line_start(line - 1)
    wanted = min(max(column - 1, 0), len(text))
    candidates = [match.start() for match in re.finditer(r"<(?=[^\s/!?])", text)]
    for position in sorted(candidates, key=lambda position: abs(position - wanted)):
        found = tag_at(index.text, base + position)
        if found is not None:
            return found
    return None


def named_attributes(tag: Tag, message: str) -> list[str]:
    """The attributes of ``tag`` a finding's message is about: named as a word (``lower 1.5 > upper
    -1.5``, ``xzy="0 0 1"``), or quoted by a value that looks like a path or URI."""
    named = []
    for name, (_, _, value) in tag.attributes.items():
        if re.search(rf"(?<![\w-]){re.escape(name)}(?![\w-])", message) or (
                len(value) >= 3 and PATH_LIKE.search(value) and not value.replace(".", "").isdigit()
                and value in message):
            named.append(name)
    return named


def finding_span(index: LineIndex, line: int, column: int, message: str) -> tuple[int, int]:
    """The text offsets (start, end) an editor underlines for a finding at ``line``/``column``
    (1-based; 0 when unknown): the attributes the message names, else the start tag, else the
    line's text, else the first line."""
    if line <= 0:
        return 0, len(index.line_text(0))
    tag = tag_near(index, line, column) if column > 0 else None
    if tag is None:
        text = index.line_text(line - 1)
        start = index.line_start(line - 1)
        stripped = text.lstrip()
        begin = start + len(text) - len(stripped)
        return begin, start + len(text.rstrip()) if stripped else start + len(text)
    named = named_attributes(tag, message)
    if named:
        spans = [tag.attributes[name] for name in named]
        return min(span[0] for span in spans), max(span[1] for span in spans)
    return tag.start, tag.end
