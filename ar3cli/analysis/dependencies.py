"""The files one load of a robot read or looked for, with their state at that moment: what a viewer
or an editor polls to ask "did anything change since I loaded?".

A load depends on the robot file (unless an editor's buffer stood in for it), the files xacro
included (and YAML it loaded), and every path the package resolution looked at: the meshes found,
the places a missing mesh was looked for (so a mesh that appears is a change too) and the
``package.xml`` manifests read (:attr:`ar3cli.urdf.packages.PackageResolver.probed`). A state is
:func:`ar3cli.infra.file_cache.path_state`'s (mtime, ctime, size, mode; None where nothing is), so
a file that is replaced, touched, removed or created counts, and polling costs one ``stat`` per
path (a few hundred for the largest robots of example-robot-data).

The robot file's state is taken before it is read and the others right after the load, so a file
written during the load is seen as changed at the next poll (at worst one reload too many).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ar3cli.infra.file_cache import PathState, path_state

if TYPE_CHECKING:
    from ar3cli.urdf.model import Model

MAX_WATCHED = 4096
"""Paths kept per load (the first ones: the robot file, its includes, then the meshes): a file that
names 100,000 meshes must not make each poll 100,000 system calls."""


@dataclass(frozen=True)
class Dependencies:
    """Path -> its state when the robot was loaded."""

    states: Mapping[str, PathState | None] = field(default_factory=dict)

    @property
    def paths(self) -> list[Path]:
        return [Path(name) for name in self.states]

    def changed(self) -> list[Path]:
        """The paths whose state differs now (created, removed, written, replaced), in load order."""
        return [Path(name) for name, state in self.states.items() if path_state(name) != state]

    @classmethod
    def stamp(cls, names: Iterable[str], known: Mapping[str, PathState | None] | None = None) -> Dependencies:
        """``names`` (absolute, duplicates once) with their state now, or as ``known`` recorded it."""
        known = known or {}
        states: dict[str, PathState | None] = {}
        for name in names:
            if len(states) >= MAX_WATCHED:
                break
            full = os.path.abspath(name)
            if full not in states:
                states[full] = known[name] if name in known else path_state(full)
        return cls(states)


def robot_file_state(path: Path) -> dict[str, PathState | None]:
    """The robot file's state, taken before it is read."""
    return {os.path.abspath(path): path_state(os.path.abspath(path))}


def of_load(path: Path, model: Model | None, robot_file: Mapping[str, PathState | None],
            earlier: Dependencies | None = None) -> Dependencies:
    """What a load of ``path`` depends on: ``robot_file`` (:func:`robot_file_state`; empty when a
    buffer stood in for the file), the xacro includes and the resolver's probed paths of ``model``.
    A load that failed (``model`` None) keeps watching what ``earlier`` (the last load) watched,
    taken anew: fixing an included file is what makes the robot load again."""
    names: list[str] = list(robot_file)
    known: dict[str, PathState | None] = dict(robot_file)
    if model is None:
        own = os.path.abspath(path)  # watched through robot_file, or not at all (a buffer)
        names += [name for name in (earlier.states if earlier else {}) if name != own]
        return Dependencies.stamp(names, known)
    if model.is_xacro:
        from ar3cli.urdf.xacro_expand import included_files

        names += included_files(model.xml_bytes)
    probed = model.resolver.probed
    names += list(probed)
    known.update(probed)
    return Dependencies.stamp(names, known)
