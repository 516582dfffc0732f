"""``lint-urdf --changed-since REF``: the robot files a change touches.

A robot file (``.urdf``/``.xacro`` under the given PATHs) is linted when it changed since the git
ref (``git diff --name-only REF``: committed, staged and unstaged changes; plus untracked files
git does not ignore), or when it *uses* a file that changed: a mesh it references (as the package
resolver finds it, or, for a mesh that is now missing, every place it looked), or, for a xacro
file, a file xacro read while expanding it (``xacro:include``, ``load_yaml``). Finding the users
means loading every robot file under PATH once, so that is done only when something other than a
``.urdf`` file changed (a ``.urdf`` file is used by nobody).

Git is only read: every call is ``git -C ROOT`` with ``diff.autoRefreshIndex=false``, so not even
the index's stat cache is rewritten. Files git reports because only their time stamps changed (a
``touch``, a fresh copy) are compared by content and dropped when equal.
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.infra.git import run_git
from ar3cli.lint.engine import collect_files, display_path


@dataclass
class ChangedSelection:
    """What ``--changed-since`` picked: the files to lint (in the order of a full run), those that
    changed themselves, and those linted because they use a changed file (-> the files they use)."""

    ref: str
    files: list[Path] = field(default_factory=list)
    changed: list[str] = field(default_factory=list)
    dependents: dict[str, list[str]] = field(default_factory=dict)
    candidates: int = 0
    """Robot files under PATH (all of them would be linted without --changed-since)."""

    def to_dict(self) -> dict:
        return {"ref": self.ref, "changed": self.changed, "dependents": self.dependents,
                "robot_files_under_paths": self.candidates}

    def note(self) -> str:
        """What --changed-since picked, in one line (lint-urdf's first text line, else on stderr)."""
        head = f"--changed-since {self.ref}:"
        if not self.files:
            return (f"{head} no robot file under PATH changed or uses a changed file "
                    f"({self.candidates} not checked); nothing to check")
        parts = []
        if self.changed:
            parts.append(f"{len(self.changed)} changed ({listed(self.changed, 3)})")
        if self.dependents:
            count = len(self.dependents)
            parts.append(f"{count} use{'s' if count == 1 else ''} a changed file ("
                         + listed((f"{robot} uses {listed(used, 3)}" for robot, used in self.dependents.items()), 3)
                         + ")")
        return f"{head} {len(self.files)} of {self.candidates} robot files: {'; '.join(parts)}"


def select_changed(paths: Iterable[Path], ref: str, package_paths: Mapping[str, Path] | None = None,
                   xacro_args: Mapping[str, str] | None = None) -> ChangedSelection:
    """The robot files under ``paths`` that changed since ``ref`` or use a changed file.

    Not a git repository, no git, or an unknown ref: one-line :class:`UserError` (exit 2).
    """
    paths = list(paths)
    if ref.startswith("-") or not ref.strip():
        raise UserError(f"--changed-since: {ref!r} is not a git ref")
    candidates = collect_files(paths)
    selection = ChangedSelection(ref, candidates=len(candidates))
    changed: set[str] = set()
    for root in dict.fromkeys(_repo_root(path) for path in paths):
        changed |= changed_files(root, ref)
    if not candidates:
        return selection
    real = {path: os.path.realpath(path) for path in candidates}
    direct = {path for path in candidates if real[path] in changed}
    selection.changed = [display_path(path) for path in candidates if path in direct]
    if any(not name.lower().endswith(".urdf") for name in changed):
        for path in candidates:
            if path in direct:
                continue
            used = sorted(changed.intersection(_used_files(path, package_paths, xacro_args)))
            if used:
                selection.dependents[display_path(path)] = [display_path(Path(name)) for name in used]
    chosen = direct | {path for path in candidates if display_path(path) in selection.dependents}
    selection.files = [path for path in candidates if path in chosen]
    return selection


def _git(root: Path | str, *args: str, stdin: str | None = None) -> subprocess.CompletedProcess:
    """``git -C root ARGS``, read-only (:func:`~ar3cli.infra.git.run_git`)."""
    return run_git(root, *args, purpose="--changed-since", stdin=stdin)


def _repo_root(path: Path) -> str:
    """The top folder of the git working tree holding ``path``."""
    folder = path if path.is_dir() else (path.parent if str(path.parent) else Path("."))
    done = _git(folder, "rev-parse", "--show-toplevel")
    if done.returncode != 0:
        raise UserError(f"--changed-since: {path} is not in a git working tree")
    return os.fsdecode(done.stdout).strip()


def changed_files(root: str, ref: str) -> set[str]:
    """Real paths of the files that differ between ``ref`` and the working tree of the repository
    at ``root`` (deleted ones included), plus the untracked files git does not ignore."""
    verify = _git(root, "rev-parse", "--verify", "--quiet", f"{ref}^{{commit}}")
    if verify.returncode != 0:
        raise UserError(f"--changed-since: unknown git ref {ref!r} in {root}")
    commit = os.fsdecode(verify.stdout).strip()
    diff = _git(root, "diff", "--name-only", "--no-renames", "-z", commit, "--")
    untracked = _git(root, "ls-files", "--others", "--exclude-standard", "-z")
    for done in (diff, untracked):
        if done.returncode != 0:
            raise UserError(f"--changed-since: git failed in {root}: "
                            f"{' '.join(os.fsdecode(done.stderr).split()) or 'exit code ' + str(done.returncode)}")
    names = [os.fsdecode(name) for name in diff.stdout.split(b"\0") if name]
    names = _drop_unchanged_content(root, commit, names)
    names += [os.fsdecode(name) for name in untracked.stdout.split(b"\0") if name]
    return {os.path.realpath(os.path.join(root, name)) for name in names}


def _drop_unchanged_content(root: str, commit: str, names: list[str]) -> list[str]:
    """``names`` without the files whose content is what ``commit`` holds (git reports a file whose
    time stamps changed when it may not refresh its index)."""
    present = [name for name in names if "\n" not in name and os.path.isfile(os.path.join(root, name))
               and not os.path.islink(os.path.join(root, name))]
    if not present:
        return names
    stored = _git(root, "cat-file", "--batch-check=%(objectname)", stdin="".join(f"{commit}:{n}\n" for n in present))
    current = _git(root, "hash-object", "--stdin-paths", stdin="".join(f"{n}\n" for n in present))
    if stored.returncode != 0 or current.returncode != 0:
        return names
    before, after = os.fsdecode(stored.stdout).split(), os.fsdecode(current.stdout).split()
    if len(before) != len(present) or len(after) != len(present):
        return names
    same = {name for name, old, new in zip(present, before, after) if old == new}
    return [name for name in names if name not in same]


def _used_files(path: Path, package_paths: Mapping[str, Path] | None,
                xacro_args: Mapping[str, str] | None) -> set[str]:
    """Real paths of the files the robot file uses: its meshes (where found, or every place tried
    when missing) and, for xacro, every file xacro read. Empty when it cannot be loaded."""
    from ar3cli.urdf.file_kind import is_xacro
    from ar3cli.urdf.model import load_model
    from ar3cli.urdf.xacro_expand import included_files, origins

    try:
        model = load_model(path, package_paths, xacro_args)
    except (UserError, RecursionError):
        return set()
    used: list[str] = []
    for _, shape in model.meshes():
        resolution = shape.geometry.resolution
        if resolution is not None:
            used += [str(resolution.path)] if resolution.path is not None else list(resolution.tried)
    if is_xacro(path):
        used += included_files(model.xml_bytes)  # what xacro --deps lists
        used += [origin.file for origin in origins(model.xml_bytes) or [] if origin is not None]
    return {os.path.realpath(name) for name in used}
