"""A keystroke applied to a loaded model: the new text's model without parsing the file again.

An editor sends a new buffer on every keystroke, and nearly every keystroke changes one attribute
value of one element (``upper="1.57"`` -> ``upper="1.5"``). :func:`edited` recognises exactly that
case in the bytes and answers with the model of the new text built from the earlier one: the
attribute is set on the element the earlier parse made, the one ``<link>`` or ``<joint>`` holding
it is read again, and every other element, link, joint, shape and child list is the same object as
before. That is what a parse of the new text would give (the same tree, the same source lines:
the edit adds no line), for a fraction of its cost, and it lets the next check reuse what it knew
about the objects the edit did not touch (:mod:`ar3cli.lint.reuse`).

Anything else is None, and the caller parses the new text as usual: an edit outside an attribute
value or spanning several, a value holding an entity reference, a tab or a line break (the parser
rewrites those), markup characters typed, an edit inside a comment, CDATA or processing
instruction, a file with a DOCTYPE or any load quirk (BOM, CRLF, junk, another encoding), an
element that cannot be told apart from another on its line, an attribute with a namespace, a mesh's
``filename`` (a full load resolves it with a fresh resolver, which does not keep every name typed on the
way), an element outside the robot's links and joints, and xacro files (the buffer is not what was parsed).
The earlier model is consumed: its tree now holds the new value, so it is never the base of
another edit (:attr:`Model.edited_away`; :attr:`Edit.model` is the base of the next).
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, replace
from typing import Any

from ar3cli.urdf.model import Joint, Link, Model, read_joint, read_link

_CHUNK = 4096
_START_TAG = re.compile(rb"<[A-Za-z_][\w.\-]*(?:\s+[^\s=/>\"'<]+\s*=\s*(?:\"[^\"<]*\"|'[^'<]*'))*\s*/?>")
_ATTRIBUTE = re.compile(rb"\s([^\s=/>\"'<]+)\s*=\s*(?:\"([^\"<]*)\"|'([^'<]*)')")
_NOT_IN_VALUE = frozenset(b"<>&\"'")
"""Bytes an edit may not type or delete: markup, an entity reference, a quote (control bytes neither)."""
_REWRITTEN_IN_VALUE = (b"&", b"\t", b"\n", b"\r")
"""What the parser does not keep as written in an attribute value (entities, whitespace turned to spaces)."""


@dataclass(frozen=True)
class Edit:
    """The model of a new text made from the earlier one, and what the edit touched."""

    model: Model
    item: Any
    """The ``<link>`` or ``<joint>`` element (a child of ``<robot>``) holding the edited attribute: the same
    element object in the earlier model and in :attr:`model`."""
    before: Link | Joint
    """The item's object in the earlier model (read before the edit)."""
    after: Link | Joint
    """The item's object in :attr:`model`."""


def edited(model: Model, source: bytes) -> Edit | None:
    """The model of ``source`` made from ``model`` when ``source`` differs from the model's text by one
    attribute value of one link or joint (the tree of ``model`` is changed in place, and ``model`` may not
    be edited again); None otherwise (``model`` untouched)."""
    if model.is_xacro or model.quirks or model.edited_away or model.xml_bytes != model.source_bytes:
        return None
    old = model.source_bytes
    if source == old or b"<!DOCTYPE" in source or b"<![CDATA[" in source or b"\r" in source or b"\x00" in source \
            or source.startswith(b"\xef\xbb\xbf"):
        return None
    start, old_end, new_end = _changed_span(old, source)
    if not (_plain(old[start:old_end]) and _plain(source[start:new_end])):
        return None
    place = _attribute_at(source, start, new_end)
    if place is None:
        return None
    tag, name, value_start, value_end, tag_end = place
    new_value = source[value_start:value_end]
    old_value = old[value_start:value_end - (new_end - old_end)]
    if any(mark in value for value in (old_value, new_value) for mark in _REWRITTEN_IN_VALUE):
        return None
    element = _element_at(model, source.count(b"\n", 0, tag_end) + 1, tag.decode("ascii"), name.decode("utf-8"),
                          old_value.decode("utf-8"))
    if element is None:
        return None
    item = element
    while item.getparent() is not None and item.getparent() is not model.root:
        item = item.getparent()
    kind = "links" if item.tag == "link" else "joints" if item.tag == "joint" else None
    if kind is None or item.getparent() is not model.root:
        return None
    objects = getattr(model, kind)
    index = next((i for i, thing in enumerate(objects) if thing.element is item), None)
    if index is None:
        return None
    element.set(name.decode("utf-8"), new_value.decode("utf-8"))
    model.edited_away = True
    read = model.read_children
    after = read_link(item, model.resolver, read) if kind == "links" else read_joint(item, read)
    changed = list(objects)
    changed[index] = after
    new_model = replace(model, source_bytes=source, xml_bytes=source, quirks=[], edited_away=False, **{kind: changed})
    return Edit(new_model, item, objects[index], after)


def _changed_span(old: bytes, new: bytes) -> tuple[int, int, int]:
    """(start, end in ``old``, end in ``new``) of the bytes that differ, widened to whole UTF-8 characters."""
    shorter = min(len(old), len(new))
    start = 0
    while start < shorter and old[start:start + _CHUNK] == new[start:start + _CHUNK]:
        start += _CHUNK
    while start < shorter and old[start] == new[start]:
        start += 1
    start = min(start, shorter)
    tail = 0
    room = shorter - start
    while tail + _CHUNK <= room and \
            old[len(old) - tail - _CHUNK:len(old) - tail] == new[len(new) - tail - _CHUNK:len(new) - tail]:
        tail += _CHUNK
    while tail < room and old[len(old) - tail - 1] == new[len(new) - tail - 1]:
        tail += 1
    old_end, new_end = len(old) - tail, len(new) - tail
    while start > 0 and any(start < len(text) and text[start] & 0xC0 == 0x80 for text in (old, new)):
        start -= 1  # back to the first byte of the character
    while old_end < len(old) and old[old_end] & 0xC0 == 0x80:
        old_end += 1
        new_end += 1
    return start, old_end, new_end


def _plain(data: bytes) -> bool:
    """Text an attribute value holds as written: UTF-8 of XML characters, no markup, quotes or control bytes."""
    if any(byte < 0x20 or byte in _NOT_IN_VALUE for byte in data):
        return False
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return "\ufffe" not in text and "\uffff" not in text


def _attribute_at(source: bytes, start: int, end: int) -> tuple[bytes, bytes, int, int, int] | None:
    """(tag name, attribute name, value start, value end, offset of the tag's ``>``) of the start tag whose
    attribute value holds ``source[start:end]``, or None (not in one value, or not in a start tag)."""
    opening = source.rfind(b"<", 0, start)
    closing = source.find(b">", end)
    if opening < 0 or closing < 0:
        return None
    if not _START_TAG.fullmatch(source, opening, closing + 1):
        return None
    comment = source.rfind(b"<!--", 0, opening)
    if comment >= 0 and source.find(b"-->", comment + 4, opening) < 0:
        return None  # inside a comment
    instruction = source.rfind(b"<?", 0, opening)
    if instruction >= 0 and source.find(b"?>", instruction + 2, opening) < 0:
        return None  # inside a processing instruction
    tag = re.match(rb"<([A-Za-z_][\w.\-]*)", source[opening:closing]).group(1)  # type: ignore[union-attr]
    found = None
    for match in _ATTRIBUTE.finditer(source, opening, closing + 1):
        group = 2 if match.group(2) is not None else 3
        if match.start(group) <= start and end <= match.end(group):
            found = (tag, match.group(1), match.start(group), match.end(group), closing)
    if found is None or b":" in found[1] or found[1] in (b"xmlns", b"filename"):
        return None  # a namespace; a mesh file name, which a full load resolves with a fresh resolver
    return found


def _element_at(model: Model, line: int, tag: str, name: str, value: str) -> Any:
    """The one element of ``model`` whose start tag ends on ``line`` (lxml's source line) with ``tag`` and
    ``name="value"``, or None when there is none or more than one."""
    items = [child for child in model.root if isinstance(child.tag, str)]
    lines = [child.sourceline or 0 for child in items]
    last = bisect.bisect_right(lines, line) - 1
    if last < 0:
        return None
    first = last
    while first > 0 and lines[first] >= line:
        first -= 1
    found = [element for item in items[first:last + 1] for element in item.iter(tag)
             if element.sourceline == line and element.get(name) == value]
    return found[0] if len(found) == 1 else None
