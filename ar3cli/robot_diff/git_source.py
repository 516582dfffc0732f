"""One side of a diff: a file on disk, or ``REV:path``, a file as a git revision holds it
(:func:`read_spec`: a revision whenever REV resolves in git, never a file that happens to have that name).

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


@dataclass(frozen=True)
class SideSpec:
    """What one side names: ``path`` (relative to the current folder) as git ``revision`` holds it,
    or on disk when ``revision`` is None; ``label`` is how it is shown (``REV:path`` or the path)."""

    label: str
    path: str
    revision: str | None = None

    @classmethod
    def at(cls, revision: str, path: str) -> SideSpec:
        """``path`` as ``revision`` holds it, whatever is on disk (``--old-rev``, ``--changed-since``)."""
        return cls(f"{revision}:{path}", path, revision)


def read_spec(spec: str) -> tuple[SideSpec, str | None]:
    """The side a command-line argument names, and a note saying how it was read when it has a colon.

    ``REV:path`` is a revision whenever REV resolves to a commit in the repository holding ``path``,
    even if a file of that very name exists: a pull request can commit a folder named
    ``origin/main:robots`` and must not become its own old side. Otherwise the argument is a path
    (``./REV:path`` always is one). Neither: a one-line UserError."""
    if ":" not in spec:
        if not os.path.lexists(spec):
            raise UserError(f"{spec}: no such file or directory")
        return SideSpec(spec, spec), None
    revision, _, path = spec.partition(":")
    commit, why = _commit_of(revision, path) if revision and path and not revision.startswith("-") else (None, "")
    if commit is not None:
        return SideSpec(spec, path, revision), (f"{spec}: the file {path} as git revision {revision} ({commit[:12]}) "
                                                "holds it" + (" (not the file of that name: write ./" + spec + " for it)"
                                                              if os.path.lexists(spec) else ""))
    if os.path.lexists(spec):
        return SideSpec(spec, spec), f"{spec}: the file of that name ({revision} is no git revision here)"
    if not revision or not path or revision.startswith("-"):
        raise UserError(f"{spec!r}: expected a path or REV:path (a git revision, a colon, a path)")
    raise UserError(f"{spec}: no such file or directory, and {why} (REV:path reads the file as git revision REV "
                    "holds it)")


def _commit_of(revision: str, path: str) -> tuple[str | None, str]:
    """The commit ``revision`` names in the repository holding ``path``, or None and why not (no
    repository, or no such revision there)."""
    folder = _existing_folder(Path(os.path.abspath(path)))
    done = git(folder, "rev-parse", "--show-toplevel")
    if done.returncode != 0:
        return None, f"{path} is not in a git working tree"
    root = os.fsdecode(done.stdout).strip()
    found = git(Path(root), "rev-parse", "--verify", "--quiet", "--end-of-options", f"{revision}^{{commit}}")
    if found.returncode != 0:
        return None, f"{revision} is an unknown git revision in {root}"
    return os.fsdecode(found.stdout).strip(), ""


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
def open_side(spec: SideSpec) -> Iterator[Side]:
    """The :class:`Side` ``spec`` names; a revision's copy exists while the ``with`` block runs."""
    revision, path = spec.revision, spec.path
    if revision is None:
        if not os.path.lexists(path):
            raise UserError(f"{path}: no such file or directory")
        yield Side(spec.label, Path(path))
        return
    root, inside = repository_path(path)
    commit = resolve_commit(root, revision)
    if not exists_at(root, commit, inside):
        raise UserError(f"{spec.label}: {revision} has no file {inside}")
    folder = package_folder(root, commit, inside)
    size = _tree_size(root, commit, folder)
    if size > MAX_BYTES:
        raise UserError(f"{spec.label}: the folder {folder} at {revision} holds {size / 1e6:.0f} MB, more than the "
                        f"{MAX_BYTES // 2**20} MiB ar3cli copies out of a revision")
    archive = git(root, "archive", "--format=tar", commit, "--", folder)
    if archive.returncode != 0:
        raise UserError(f"{spec.label}: git archive failed: {' '.join(os.fsdecode(archive.stderr).split())}")
    with tempfile.TemporaryDirectory(prefix="ar3cli-diff-") as temporary:
        copy = Path(temporary) / "rev"
        copy.mkdir()
        _extract(archive.stdout, copy)
        yield Side(spec.label, copy / inside, revision, copy, root)
