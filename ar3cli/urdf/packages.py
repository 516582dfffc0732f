"""Resolve mesh URIs (relative, absolute, ``file://``, ``package://``) to files on disk.

ROS tools resolve ``package://NAME/...`` through a ROS installation; most ar3cli users have none.
So the search is explicit, in this order, and every place tried is remembered for the error:

1. ``--package-path NAME=DIR`` given on the command line (DIR is the package folder itself);
2. each entry of ``ROS_PACKAGE_PATH`` (``ENTRY/NAME``, or ENTRY itself when it is the package);
3. each prefix of ``AMENT_PREFIX_PATH`` (``PREFIX/share/NAME``);
4. the nearest ancestor folder of the robot file that is named NAME or holds a ``package.xml``
   whose ``<name>`` is NAME (the usual ``NAME/urdf/robot.urdf`` layout works with no setup);
5. PyBullet's own rule, as a last resort: drop ``package://`` and look for the rest in the file's
   folder and up to three folders above it. Many models (pybullet_data's panda, xarm) only load
   because of this rule; :attr:`Resolution.via` says ``pybullet-search`` so the linter can warn
   that ROS tools will not find those meshes. Relative paths get the same fallback.
"""

from __future__ import annotations

import dataclasses
import os
import re
import stat
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property, lru_cache
from pathlib import Path
from urllib.parse import unquote

from ar3cli.infra.file_cache import PathState, path_state
from ar3cli.infra.safe_read import kind_of

_PACKAGE_NAME = re.compile(rb"<name>\s*([^<\s]+)\s*</name>")


@dataclass(frozen=True)
class Resolution:
    """Where a URI points: ``path`` when found, else ``None`` with ``tried`` listing the candidates."""

    uri: str
    path: Path | None
    tried: tuple[str, ...]
    problem: str = ""
    via: str = ""
    """How it was found: ``direct``, ``package`` or ``pybullet-search`` (empty when not found)."""
    refused: Path | None = None
    """The place the search stopped at because something other than a regular file is there (a
    FIFO, a device, a folder): never read, never handed to pybullet (which would block on a FIFO)."""

    folder: str = ""
    """The robot file's folder (the resolver's), for :meth:`places`."""

    @property
    def found(self) -> bool:
        return self.path is not None

    def places(self) -> list[str]:
        """Where the search looked, as a message may show it (:func:`shown_places`)."""
        return shown_places(self.tried, self.folder)

    def explain(self) -> str:
        """One line for error messages: why the URI did not resolve and where we looked."""
        if self.found:
            return f"{self.uri} -> {self.path}"
        reason = self.problem or "not found"
        if self.tried:
            return f"{self.uri}: {reason}; tried {', '.join(self.places())}"
        return f"{self.uri}: {reason}"


def shown_places(places: Sequence[str], folder: str | os.PathLike[str]) -> list[str]:
    """The places a search tried, as a message shows them (:func:`split_places`), the hidden ones as one
    last item ("3 places outside the robot's folder")."""
    shown, hidden = split_places(places, folder)
    if hidden:
        shown.append(f"{hidden} place{'s' if hidden != 1 else ''} outside the robot's folder")
    return shown


def split_places(places: Sequence[str], folder: str | os.PathLike[str]) -> tuple[list[str], int]:
    """(the places a message may name: those inside the current folder (relative to it) or inside the robot's
    ``folder``, in order; how many others there were: the folders above the checkout, ``ROS_PACKAGE_PATH``
    and ``AMENT_PREFIX_PATH`` entries). Their names are the machine's layout, not the robot's, and a linted
    pull request must not learn it (docs/security.md)."""
    here = os.getcwd()
    roots = [root.rstrip(os.sep) + os.sep for root in (here, os.fspath(folder)) if root]
    shown: list[str] = []
    hidden = 0
    for place in places:
        absolute = os.path.abspath(place) if not place.startswith(ANCESTORS) else place
        if place.startswith(ANCESTORS):
            shown.append(place)
        elif absolute.startswith(roots[0]):
            shown.append(os.path.relpath(absolute, here))
        elif any(absolute.startswith(root) for root in roots[1:]):
            shown.append(place)
        else:
            hidden += 1
    return shown, hidden


ANCESTORS = "ancestors of the robot's folder"
"""How the package search's walk up the folders is named among the places tried."""


def parse_package_paths(items: list[str] | None) -> dict[str, Path]:
    """Turn repeated ``NAME=DIR`` options into a mapping; raises ValueError on a malformed item."""
    mapping: dict[str, Path] = {}
    for item in items or []:
        name, sep, folder = item.partition("=")
        if not sep or not name.strip() or not folder.strip():
            raise ValueError(f"--package-path expects NAME=DIR, got {item!r}")
        mapping[name.strip()] = Path(folder.strip()).expanduser()
    return mapping


PACKAGE_XML_HEAD_BYTES = 65536
"""Bytes of a package.xml searched for its <name> (it comes right after <package>)."""


@lru_cache(maxsize=256)
def _package_xml_name(folder: Path, _state: PathState | None = None) -> str | None:
    """The ``<name>`` in ``folder/package.xml`` (cached per state of the file: an edit is seen)."""
    from ar3cli.errors import UserError
    from ar3cli.infra.safe_read import read_head

    try:  # only the head: an ancestor's package.xml of 3 GB is not read whole; a pipe or device is refused
        match = _PACKAGE_NAME.search(read_head(folder / "package.xml", PACKAGE_XML_HEAD_BYTES, what="a package.xml"))
    except (OSError, UserError):  # missing, a folder, a pipe that would never end, unreadable
        return None
    return match.group(1).decode("utf-8", "replace") if match else None


def enclosing_package(folder: Path) -> tuple[str, Path] | None:
    """The package a file in ``folder`` belongs to: the nearest folder from ``folder`` up that holds a
    ``package.xml`` with a ``<name>``, as (name, that folder); None when there is none. This is the
    package :class:`PackageResolver` finds for ``package://NAME/...`` from the file (its rule 4)."""
    for ancestor in [folder, *folder.parents]:
        manifest = ancestor / "package.xml"
        name = _package_xml_name(ancestor, path_state(str(manifest)))
        if name:
            return name, ancestor
    return None


PYBULLET_SEARCH_LEVELS = 64
"""How many folders above the robot file PyBullet's fallback search climbs: all of them (pybullet 3.2.7
found ``pkg/meshes/m.obj``, ``package://pkg/meshes/m.obj`` and ``package:///pkg/meshes/m.obj`` from a
URDF 20 folders below ``pkg``'s folder); the bound only keeps a pathological path finite."""


class PackageResolver:
    """Resolves URIs for one robot file; construct once per file and reuse (results are cached)."""

    def __init__(
        self,
        base_dir: Path,
        package_paths: Mapping[str, Path] | None = None,
        environ: Mapping[str, str] | None = None,
    ) -> None:
        self.base_dir = base_dir.resolve()
        self.package_paths = dict(package_paths or {})
        env = os.environ if environ is None else environ
        self._ros_paths = [Path(p) for p in env.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
        self._ament_prefixes = [Path(p) for p in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
        self._packages: dict[str, tuple[Path | None, tuple[str, ...]]] = {}
        self._resolutions: dict[str, Resolution] = {}
        self.probed: dict[str, PathState | None] = {}
        """Every path a resolution depended on, with its state when first looked at (the lint result
        cache stores these: the answer is stale when any of them changes)."""

    @cached_property
    def _ancestors(self) -> list[Path]:
        """The file's folder and every folder above it, nearest first (``[base_dir, *base_dir.parents]``,
        built once per resolver: ``parents`` makes each one anew by index, for every URI searched)."""
        folders = [self.base_dir]
        while folders[-1].parent != folders[-1]:
            folders.append(folders[-1].parent)
        return folders

    def _probe(self, path: Path) -> Path:
        """``path``, its state remembered in :attr:`probed` (call it before looking at the disk)."""
        key = str(path)
        if key not in self.probed:
            self.probed[key] = path_state(key)
        return path

    def is_file(self, path: Path) -> bool:
        """Whether ``path`` is a regular file, remembered in :attr:`probed` like every path a resolution
        looks at (a lint rule that resolves a path its own way, as MuJoCo would, asks here)."""
        return self._kind(path) == "file"

    def _kind(self, path: Path) -> str | None:
        """What is at ``path`` (symlinks followed, state remembered in :attr:`probed`): ``"file"`` for
        a regular file, None for nothing (or a path the OS refuses, such as a name over 255 bytes),
        else what it is (:func:`~ar3cli.infra.safe_read.kind_of`)."""
        self._probe(path)
        state = self.probed[str(path)]
        if state is None:
            return None
        return "file" if stat.S_ISREG(state[3]) else kind_of(state[3])

    def _found(self, uri: str, candidate: Path, tried: tuple[str, ...], via: str) -> Resolution | None:
        """The resolution when ``candidate`` ends the search: a regular file is found; anything else
        that is there stops it too (pybullet would open it: a FIFO blocks it) and is refused."""
        kind = self._kind(candidate)
        if kind is None:
            return None
        if kind == "file":
            return Resolution(uri, candidate, tried, via=via)
        return Resolution(uri, None, tried, f"not a regular file ({kind})", refused=candidate)

    def _package_name(self, folder: Path) -> str | None:
        manifest = folder / "package.xml"
        self._probe(manifest)
        return _package_xml_name(folder, self.probed[str(manifest)])

    def find_package(self, name: str) -> tuple[Path | None, tuple[str, ...]]:
        """Folder of package ``name`` and the candidates tried, following the module's order."""
        if name not in self._packages:
            self._packages[name] = self._search_package(name)
        return self._packages[name]

    def _search_package(self, name: str) -> tuple[Path | None, tuple[str, ...]]:
        tried: list[str] = []

        def accept(candidate: Path) -> bool:
            tried.append(str(candidate))
            return self._kind(candidate) == "a folder"

        if name in self.package_paths and accept(self.package_paths[name]):
            return self.package_paths[name], tuple(tried)
        for entry in self._ros_paths:
            if accept(entry / name):
                return entry / name, tuple(tried)
            if entry.name == name or self._package_name(entry) == name:
                return entry, tuple(tried)
        for prefix in self._ament_prefixes:
            if accept(prefix / "share" / name):
                return prefix / "share" / name, tuple(tried)
        for ancestor in self._ancestors:
            if ancestor.name == name or self._package_name(ancestor) == name:
                return ancestor, tuple(tried)
            sibling = ancestor / name
            if self._kind(sibling) == "a folder" and self._package_name(sibling) in (name, None) \
                    and self.probed[str(sibling / "package.xml")] is not None:  # the manifest exists
                return sibling, tuple(tried)
        tried.append(f"{ANCESTORS} named {name} or with package.xml <name>{name}</name>")
        return None, tuple(tried)

    def resolve(self, uri: str) -> Resolution:
        """Resolve one URI as found in a ``filename`` attribute (once per resolver: a visual and
        its collision usually share their mesh)."""
        if uri not in self._resolutions:
            self._resolutions[uri] = dataclasses.replace(self._resolve(uri), folder=str(self.base_dir))
        return self._resolutions[uri]

    def _resolve(self, uri: str) -> Resolution:
        uri = uri.strip()
        if uri.startswith("package://"):
            name, _, rest = uri[len("package://"):].partition("/")
            if not name:  # G002 reports it for ROS; PyBullet drops the slashes and searches (Talos' meshes)
                return self._pybullet_search(uri, unquote(rest), (), "empty package name in package:/// URI")
            folder, tried = self.find_package(name)
            if folder is not None:
                candidate = folder / unquote(rest)
                tried = (*tried, str(candidate))
                found = self._found(uri, candidate, tried, "package")
                if found is not None:
                    return found
            return self._pybullet_search(uri, unquote(uri[len("package://"):]), tried,
                                         f"package '{name}' not found" if folder is None else "file not found in package")
        if uri.startswith("file://"):
            candidate = Path(unquote(uri[len("file://"):]))
        elif "://" in uri:
            return Resolution(uri, None, (), "unsupported URI scheme")
        else:
            candidate = Path(uri)
        if not candidate.is_absolute():
            candidate = self.base_dir / candidate
        found = self._found(uri, candidate, (str(candidate),), "direct")
        if found is not None:
            return found
        if Path(uri).is_absolute() or uri.startswith("file://"):
            return Resolution(uri, None, (str(candidate),), "file not found")
        return self._pybullet_search(uri, uri, (str(candidate),), "file not found")

    def _pybullet_search(self, uri: str, relative: str, tried: tuple[str, ...], problem: str) -> Resolution:
        """PyBullet's fallback: ``relative`` inside the file's folder and a few folders above."""
        folders = self._ancestors[:PYBULLET_SEARCH_LEVELS + 1]
        for folder in folders:
            candidate = folder / relative
            if str(candidate) not in tried:
                tried = (*tried, str(candidate))
            found = self._found(uri, candidate, tried, "pybullet-search")
            if found is not None:
                return found
        return Resolution(uri, None, tried, problem)
