"""One side of a diff: a file on disk, or ``REV:path``, a file as a git revision holds it.

A revision is read with git only, never checked out: the robot's folder as ``REV`` holds it is
copied into a private temporary folder, removed when the diff is done (a process killed by a signal
leaves it behind). What is copied: the nearest folder above the file that holds a ``package.xml``
at ``REV`` (the ROS package, so ``package://`` URIs, ``$(find ...)`` and relative includes resolve
inside the revision), or else the file's own folder; regular files only (no symlinks), at most
:data:`MAX_BYTES`. ``path`` is relative to the current directory, like every other path; the
repository is the one holding it (or its nearest existing folder).

Git is only read: ``git -C ROOT`` with optional locks off, as lint's ``--changed-since`` calls it.
"""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import tarfile
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from ar3cli.errors import UserError
from ar3cli.infra.git import run_git

MAX_BYTES = 512 * 1024 * 1024
"""Largest robot folder copied out of a revision (example-robot-data's whole robots/ tree is ~200 MB)."""


@dataclass(frozen=True)
class Side:
    """The file to load for one side, and how to show its paths: ``label`` is what the user wrote."""

    label: str
    path: Path
    revision: str | None = None
    copy_root: Path | None = None
    """The temporary folder standing for the repository root at ``revision``."""
    repo_root: Path | None = None

    def show(self, path: str) -> str:
        """A path of the temporary copy as ``REV:repo/path``; other paths unchanged."""
        if self.copy_root is None:
            return path
        root = str(self.copy_root)
        if path == root or path.startswith(root + os.sep):
            return f"{self.revision}:{os.path.relpath(path, root).replace(os.sep, '/')}"
        return path

    def relabel(self, message: str) -> str:
        """An error message with the temporary folder replaced by ``REV:``."""
        if self.copy_root is None:
            return message
        return message.replace(str(self.copy_root) + os.sep, f"{self.revision}:")


def git(root: Path | str, *args: str) -> subprocess.CompletedProcess:
    """``git -C root ARGS``, read-only (:func:`~ar3cli.infra.git.run_git`), bytes captured."""
    return run_git(root, *args, purpose="reading a git revision")


def split_spec(spec: str) -> tuple[str | None, str]:
    """``REV:path`` -> (REV, path); a path (one that exists, or has no colon) -> (None, path)."""
    if os.path.lexists(spec) or ":" not in spec:
        return None, spec
    revision, _, path = spec.partition(":")
    if not revision or not path or revision.startswith("-"):
        raise UserError(f"{spec!r}: expected a path or REV:path (a git revision, a colon, a path)")
    return revision, path


def _existing_folder(path: Path) -> Path:
    folder = path.parent
    while not folder.is_dir() and folder != folder.parent:
        folder = folder.parent
    return folder


def repository_path(path: str) -> tuple[Path, str]:
    """(repository root, path inside it, with ``/``) of a path relative to the current directory."""
    absolute = Path(os.path.abspath(path))
    folder = _existing_folder(absolute)
    done = git(folder, "rev-parse", "--show-toplevel")
    if done.returncode != 0:
        raise UserError(f"{path}: not in a git working tree (REV:path reads the repository holding path)")
    root = Path(os.fsdecode(done.stdout).strip())
    real = Path(os.path.realpath(folder)) / absolute.relative_to(folder)
    try:
        inside = real.relative_to(os.path.realpath(root))
    except ValueError:
        raise UserError(f"{path}: outside the git working tree {root}") from None
    return root, inside.as_posix()


def resolve_commit(root: Path, revision: str) -> str:
    done = git(root, "rev-parse", "--verify", "--quiet", "--end-of-options", f"{revision}^{{commit}}")
    if done.returncode != 0:
        raise UserError(f"{revision}: unknown git revision in {root}")
    return os.fsdecode(done.stdout).strip()


def exists_at(root: Path, commit: str, inside: str) -> bool:
    return git(root, "cat-file", "-e", f"{commit}:{inside}").returncode == 0


def package_folder(root: Path, commit: str, inside: str) -> str:
    """The nearest folder above ``inside`` holding a package.xml at ``commit``, else the file's folder."""
    folder = PurePosixPath(inside).parent
    for candidate in (folder, *folder.parents):
        name = "package.xml" if str(candidate) == "." else f"{candidate}/package.xml"
        if exists_at(root, commit, name):
            return str(candidate)
    return str(folder)


def _extract(archive: bytes, into: Path) -> None:
    """Regular files and folders of a tar stream git wrote; anything else, or any name leaving ``into``, is skipped."""
    with tarfile.open(fileobj=io.BytesIO(archive), mode="r:") as tar:
        for member in tar:
            parts = PurePosixPath(member.name).parts
            if not member.isfile() or member.name.startswith("/") or ".." in parts:
                continue
            target = into.joinpath(*parts)
            target.parent.mkdir(parents=True, exist_ok=True)
            source = tar.extractfile(member)
            if source is not None:
                target.write_bytes(source.read())


def _tree_size(root: Path, commit: str, folder: str) -> int:
    done = git(root, "ls-tree", "-r", "-l", "-z", commit, "--", folder)
    total = 0
    for entry in done.stdout.split(b"\0"):
        fields = entry.split(b"\t", 1)[0].split()
        if len(fields) == 4 and fields[3].isdigit():
            total += int(fields[3])
    return total


@contextlib.contextmanager
def open_side(spec: str) -> Iterator[Side]:
    """The :class:`Side` ``spec`` names; a revision's copy exists while the ``with`` block runs."""
    revision, path = split_spec(spec)
    if revision is None:
        if not os.path.lexists(path):
            raise UserError(f"{path}: no such file or directory")
        yield Side(spec, Path(path))
        return
    root, inside = repository_path(path)
    commit = resolve_commit(root, revision)
    if not exists_at(root, commit, inside):
        raise UserError(f"{spec}: {revision} has no file {inside}")
    folder = package_folder(root, commit, inside)
    size = _tree_size(root, commit, folder)
    if size > MAX_BYTES:
        raise UserError(f"{spec}: the folder {folder} at {revision} holds {size / 1e6:.0f} MB, more than the "
                        f"{MAX_BYTES // 2**20} MiB ar3cli copies out of a revision")
    archive = git(root, "archive", "--format=tar", commit, "--", folder)
    if archive.returncode != 0:
        raise UserError(f"{spec}: git archive failed: {' '.join(os.fsdecode(archive.stderr).split())}")
    with tempfile.TemporaryDirectory(prefix="ar3cli-diff-") as temporary:
        copy = Path(temporary) / "rev"
        copy.mkdir()
        _extract(archive.stdout, copy)
        yield Side(spec, copy / inside, revision, copy, root)
