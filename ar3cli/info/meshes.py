"""Mesh facts for ``ar3cli info``: how many, which formats, which did not resolve, and triangles
where a file says so cheaply.

Only binary STL files are counted: their 84-byte header holds the triangle count (checked
against the file size by :func:`ar3cli.urdf.meshinfo.mesh_content`). Counting OBJ, ASCII STL or
COLLADA triangles means reading and parsing each file (COLLADA needs trimesh, ~0.5 s to import):
their count is left out, and the report says so, so ``info`` stays fast on big robots.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ar3cli.urdf.meshinfo import is_lfs_pointer, mesh_content
from ar3cli.urdf.model import Model


@dataclass
class MeshFacts:
    """The meshes a model uses; a file is counted once however many shapes use it."""

    references: int = 0
    """``<mesh>`` elements (visual and collision)."""
    files: int = 0
    """Distinct mesh files (by resolved path; by URI when it did not resolve)."""
    formats: dict[str, int] = field(default_factory=dict)
    """Distinct files per extension (lower case, without the dot; ``none`` when there is none)."""
    unresolved: list[dict[str, str]] = field(default_factory=list)
    """``{"uri", "problem"}`` of each URI that did not resolve to a file (a ``package://`` whose
    package is not found, a missing file)."""
    lfs_pointers: list[str] = field(default_factory=list)
    """Resolved files that are Git LFS pointers (``git lfs pull`` was never run)."""
    triangles: int | None = None
    """Triangles in the files that could be counted (binary STL); None when none could."""
    counted_files: int = 0
    triangles_by_role: dict[str, int | None] = field(default_factory=dict)
    """``visual`` / ``collision``: triangles in the counted files each role uses."""

    def to_dict(self) -> dict[str, Any]:
        return {"references": self.references, "files": self.files, "formats": self.formats,
                "unresolved": self.unresolved, "lfs_pointers": self.lfs_pointers, "triangles": self.triangles,
                "triangles_counted_files": self.counted_files, "triangles_by_role": self.triangles_by_role}


def binary_stl_triangles(path: Path) -> int | None:
    """The triangle count in a binary STL's header, or None (not STL, ASCII STL, unreadable):
    :func:`ar3cli.urdf.meshinfo.mesh_content` reads 84 bytes and the file size (cached on disk with
    lint's mesh facts), never the triangles."""
    content = mesh_content(path)
    return content[1] if content is not None and content[0] == "stl-binary" else None


def mesh_facts(model: Model) -> MeshFacts:
    """Count, formats, unresolved URIs and (binary STL) triangles of every mesh in ``model``."""
    facts = MeshFacts()
    roles: dict[str, set[str]] = {"visual": set(), "collision": set()}
    paths: dict[str, Path | None] = {}
    for _link, shape in model.meshes():
        facts.references += 1
        resolution = shape.geometry.resolution
        found = resolution is not None and resolution.found
        key = str(resolution.path) if found else (shape.geometry.filename or "")  # type: ignore[union-attr]
        roles.setdefault(shape.role, set()).add(key)
        if key in paths:
            continue
        paths[key] = resolution.path if found else None  # type: ignore[union-attr]
        suffix = Path(key.split("?")[0]).suffix.lower().lstrip(".") or "none"
        facts.formats[suffix] = facts.formats.get(suffix, 0) + 1
        if not found:
            problem = (resolution.problem if resolution is not None else "") or "not found"
            facts.unresolved.append({"uri": key, "problem": problem})
    facts.files = len(paths)
    facts.formats = dict(sorted(facts.formats.items(), key=lambda item: (-item[1], item[0])))
    counts: dict[str, int] = {}
    for key, path in paths.items():
        if path is None:
            continue
        if is_lfs_pointer(path):
            facts.lfs_pointers.append(key)
            continue
        count = binary_stl_triangles(path)
        if count is not None:
            counts[key] = count
    facts.counted_files = len(counts)
    facts.triangles = sum(counts.values()) if counts else None
    for role, keys in roles.items():
        counted = [counts[key] for key in keys if key in counts]
        facts.triangles_by_role[role] = sum(counted) if counted else None
    return facts
