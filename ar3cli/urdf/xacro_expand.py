"""Expand ``.xacro`` files in-process with the ``xacro`` package.

No ROS installation is needed: ``$(find NAME)`` is answered by the same
:class:`~ar3cli.urdf.packages.PackageResolver` that resolves ``package://`` URIs, and ``$(arg ...)``
values come from ``--xacro-arg NAME:=VALUE``. Whatever goes wrong inside xacro becomes a one-line
:class:`~ar3cli.errors.UserError` naming the file.

Each element of the expanded URDF remembers where it was written: xacro's parser is wrapped so that
every element it reads from the top file or an included file gets its file, line and column
(expat's). An element xacro may copy (inside a macro body or a block) carries them through the copy
as an ``ar3cli-origin`` attribute, so an element a macro produced points at the macro's file and
line; the attributes are taken off before the text is written, so the URDF is byte for byte what
xacro alone writes. :func:`origins` gives the linter each element's origin, in document order.
"""

from __future__ import annotations

import contextlib
import io
import os
from pathlib import Path
from typing import NamedTuple

from ar3cli.errors import UserError
from ar3cli.output.report import log
from ar3cli.urdf.packages import PackageResolver


def is_xacro(path: Path) -> bool:
    """True for ``robot.xacro`` and ``robot.urdf.xacro``."""
    return path.suffix.lower() == ".xacro"


def parse_xacro_args(items: list[str] | None) -> dict[str, str]:
    """Turn repeated ``NAME:=VALUE`` options into a mapping; raises ValueError when malformed."""
    mapping: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition(":=")
        if not sep or not name.strip():
            raise ValueError(f"--xacro-arg expects NAME:=VALUE, got {item!r}")
        mapping[name.strip()] = value
    return mapping


class Origin(NamedTuple):
    """Where an element of the expanded URDF was written: the xacro file as xacro named it
    (relative to the current directory, or absolute), 1-based line and column of its start tag."""

    file: str
    line: int
    column: int


ORIGIN_ATTRIBUTE = "ar3cli-origin"
"""The attribute that carries an element's origin through xacro (taken off before the output)."""
_KEEP_ORIGINS = 4
"""Expansions whose origins are kept: a file is linted right after it is expanded."""
_origins: dict[bytes, list[Origin | None]] = {}


def origins(xml_bytes: bytes) -> list[Origin | None] | None:
    """The origin of each element of an expansion :func:`expand` returned, in document order
    (None for an element xacro made itself, such as ``xacro:element``); None for other bytes."""
    return _origins.get(xml_bytes)


def expand(path: Path, args: dict[str, str], resolver: PackageResolver) -> bytes:
    """Return the expanded URDF as UTF-8 bytes (and keep its elements' :func:`origins`).

    xacro keeps module-level state and prints diagnostics with ``print``; both are contained
    here: its ``$(find)`` hook and its ``parse`` are swapped for ours for the duration of the call,
    and anything it prints is kept off stdout (stdout may be carrying JSON).
    """
    import xacro
    from xacro import substitution_args

    not_found: list[UserError] = []  # xacro wraps what the hook raises; keep ours to re-raise it as is

    def find_package(name: str) -> str:
        folder, tried = resolver.find_package(name)
        if folder is None:
            not_found.append(UserError(f"{path}: $(find {name}): package not found; tried {', '.join(tried)}; "
                                       f"pass --package-path {name}=DIR"))
            raise not_found[-1]
        return str(folder)

    table: list[Origin] = []
    kept: dict = {}
    original_find, original_parse = substitution_args._eval_find, xacro.parse
    substitution_args._eval_find = find_package
    xacro.parse = _parse_with_origins(original_parse, table, kept)
    chatter = io.StringIO()
    try:
        with contextlib.redirect_stdout(chatter), contextlib.redirect_stderr(chatter):
            document = xacro.process_file(str(path), mappings=dict(args))
            found = _take_origins(document, table, kept)
            text = document.toprettyxml(indent="  ")
    except UserError:
        raise
    except Exception as exc:  # noqa: BLE001 - xacro raises many types: XacroException, NameError, XML errors...
        if not_found:
            raise not_found[-1] from None
        if isinstance(exc, RecursionError):
            raise UserError(f"{path}: xacro error: macro recursion too deep") from None
        raise UserError(f"{path}: xacro error: {_one_line(exc)}") from None
    finally:
        substitution_args._eval_find = original_find
        xacro.parse = original_parse
    for line in chatter.getvalue().splitlines():
        if line.strip() and not line.startswith("when processing file:"):
            log(f"ar3cli: note: {path}: xacro says: {line.strip()}")
    data = text.encode("utf-8")
    while len(_origins) >= _KEEP_ORIGINS:
        del _origins[next(iter(_origins))]
    _origins[data] = found
    return data


def _parse_with_origins(original_parse, table: list[Origin], kept: dict):
    """xacro's ``parse(inp, filename)``, noting the origin of each element read from a file.

    The file is read as xacro reads it (text, default encoding) and parsed by the builder
    ``xml.dom.minidom.parse`` uses, so the document and every error are the same. An element inside
    a xacro element (a macro body, a block passed to a macro, a property's block) may be copied by
    xacro, so it carries its origin as an attribute (its index in ``table``); every other element
    stays the same node up to the output, and ``kept`` maps it to its origin (no attribute for
    xacro to evaluate: 3 ms less on the AR3). xacro's own elements are left alone (xacro checks
    their attributes); inside ``xacro:if``/``xacro:unless`` nodes are moved, never copied.
    """
    from xml.dom import expatbuilder

    class Builder(expatbuilder.ExpatBuilderNS):
        def __init__(self, file: str) -> None:
            super().__init__()
            self.file = file
            self.copied = 0  # depth inside xacro elements whose content xacro may copy
            self.copying: list[bool] = []

        def start_element_handler(self, name, attributes):
            # name is "URI LOCALNAME PREFIX" for a prefixed element
            if name.endswith(" xacro"):
                super().start_element_handler(name, attributes)
                copies = name.split(" ")[1] not in ("if", "unless")
            else:
                parser = self._parser
                origin = Origin(self.file, parser.CurrentLineNumber, parser.CurrentColumnNumber + 1)
                if self.copied:
                    attributes.append(ORIGIN_ATTRIBUTE)  # expat's flat list of names and values
                    attributes.append(str(len(table)))
                    table.append(origin)
                    super().start_element_handler(name, attributes)
                else:
                    super().start_element_handler(name, attributes)
                    kept[self.curNode] = origin
                copies = False
            self.copying.append(copies)
            self.copied += copies

        def end_element_handler(self, name):
            self.copied -= self.copying.pop()
            super().end_element_handler(name)

    def parse(inp, filename=None):
        import xacro

        if inp is not None or filename is None:
            return original_parse(inp, filename)
        try:
            with open(os.path.join(getattr(xacro, "root_dir", os.curdir), filename)) as handle:
                text = handle.read()
        except OSError:
            return original_parse(inp, filename)  # raises xacro's own error, with its file stack
        return Builder(str(filename)).parseString(text)

    return parse


def _take_origins(document, table: list[Origin], kept: dict) -> list[Origin | None]:
    """Each element's origin in document order; the origin attributes are removed from the document."""
    found: list[Origin | None] = []
    stack = [document.documentElement] if document.documentElement is not None else []
    while stack:
        node = stack.pop()
        origin = kept.get(node)
        if origin is None:
            attribute = node.getAttributeNode(ORIGIN_ATTRIBUTE)
            if attribute is not None:
                node.removeAttributeNode(attribute)
                index = attribute.value
                origin = table[int(index)] if index.isdigit() and int(index) < len(table) else None
        found.append(origin)
        stack.extend(reversed([child for child in node.childNodes if child.nodeType == 1]))  # ELEMENT_NODE
    return found


def _one_line(exc: BaseException) -> str:
    inner = getattr(exc, "exc", None)  # XacroException wraps the real error and repeats its text
    if isinstance(inner, OSError) and inner.filename:
        message = f"cannot read {inner.filename}: {inner.strerror or inner}"
    else:
        message = " ".join(str(exc).split()) or type(exc).__name__
    location = _xacro_location()
    return f"{message} (in {location})" if location else message


def _xacro_location() -> str:
    """The innermost file xacro was reading when it failed, when xacro recorded one."""
    try:
        import xacro

        stack = [entry for entry in getattr(xacro, "filestack", None) or [] if entry]
    except Exception:  # noqa: BLE001 - defensive: xacro internals differ between versions
        return ""
    return str(stack[-1]) if stack else ""
