"""Read robot description bytes safely and tolerate the mess real files contain.

Real URDF files are messy: 26 of pybullet_data's models declare ``<?xml version="0.0"?>``,
CAD exporters leave blank lines before the declaration or NUL bytes after the root, Windows
editors add a BOM and CRLF line endings. A strict parser refuses several of these; ar3cli loads
them anyway and records each oddity as a :class:`Quirk`, so the linter can report it while every
other command just works.

What is never tolerated: entity declarations. libxml2 expands *internal* entities even with
``resolve_entities=False`` (a "billion laughs" file still explodes), and URDF never needs them,
so any ``<!ENTITY`` is refused before parsing. DTDs are not loaded and the network is never used.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from ar3cli.errors import UserError
from ar3cli.findings import listed

_DECLARATION = re.compile(rb"<\?xml[^>]*\?>")
_VERSION_ATTR = re.compile(rb"""version\s*=\s*(["'])([^"']*)\1""")
_ENCODING_ATTR = re.compile(rb"""encoding\s*=\s*(["'])([^"']*)\1""")
_ENTITY_DECLARATION = re.compile(rb"<!ENTITY", re.IGNORECASE)
_BOM = b"\xef\xbb\xbf"


@dataclass(frozen=True)
class Quirk:
    """Something odd about a file that ar3cli worked around while loading it.

    ``code`` is stable (``version-0.0``, ``leading-junk``, ``trailing-junk``, ``bom``, ``crlf``,
    ``non-utf8-encoding``) so lint rules can map each quirk to a finding.
    """

    code: str
    message: str
    line: int = 1


def refuse_entities(data: bytes, path: Path) -> None:
    """Refuse entity declarations: they are the vector of entity bombs and external-file leaks."""
    match = _ENTITY_DECLARATION.search(data)
    if match:
        line = data.count(b"\n", 0, match.start()) + 1
        raise UserError(
            f"{path}:{line}: declares an XML entity (<!ENTITY>); entities are refused because they "
            "can expand without bound or read other files. Remove the DOCTYPE."
        )


def normalize(data: bytes) -> tuple[bytes, list[Quirk]]:
    """Return bytes a strict XML parser accepts, with the line of every element unchanged.

    Only the quirks listed in :class:`Quirk` are handled here; junk after the root element is
    handled by :func:`parse` because only the parser knows where the root ends.
    """
    quirks: list[Quirk] = []
    if data.startswith(_BOM):
        quirks.append(Quirk("bom", "file starts with a UTF-8 byte order mark"))
        data = data[len(_BOM):]
    if b"\r\n" in data:
        quirks.append(Quirk("crlf", "file uses CRLF (Windows) line endings"))
    if b"\x00" in data:
        # A NUL is never valid XML. CAD exporters pad files with them after the root; elsewhere
        # the parser will still refuse the file with its own line number.
        stripped = data.rstrip(b"\x00\r\n\t ")
        if b"\x00" not in stripped:
            quirks.append(Quirk("trailing-junk", "NUL bytes after the root element", stripped.count(b"\n") + 1))
            data = stripped + b"\n"
    declaration = _DECLARATION.search(data)
    if declaration and declaration.start() > 0 and not data[: declaration.start()].strip():
        # Blank lines before the declaration: swap them behind it so every later line keeps its number.
        leading = data[: declaration.start()]
        quirks.append(Quirk("leading-junk", "blank lines before the XML declaration", 1))
        data = declaration.group(0) + leading + data[declaration.end():]
        declaration = _DECLARATION.match(data)
    if declaration and declaration.start() == 0:
        text = declaration.group(0)
        version = _VERSION_ATTR.search(text)
        if version and version.group(2) != b"1.0":
            quirks.append(
                Quirk("version-" + version.group(2).decode("ascii", "replace"),
                      f'XML declaration says version="{version.group(2).decode("ascii", "replace")}"; '
                      'strict parsers only accept "1.0"')
            )
            fixed = text[: version.start(2)] + b"1.0" + text[version.end(2):]
            data = fixed + data[declaration.end():]
        encoding = _ENCODING_ATTR.search(text)
        if encoding and encoding.group(2).lower().replace(b"_", b"-") not in (b"utf-8", b"utf8", b"ascii", b"us-ascii"):
            quirks.append(Quirk("non-utf8-encoding",
                                f"file is encoded as {encoding.group(2).decode('ascii', 'replace')}, not UTF-8"))
    return data, quirks


def parse(data: bytes, path: Path):
    """Parse normalised bytes into an lxml element tree; errors become ``path:line: reason``.

    Returns ``(root, quirks)``; quirks holds ``trailing-junk`` when content after the root
    element had to be cut off.
    """
    from lxml import etree

    parser = etree.XMLParser(
        resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False, remove_blank_text=False
    )
    quirks: list[Quirk] = []
    data = _declare_undeclared_prefixes(data, quirks)
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        cut = _end_of_root(data, exc)
        if cut is None:
            raise _syntax_error(path, exc) from None
        quirks.append(Quirk("trailing-junk", "content after the root element", exc.lineno or 1))
        try:
            root = etree.fromstring(data[:cut], parser)
        except etree.XMLSyntaxError as again:
            raise _syntax_error(path, again) from None
    except ValueError as exc:  # e.g. unknown encoding declared
        raise UserError(f"{path}: cannot decode: {exc}") from None
    return root, quirks


_PREFIXED_TAG = re.compile(rb"<([A-Za-z_][\w.-]*):[A-Za-z_]")
_PREFIXED_ATTRIBUTE = re.compile(rb""":[A-Za-z_][\w.-]*\s*=\s*["']""")
"""The ``:name="`` of a prefixed attribute; starting at the colon lets the regex engine skip to each
``:`` (rare outside URIs, which this does not match) instead of trying every whitespace."""
_PREFIX_BEFORE = re.compile(rb"\s([A-Za-z_][\w.-]*)$")
_DECLARED = re.compile(rb"""xmlns:([A-Za-z_][\w.-]*)\s*=""")
_ROOT_TAG = re.compile(rb"<robot\b")
UNDECLARED_NAMESPACE = "urn:ar3cli:undeclared:"
"""Namespace given to a prefix the file uses without declaring it (``drake:``, ``gazebo:``)."""


def _declare_undeclared_prefixes(data: bytes, quirks: list[Quirk]) -> bytes:
    """Declare on ``<robot>`` the element and attribute prefixes the file uses without an ``xmlns:``
    for them.

    Drake's URDFs write ``<drake:proximity_properties>`` and ``<limit drake:acceleration="2.5"/>``
    with no declaration: XML namespaces make that "not well-formed", yet PyBullet and urdfdom read
    the file (they ignore namespaces). The prefix is declared in the parsed copy only (quirk
    ``undeclared-prefix`` at the first use, lint's F005 warns); the source bytes and every line
    number stay as they are.
    """
    first_use: dict[bytes, int] = {}
    quoted = _unparsed_spans(data)
    for match in _PREFIXED_TAG.finditer(data):
        if not _inside(quoted, match.start()):  # <!-- <xacro:stairs .../> --> declares nothing and needs nothing
            first_use.setdefault(match.group(1), match.start())
    for match in _PREFIXED_ATTRIBUTE.finditer(data):
        before = _PREFIX_BEFORE.search(data, max(0, match.start() - 200), match.start())
        if before and _inside_a_tag(data, match.start()) and not _inside(quoted, match.start()):
            prefix, start = before.group(1), before.start(1)
            first_use[prefix] = min(first_use.get(prefix, start), start)
    declared = set(_DECLARED.findall(data)) | {b"xml", b"xmlns"}
    missing = sorted(set(first_use) - declared)
    root = _ROOT_TAG.search(data)
    if not missing or root is None:
        return data
    names = listed(prefix.decode("ascii", "replace") for prefix in missing)
    line = data.count(b"\n", 0, min(first_use[prefix] for prefix in missing)) + 1
    quirks.append(Quirk("undeclared-prefix", f"namespace prefix {names} is used but never declared (xmlns:...): "
                                             "PyBullet and urdfdom read the file, namespace-aware XML tools "
                                             "(lxml, ROS 2 launch, xacro) refuse it", line))
    declarations = b"".join(b" xmlns:" + prefix + b'="' + UNDECLARED_NAMESPACE.encode() + prefix + b'"'
                            for prefix in missing)
    return data[:root.end()] + declarations + data[root.end():]


def source_lines(quirks: list[Quirk], source: bytes) -> list[Quirk]:
    """The quirks found parsing a xacro file's expansion, at lines of its source: an undeclared prefix at
    its first use in the source (or line 0 when only an included file uses it), any other at line 0 (the
    expansion's line numbers are not the file's: ridgeback.urdf.xacro's 393 of a 332-line file)."""
    placed = []
    for quirk in quirks:
        line = 0
        if quirk.code == "undeclared-prefix":
            found: list[Quirk] = []
            _declare_undeclared_prefixes(normalize(source)[0], found)
            line = found[0].line if found else 0
        placed.append(Quirk(quirk.code, quirk.message, line))
    return placed


_UNPARSED = ((b"<!--", b"-->"), (b"<![CDATA[", b"]]>"))
"""Where XML text is not markup: comments and CDATA sections."""


def _unparsed_spans(data: bytes) -> list[tuple[int, int]]:
    """(start, end) byte offsets of the comments and CDATA sections, in order (an unclosed one runs to
    the end: the parser reports it). Linear: each opening is searched for again only once passed."""
    spans: list[tuple[int, int]] = []
    upcoming = {opening: data.find(opening) for opening, _closing in _UNPARSED}
    position = 0
    while True:
        for opening, at in upcoming.items():
            if 0 <= at < position:
                upcoming[opening] = data.find(opening, position)
        found = [(at, opening, closing) for opening, closing in _UNPARSED if (at := upcoming[opening]) >= 0]
        if not found:
            return spans
        start, opening, closing = min(found)
        end = data.find(closing, start + len(opening))
        end = len(data) if end < 0 else end + len(closing)
        spans.append((start, end))
        position = end


def _inside(spans: list[tuple[int, int]], offset: int) -> bool:
    """Whether ``offset`` lies in one of the sorted, disjoint ``spans``."""
    import bisect

    index = bisect.bisect_right(spans, (offset, float("inf"))) - 1
    return index >= 0 and offset < spans[index][1]


def _inside_a_tag(data: bytes, offset: int) -> bool:
    """Whether ``offset`` is inside a start tag (``<name ...``), not in text, a comment or a
    processing instruction: the last ``<`` before it comes after the last ``>`` and opens an element."""
    opening = data.rfind(b"<", 0, offset)
    return opening > data.rfind(b">", 0, offset) and data[opening + 1:opening + 2].isalpha()


def _end_of_root(data: bytes, exc) -> int | None:
    """Byte offset where the root element ends, when the parser complained about extra content."""
    if "Extra content at the end of the document" not in str(exc):
        return None
    lines = data.split(b"\n")
    line, column = exc.position
    if not 1 <= line <= len(lines):
        return None
    return sum(len(chunk) + 1 for chunk in lines[: line - 1]) + max(column - 1, 0)


def _syntax_error(path: Path, exc) -> UserError:
    line = exc.lineno or 0
    message = str(exc.msg if hasattr(exc, "msg") else exc)
    message = re.sub(r",? line \d+, column \d+.*$", "", message)
    where = f"{path}:{line}" if line else str(path)
    return UserError(f"{where}: not well-formed XML: {message}")


def decode_text(data: bytes) -> str:
    """Best-effort text of the file, for line-based checks (suppression comments, columns)."""
    for encoding in ("utf-8", "latin-1"):
        try:
            return data.decode(encoding)
        except UnicodeDecodeError:
            continue
    return data.decode("utf-8", "replace")  # pragma: no cover - latin-1 always decodes
