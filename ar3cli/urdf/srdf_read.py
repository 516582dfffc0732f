"""Reading a MoveIt SRDF: its ``<disable_collisions>``/``<enable_collisions>`` entries and
``<disable_default_collisions>``, safely (no entities, no DTD, no network), with one-line errors.

Used by ``sample-collisions --srdf-merge/--srdf-compare`` (``ar3cli.collisions.srdf_files``) and by
``lint-urdf --sim --srdf`` (pairs the user disabled are not reported as colliding at home).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError

GENERATED_REASONS = frozenset({"Adjacent", "Default", "Always", "Never"})
"""Reasons MoveIt Setup Assistant (and ar3cli) write, exactly so spelt (``compute_default_collisions.cpp``);
entries with any other reason, or none, are the user's."""


@dataclass(frozen=True)
class Entry:
    """One ``<disable_collisions>`` or ``<enable_collisions>`` child of ``<robot>``."""

    kind: str  # "disable" | "enable"
    link1: str
    link2: str
    reason: str | None
    line: int

    @property
    def key(self) -> frozenset[str]:
        return frozenset((self.link1, self.link2))

    @property
    def generated(self) -> bool:
        return self.kind == "disable" and self.reason in GENERATED_REASONS

    @property
    def label(self) -> str:
        """How the SRDF treats the pair: its reason, ``disabled`` without one, or ``enabled``."""
        if self.kind == "enable":
            return "enabled"
        return self.reason if self.reason else "disabled"


@dataclass
class Srdf:
    """A parsed SRDF: its bytes, the lxml root, the collision entries (document order)."""

    path: Path
    data: bytes
    root: Any
    entries: list[Entry] = field(default_factory=list)
    no_default: dict[str, int] = field(default_factory=dict)
    """``<disable_default_collisions link=...>``: link -> line (every pair with it is disabled unless enabled)."""

    @property
    def robot_name(self) -> str | None:
        return self.root.get("name")

    def disabled_by(self, a: str, b: str) -> str | None:
        """Why the SRDF disables the pair (its reason), or None when MoveIt checks it. As MoveIt builds
        the allowed-collision matrix: an explicit disable wins, then an explicit enable, then the
        links' default entries."""
        key = frozenset((a, b))
        explicit = [e for e in self.entries if e.key == key]
        disabling = next((e for e in explicit if e.kind == "disable"), None)
        if disabling is not None:
            return disabling.label
        if explicit:
            return None
        if a in self.no_default or b in self.no_default:
            return "default off"
        return None

    @property
    def hand_written(self) -> list[Entry]:
        return [e for e in self.entries if not e.generated]


def read_srdf(path: Path) -> Srdf:
    """Read and parse an SRDF safely (no entities, no DTD, no network); one-line UserError otherwise."""
    from lxml import etree

    from ar3cli.infra.safe_read import read_bytes
    from ar3cli.urdf.xmlsource import refuse_entities

    if path.is_dir():
        raise UserError(f"{path}: is a directory, expected an .srdf file")
    if not path.exists():
        raise UserError(f"{path}: no such file (an existing SRDF was expected)")
    data = read_bytes(path, what="an .srdf file")
    refuse_entities(data, path)
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False,
                             remove_blank_text=False)
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        message = re.sub(r",? line \d+, column \d+.*$", "", str(exc.msg if hasattr(exc, "msg") else exc))
        where = f"{path}:{exc.lineno}" if exc.lineno else str(path)
        raise UserError(f"{where}: not well-formed XML: {message}") from None
    except ValueError as exc:
        raise UserError(f"{path}: cannot decode: {exc}") from None
    if root.tag != "robot":
        raise UserError(f"{path}:{root.sourceline}: the root element is <{root.tag}>, an SRDF has <robot>")
    srdf = Srdf(path, data, root)
    for element in root:
        if element.tag in ("disable_collisions", "enable_collisions"):
            link1, link2 = element.get("link1"), element.get("link2")
            if not link1 or not link2:
                raise UserError(f"{path}:{element.sourceline}: <{element.tag}> needs link1 and link2")
            srdf.entries.append(Entry(element.tag.split("_")[0], link1, link2, element.get("reason"),
                                      element.sourceline or 0))
        elif element.tag == "disable_default_collisions" and element.get("link"):
            srdf.no_default.setdefault(element.get("link"), element.sourceline or 0)
    return srdf


@dataclass(frozen=True)
class DisabledPairs:
    """The link pairs an SRDF tells MoveIt not to check, as MoveIt builds its allowed-collision matrix (and
    :meth:`Srdf.disabled_by`): an explicit ``<disable_collisions>`` wins, then an explicit
    ``<enable_collisions>``, then a link's ``<disable_default_collisions>``."""

    explicit: frozenset[frozenset[str]] = frozenset()
    enabled: frozenset[frozenset[str]] = frozenset()
    default_off: frozenset[str] = frozenset()

    def covers(self, a: str, b: str) -> bool:
        """Whether MoveIt leaves the pair (a, b) unchecked."""
        key = frozenset((a, b))
        if key in self.explicit:
            return True
        return key not in self.enabled and (a in self.default_off or b in self.default_off)


def disabled_pairs(path: Path) -> DisabledPairs:
    """Every link pair the SRDF at ``path`` tells MoveIt not to check (:class:`DisabledPairs`)."""
    srdf = read_srdf(path)
    return DisabledPairs(frozenset(entry.key for entry in srdf.entries if entry.kind == "disable"),
                         frozenset(entry.key for entry in srdf.entries if entry.kind == "enable"),
                         frozenset(srdf.no_default))


PACKAGE_FOLDERS = ("urdf", "robots")
"""Folder names of a ROS package's robot files: their parent is the package's root, where srdf/ and config/
(and a loose SRDF) live."""
SRDF_FOLDERS = ("", "srdf", "config")
"""Where a package keeps its SRDF, relative to the robot file's folder (and, in a PACKAGE_FOLDERS layout, to
its parent)."""
MAX_SRDF_CANDIDATES = 64
"""SRDF files read when the package's SRDF is looked for (a hint: bounded)."""


def package_srdf(urdf_path: Path, robot_name: str | None, links: set[str]) -> Path | None:
    """The SRDF a package ships for this robot file, or None: an ``*.srdf`` in the file's folder or its
    ``srdf/`` or ``config/`` subfolder (and the same beside a ``urdf/`` or ``robots/`` folder, the package's
    root in ROS's layout), whose file name is the robot file's (``panda.srdf`` for ``panda.urdf``), else whose
    ``<robot name>`` is the robot's, else whose file name is the robot's name (``vega_1p_gripper.srdf`` for
    a collision-spheres variant of that robot). Exactly one candidate of the first kind that has any must
    match, and its disabled pairs must name links of this robot; an SRDF that cannot be read is skipped.
    Used by ``lint-urdf --sim`` when no ``--srdf`` is given (compas-fab, dexmate-urdf and pyroboplan ship
    one beside each URDF)."""
    folder = urdf_path.parent
    roots = [folder] + ([folder.parent] if folder.name in PACKAGE_FOLDERS and folder.parent != folder else [])
    candidates: list[Path] = []
    for root in roots:
        for sub in SRDF_FOLDERS:
            place = root / sub if sub else root
            try:
                candidates += sorted(p for p in place.iterdir() if p.suffix.lower() == ".srdf" and p.is_file())
            except OSError:
                continue
    stem = urdf_path.name.split(".", 1)[0]
    read: list[tuple[Path, Srdf]] = []
    for candidate in list(dict.fromkeys(candidates))[:MAX_SRDF_CANDIDATES]:
        try:
            read.append((candidate, read_srdf(candidate)))
        except UserError:
            continue
    for matches in (lambda path, srdf: path.stem == stem,
                    lambda path, srdf: robot_name is not None and srdf.robot_name == robot_name,
                    lambda path, srdf: robot_name is not None and path.stem == robot_name):
        found = [(path, srdf) for path, srdf in read if matches(path, srdf)]
        if found:
            if len(found) != 1:
                return None  # several fit equally: none is the robot's for sure
            path, srdf = found[0]
            named = {link for entry in srdf.entries for link in (entry.link1, entry.link2)} | set(srdf.no_default)
            return path if named & links else None
    return None


def moveit_disabled(model: Any, given: DisabledPairs | None = None) -> tuple[DisabledPairs, Path | None]:
    """(the link pairs MoveIt is told not to check, the package's SRDF they come from or None): ``given``
    (the user's ``--srdf``, even one that disables nothing), else the SRDF the package ships for ``model``
    (:func:`package_srdf`), else none. lint's P002 and M003 and report's contact verdicts leave those pairs
    alone."""
    if given is not None:
        return given, None
    path = package_srdf(model.path, model.name, {link.name for link in model.links})
    if path is None:
        return DisabledPairs(), None
    try:
        return disabled_pairs(path), path
    except UserError:
        return DisabledPairs(), None
