"""Where the cursor is in a URDF or xacro text: in a tag's name, an attribute's name or value, or text.

Hover, go to definition and completion read the *current* buffer (what the user sees, typed a moment
ago and maybe not parsed yet), so this module reads the text around the cursor itself, forgivingly:
an unfinished tag (``<joint name="j1" ty``) is still a tag. It never parses the whole document;
:func:`open_elements` walks the text before the cursor once, for the elements a new child may be.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

_NAME = re.compile(r"[^\s/>=\"'<]+")
_SPACE = re.compile(r"\s*")
_EQUALS = re.compile(r"\s*=\s*")
_MARKUP = re.compile(r"<!--.*?(?:-->|$)|<!\[CDATA\[.*?(?:\]\]>|$)|<\?.*?(?:\?>|$)|<!.*?>|"
                     r"<(/?)([^\s/>!?\"'=<]+)(?:[^>\"']|\"[^\"]*\"|'[^']*')*?(/?)>", re.S)
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


@dataclass(frozen=True)
class Cursor:
    """What is under the cursor.

    ``kind``: ``tag`` (in a start tag's name, ``<lin|``), ``attribute`` (in an attribute's name or
    the space where one may go), ``value`` (inside an attribute's quotes), ``text`` (anything else).
    ``word`` is the part of the name or value before the cursor (what completion replaces, from
    ``word_start``); ``value`` the attribute's whole value and ``value_start`` where it starts.
    """

    kind: str
    tag: str = ""
    tag_start: int = -1
    attribute: str = ""
    value: str = ""
    value_start: int = -1
    word_start: int = -1
    word: str = ""
    present: frozenset[str] = field(default_factory=frozenset)


def cursor_at(text: str, offset: int) -> Cursor:
    """The :class:`Cursor` at ``offset`` of ``text``."""
    offset = min(max(offset, 0), len(text))
    start = text.rfind("<", 0, offset)
    if start < 0 or text.startswith(("<!", "<?", "</"), start):
        return Cursor("text")
    name = _NAME.match(text, start + 1)
    name_end = name.end() if name else start + 1
    tag = text[start + 1:name_end]
    if offset <= name_end:
        return Cursor("tag", tag, start, word_start=start + 1, word=text[start + 1:offset])
    position, present, found = name_end, set(), None
    while True:
        gap = _SPACE.match(text, position).end()
        if found is None and position < offset <= gap and gap > position:
            found = Cursor("attribute", tag, start, word_start=offset)
        if gap >= len(text) or text[gap] in "<>/":
            closing = text.find(">", gap) if text[gap:gap + 1] in (">", "/") else -1
            if 0 <= closing < offset or (found is None and gap < offset):
                return Cursor("text")  # the tag ended before the cursor
            break
        attribute = _NAME.match(text, gap)
        if attribute is None:
            return Cursor("text") if found is None else found
        present.add(attribute.group())
        if found is None and attribute.start() <= offset <= attribute.end():
            found = Cursor("attribute", tag, start, attribute=attribute.group(), word_start=attribute.start(),
                           word=text[attribute.start():offset])
        equals = _EQUALS.match(text, attribute.end())
        position = attribute.end() if equals is None else equals.end()
        quote = text[position:position + 1] if equals is not None else ""
        if quote not in ("'", '"'):
            continue
        close = text.find(quote, position + 1)
        value_end = close if close >= 0 else len(text)
        if found is None and position < offset <= value_end:
            found = Cursor("value", tag, start, attribute=attribute.group(), value=text[position + 1:value_end],
                           value_start=position + 1, word_start=position + 1, word=text[position + 1:offset])
        if close < 0:
            break
        position = close + 1
    if found is None:
        return Cursor("text")
    return Cursor(found.kind, found.tag, found.tag_start, found.attribute, found.value, found.value_start,
                  found.word_start, found.word, frozenset(present))


def open_elements(text: str, before: int) -> list[str]:
    """The names of the elements open at offset ``before``, outermost first (a forgiving walk:
    a stray end tag closes the nearest element of its name, comments and CDATA are skipped)."""
    stack: list[str] = []
    for match in _MARKUP.finditer(text, 0, before):
        name = match.group(2)
        if not name:
            continue
        if match.group(1):
            if name in stack:
                del stack[len(stack) - 1 - stack[::-1].index(name):]
        elif not match.group(3):
            stack.append(name)
    return stack


def identifier_at(text: str, offset: int) -> str | None:
    """The identifier (``[A-Za-z_][A-Za-z0-9_]*``) the cursor is on, if any."""
    line_start = text.rfind("\n", 0, offset) + 1
    line_end = text.find("\n", offset)
    line_end = len(text) if line_end < 0 else line_end
    for match in _IDENTIFIER.finditer(text, line_start, line_end):
        if match.start() <= offset <= match.end():
            return match.group()
    return None


def expression_at(text: str, offset: int) -> tuple[str, int] | None:
    """The ``${...}`` or ``$(...)`` substitution around ``offset`` on its line: (its text, its start)."""
    line_start = text.rfind("\n", 0, offset) + 1
    line_end = text.find("\n", offset)
    line_end = len(text) if line_end < 0 else line_end
    for match in re.finditer(r"\$\{[^}]*\}?|\$\([^)]*\)?", text[line_start:line_end]):
        if match.start() <= offset - line_start <= match.end():
            return match.group(), line_start + match.start()
    return None
