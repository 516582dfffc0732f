"""A keystroke applied to a loaded model: the new text's model, sharing every object the edit did not touch.

An editor sends a new buffer on every keystroke, and nearly every keystroke changes one attribute value
(``upper="1.57"`` -> ``upper="1.5"``), a line break or an indent, or one element's content. :func:`edited`
makes the model of the new text from the earlier one, in one of two ways:

- **One attribute value** of one element inside a ``<link>`` or ``<joint>`` (found in the bytes, no parse):
  the attribute is set on the element the earlier parse made and that link or joint is read again.
- **The same elements** (a line added or removed, an indent, values or comments changed anywhere inside
  the items, several of them): the new text is parsed, and when its tree has the same nodes with the same
  tags as the earlier one and ``<robot>`` keeps its attributes, the new source lines, texts and attributes
  are copied into the earlier tree, and the links and joints whose content changed are read again.

Either way every other element, link, joint, shape and child list stays the same object, and the model is
the one a load of the new text gives (the same tree, source lines, links and joints): that is what lets the
next check reuse what it knew about the objects the edit did not touch (:mod:`ar3cli.lint.reuse`).

Anything else is None, and the caller loads the new text as usual: a new, removed or renamed element, a
change of ``<robot>``'s attributes, a mesh's ``filename`` (a full load resolves it with a fresh resolver,
which does not keep every name typed on the way), a namespace declared or changed below ``<robot>``, a
processing instruction in a changed item, a DOCTYPE, CDATA or any load quirk (BOM, CRLF, junk, another
encoding, an undeclared prefix), a text that does not parse, and xacro files (the buffer is not what was
parsed). The earlier model is consumed: its tree now holds the new text, so it is never the base of
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
_REWRITTEN_IN_VALUE = (b"&", b"\t", b"\n", b"\r", b":")
"""What the parser, or the load, does not keep as written in an attribute value: entities, whitespace turned
to spaces, and a colon (``a:b=`` in a value makes the load declare the prefix ``a``: an F005 quirk)."""
_LONGEST_VALUE = 1 << 20
"""Bytes of the longest value set without a parse: libxml2 refuses one over 10,000,000 (no ``huge_tree``)."""
_DECLARED_ENCODING = re.compile(rb"\A\s*<\?xml[^>]*?\bencoding\s*=\s*[\"']([^\"']*)")


@dataclass(frozen=True)
class Edit:
    """The model of a new text made from the earlier one, and what the edit touched."""

    model: Model
    items: tuple[Any, ...]
    """The children of ``<robot>`` (links, joints, materials, comments...) whose content changed: the same
    element objects in the earlier model and in :attr:`model`. Empty for a line break or an indent."""
    before: tuple[Link | Joint, ...]
    """The changed links' and joints' objects in the earlier model."""
    after: tuple[Link | Joint, ...]
    """Their objects in :attr:`model`, read again."""


def edited(model: Model, source: bytes) -> Edit | None:
    """The model of ``source`` made from ``model`` (whose tree changes in place, and which may not be edited
    again) when the edit is one this module takes; None otherwise, ``model`` untouched."""
    if model.is_xacro or model.quirks or model.edited_away or model.xml_bytes != model.source_bytes:
        return None
    if source == model.source_bytes or b"<!DOCTYPE" in source or b"<![CDATA[" in source or b"\r" in source \
            or b"\x00" in source or source.startswith(b"\xef\xbb\xbf"):
        return None
    span = _changed_span(model.source_bytes, source)
    found = _one_value(model, source, span)
    if found is None:
        found = _same_elements(model, source, span)
    if found is None:
        return None
    changed, objects = found
    before, after, kinds = [], [], {"link": list(model.links), "joint": list(model.joints)}
    for item in changed:
        objects_of_kind = kinds.get(item.tag)
        index = objects.get(id(item))
        if objects_of_kind is None or index is None:
            continue
        before.append(objects_of_kind[index])
        objects_of_kind[index] = read_link(item, model.resolver, model.read_children) if item.tag == "link" \
            else read_joint(item, model.read_children)
        after.append(objects_of_kind[index])
    new_model = replace(model, source_bytes=source, xml_bytes=source, quirks=[], edited_away=False,
                        links=kinds["link"], joints=kinds["joint"])
    return Edit(new_model, tuple(changed), tuple(before), tuple(after))


Span = tuple[int, int, int]
"""(start, end in the earlier text, end in the new text) of the bytes an edit changed (:func:`_changed_span`)."""
Found = tuple[list[Any], dict[int, int]]
"""(the changed children of ``<robot>``, and id of each link or joint element -> its index in its list)."""


def _indexes(model: Model) -> dict[int, int]:
    return {id(thing.element): index for things in (model.links, model.joints) for index, thing in enumerate(things)}


def item_of(element: Any, root: Any) -> Any:
    """The child of ``root`` that holds ``element`` (or is it), or None (``root`` itself, no element, another tree)."""
    if element is None:
        return None
    parent = element.getparent()
    while parent is not None and parent is not root:
        element, parent = parent, parent.getparent()
    return element if parent is root else None


def _one_value(model: Model, source: bytes, span: Span) -> Found | None:
    """One attribute value of one element inside a link or joint changed: set it (the tree is changed only
    when this answers)."""
    old = model.source_bytes
    declared = _DECLARED_ENCODING.match(source)
    if declared and declared.group(1).lower() not in (b"utf-8", b"utf8"):
        return None  # a character the declared encoding lacks is the parser's to refuse (us-ascii)
    start, old_end, new_end = span
    if not (_plain(old[start:old_end]) and _plain(source[start:new_end])):
        return None
    place = _attribute_at(source, start, new_end)
    if place is None:
        return None
    tag, name, value_start, value_end, tag_end = place
    new_value = source[value_start:value_end]
    old_value = old[value_start:value_end - (new_end - old_end)]
    if len(new_value) > _LONGEST_VALUE or any(mark in value for value in (old_value, new_value)
                                              for mark in _REWRITTEN_IN_VALUE):
        return None
    element = _element_at(model, source.count(b"\n", 0, tag_end) + 1, tag.decode("ascii"), name.decode("utf-8"),
                          old_value.decode("utf-8"))
    if element is None:
        return None
    item = item_of(element, model.root)
    objects = _indexes(model)
    if id(item) not in objects:
        return None
    model.edited_away = True  # before the tree changes: a reader on another thread sees it is not its text
    element.set(name.decode("utf-8"), new_value.decode("utf-8"))
    return [item], objects


def _same_elements(model: Model, source: bytes, span: Span) -> Found | None:
    """The new text's tree has the earlier one's nodes and tags: copy its source lines, and the texts and
    attributes of the items whose content changed, into the earlier tree (changed only when this answers).

    Only the bytes between the common start and the common end of the two texts changed, so a child of
    ``<robot>`` wholly before them is the same and one wholly after them the same, moved by the lines the
    edit added; only the few children whose lines reach the changed ones are compared node by node."""
    from lxml import etree

    from ar3cli.errors import UserError
    from ar3cli.urdf import xmlsource

    try:
        normalized, quirks = xmlsource.normalize(source)
        xmlsource.refuse_entities(source, model.path)
        root, parse_quirks = xmlsource.parse(normalized, model.path)
    except (UserError, RecursionError):
        return None
    old_root, old = model.root, model.source_bytes
    if quirks or parse_quirks or normalized != source or root.tag != old_root.tag or root.nsmap != old_root.nsmap \
            or list(root.items()) != list(old_root.items()) or _outside(old_root) != _outside(root):
        return None  # <robot>'s attributes, or a comment before or after it, changed
    old_items, new_items = list(old_root), list(root)
    if len(old_items) != len(new_items) or any(a.tag != b.tag for a, b in zip(old_items, new_items)):
        return None
    start, old_end, new_end = span
    first, last = old.count(b"\n", 0, start) + 1, old.count(b"\n", 0, old_end) + 1
    shift = source.count(b"\n", start, new_end) - (last - first)
    lines = [old_root.sourceline or 0, *(item.sourceline or 0 for item in old_items), float("inf")]
    compared, moved = [], []
    for index, (old_item, new_item) in enumerate(zip(old_items, new_items)):
        if lines[index + 2] < first:
            continue  # wholly before the edit: the same
        if lines[index] > last:
            moved.append(old_item)  # wholly after: the same, moved down or up
            continue
        old_nodes, new_nodes = list(old_item.iter()), list(new_item.iter())
        pairs = list(zip(old_nodes, new_nodes))
        if len(old_nodes) != len(new_nodes) or any(a.tag != b.tag or a.nsmap != b.nsmap for a, b in pairs):
            return None
        content = etree.tostring(old_item, with_tail=False) != etree.tostring(new_item, with_tail=False)
        if content and (any(isinstance(a, etree._ProcessingInstruction) for a, _b in pairs)
                        or [a.get("filename") for a in old_item.iter("mesh")] !=
                        [b.get("filename") for b in new_item.iter("mesh")]):
            return None
        compared.append((old_item, new_item, pairs, content))
    model.edited_away = True  # before the tree changes: a reader on another thread sees it is not its text
    old_root.sourceline, old_root.text = root.sourceline, root.text
    if shift:
        for item in moved:
            for node in item.iter():
                node.sourceline += shift
    for old_item, new_item, pairs, content in compared:
        old_item.tail = new_item.tail
        for a, b in pairs:
            a.sourceline = b.sourceline
            if content:
                a.text, a.tail = b.text, b.tail
                if isinstance(a.tag, str) and list(a.items()) != list(b.items()):
                    a.attrib.clear()
                    for key, value in b.items():
                        a.set(key, value)
    return [old_item for old_item, _new, _pairs, content in compared if content], _indexes(model)


def _outside(root: Any) -> list[bytes]:
    """The nodes before and after ``<robot>`` (comments, processing instructions), serialised."""
    from lxml import etree

    return [etree.tostring(node) if node is not None else b"<robot/>"  # where <robot> is
            for node in (*root.itersiblings(preceding=True), None, *root.itersiblings())]


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
    if model.root.tag == tag and model.root.sourceline == line and model.root.get(name) == value:
        found.append(model.root)  # <robot>'s own start tag: never taken for an element that looks the same
    return found[0] if len(found) == 1 else None
