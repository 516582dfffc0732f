"""A xacro file that is a library, not a robot: it defines macros (or properties, or materials) and
instantiates nothing.

A ``*_description/urdf/`` folder holds one entry file and many such libraries (``leg.xacro``,
``utils/*.xacro``, ``materials.xacro``). Linting the folder (pre-commit's ``files: \\.(urdf|xacro)$``, the
Action's ``paths: .``, ``scan``) must not call each one a broken robot (no name, no links): it is checked
where the entry file uses it. :func:`macro_library` recognises one from its source, and names the files
next to it that include it, where that is cheap to find.
"""

from __future__ import annotations

import fnmatch
import os
import re
from dataclasses import dataclass
from pathlib import Path

from ar3cli.errors import UserError
from ar3cli.infra.safe_read import read_bytes
from ar3cli.urdf import xmlsource

DEFINITIONS = frozenset({"macro", "property", "arg", "include"})
"""xacro elements that define something and make no robot element themselves."""
CONDITIONALS = frozenset({"if", "unless"})
"""xacro elements whose children count as if written in their place."""
LEGACY_DEFINITIONS = frozenset({"property", "macro"})
"""xacro definitions written without the namespace prefix, as xacro before ROS Jade read them: no URDF element
has these names, so a top-level <property> is a library's, not a robot's."""
LIBRARY_URDF_ELEMENTS = frozenset({"material"})
"""URDF elements a library may hold at the top level (a materials.xacro)."""
MAX_CANDIDATES = 400
"""Robot files looked into for the one that includes a library: a package of thousands of files is not
read through for a hint."""
MAX_CANDIDATE_BYTES = 4 * 1024 * 1024
"""A candidate entry file larger than this is not read for the hint."""
MAX_LEVELS = 3
"""Folders above the library's where its package.xml is looked for (``urdf/legs/leg.xacro``)."""
INCLUDE_FILENAME = re.compile(rb"""<(?:xacro:)?include\b[^>]*?\bfilename\s*=\s*(["'])(.*?)\1""", re.DOTALL)
"""An include's filename attribute (xacro's, or the pre-namespace ``<include>``)."""
MAX_FOLDERS = 200
"""Folders of the package walked for the hint."""


@dataclass(frozen=True)
class MacroLibrary:
    """What a xacro library defines, and the files found to include it (display paths, at most a few)."""

    macros: tuple[str, ...]
    properties: int
    materials: int
    included_by: tuple[str, ...] = ()

    def describe(self) -> str:
        """"defines 3 xacro macros (leg, foot, hip) and 2 properties" for messages."""
        parts = []
        if self.macros:
            shown = ", ".join(self.macros[:3]) + (", ..." if len(self.macros) > 3 else "")
            parts.append(f"{len(self.macros)} xacro macro{'s' if len(self.macros) != 1 else ''} ({shown})")
        if self.properties:
            parts.append(f"{self.properties} propert{'ies' if self.properties != 1 else 'y'}")
        if self.materials:
            parts.append(f"{self.materials} material{'s' if self.materials != 1 else ''}")
        return "defines " + " and ".join(parts)


def _is_xacro(tag) -> tuple[bool, str]:
    """(whether ``tag`` is in a xacro namespace, its local name)."""
    if not isinstance(tag, str) or not tag.startswith("{"):
        return False, tag if isinstance(tag, str) else ""
    uri, _, local = tag[1:].partition("}")
    return "xacro" in uri, local


def macro_library(model, find_includers: bool = True) -> MacroLibrary | None:
    """The :class:`MacroLibrary` ``model``'s file is, or None when it makes (or tries to make) a robot.

    A library makes no link and no joint, and its source's top level holds only xacro definitions
    (``macro``, ``property``, ``arg``, ``include``, also inside ``if``/``unless``) and ``<material>``s, at
    least one macro, property or material, and no macro call: a file that calls a macro and gets
    nothing out of it is a robot whose expansion went wrong, and is linted as one. ``find_includers``
    looks for the files that include it (:func:`includers`)."""
    if model.links or model.joints:
        return None
    if not model.is_xacro:
        return library_in_root(model.root, model.path, find_includers)
    return library_in_source(model.source_bytes, model.path, find_includers)


def library_in_source(source: bytes, path: Path, find_includers: bool = True) -> MacroLibrary | None:
    """:func:`macro_library` from a xacro file's source alone, for a file whose expansion failed (a library
    that includes ``$(find pkg)/...``, which only its includer's workspace resolves)."""
    try:
        root, _ = xmlsource.parse(xmlsource.normalize(source)[0], path)
    except UserError:
        return None
    return library_in_root(root, path, find_includers)


def library_in_root(root, path: Path, find_includers: bool = True) -> MacroLibrary | None:
    """:func:`macro_library` from the parsed source's root element."""
    macros: list[str] = []
    counts = {"property": 0, "material": 0}
    stack = [child for child in root if isinstance(child.tag, str)]
    while stack:
        element = stack.pop()
        xacro, local = _is_xacro(element.tag)
        if not xacro and local in LEGACY_DEFINITIONS:
            xacro = True  # pre-namespace xacro: <property name="pi" .../> (rtb-data's KUKA macros)
        if xacro and local in CONDITIONALS:
            stack.extend(child for child in element if isinstance(child.tag, str))
        elif xacro and local == "macro":
            macros.append(element.get("name") or "?")
        elif xacro and local in ("property", "arg"):
            counts["property"] += 1
        elif not xacro and local in LIBRARY_URDF_ELEMENTS:
            counts["material"] += 1
        elif not (xacro and local in DEFINITIONS):
            return None  # a macro call, a link, anything else: a robot (or a broken one)
    if not macros and not counts["property"] and not counts["material"]:
        return None
    return MacroLibrary(tuple(sorted(macros)), counts["property"], counts["material"],
                        shown_files(includers(path), path.parent) if find_includers else ())


def includers(path: Path) -> tuple[Path, ...]:
    """The robot files that include a file of ``path``'s name, looked for in its package (the nearest
    folder with a package.xml, at most MAX_LEVELS above) or, outside a package, in its own folder tree:
    where ar3cli may read anyway (docs/security.md). A hint, so the search is bounded (MAX_FOLDERS
    folders, MAX_CANDIDATES files) and a file that cannot be read is skipped."""
    own = path.resolve()
    top = own.parent
    for _ in range(MAX_LEVELS + 1):
        if (top / "package.xml").is_file():
            break
        if top.parent == top:
            top = own.parent
            break
        top = top.parent
    else:
        top = own.parent
    name = own.name.encode()
    found: list[Path] = []
    folders = files_seen = 0
    for current, dirs, files in os.walk(top):
        folders += 1
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        for file in sorted(files):
            candidate = Path(current) / file
            if not file.lower().endswith((".xacro", ".urdf")) or candidate == own:
                continue
            files_seen += 1
            try:
                text = read_bytes(candidate, limit=MAX_CANDIDATE_BYTES)
            except UserError:
                continue
            if _includes_name(text, name):
                found.append(candidate)
            if len(found) >= 3 or files_seen >= MAX_CANDIDATES:
                return tuple(found)
        if folders >= MAX_FOLDERS:
            break
    return tuple(found)


def _includes_name(text: bytes, name: bytes) -> bool:
    """Whether ``text`` has an include whose filename's last component is ``name`` or a pattern matching it
    (``$(find arm)/urdf/hand.xacro``, ``parts/*.xacro``). A name inside another (``e.xacro`` in
    ``.secret_name.xacro``) is not one: that said a stranger's file was an include body."""
    for match in INCLUDE_FILENAME.finditer(text):
        last = match.group(2).replace(b"\\", b"/").rsplit(b"/", 1)[-1]
        if last == name or (b"*" in last or b"?" in last or b"[" in last) and fnmatch.fnmatchcase(name, last):
            return True
    return False


def shown_files(paths, folder: Path) -> tuple[str, ...]:
    """``paths`` as a message may show them: relative to the current folder when inside it, else to the robot's
    ``folder`` when inside that; the others only counted ("2 files outside the robot's folder"), as
    :func:`~ar3cli.urdf.packages.shown_places` does for searched places (docs/security.md)."""
    here, own = Path.cwd().resolve(), folder.resolve()
    shown: list[str] = []
    hidden = 0
    for path in paths:
        full = Path(path).resolve()
        if full.is_relative_to(here):
            shown.append(str(full.relative_to(here)))
        elif full.is_relative_to(own):
            shown.append(str(full.relative_to(own)))
        else:
            hidden += 1
    if hidden:
        shown.append(f"{hidden} file{'s' if hidden != 1 else ''} outside the robot's folder")
    return tuple(shown)
