"""A git repository with this checkout as its pre-commit hook (the real pre-commit, as a user sets it up).

tests/test_pre_commit.py and tests/test_macro_library.py commit into one: :func:`hook_project` makes
it (skipping, with a reason, where pre-commit or git history is missing) and :meth:`HookProject.commit`
commits everything in it, running the hook.
"""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.conftest import REPO


@dataclass(frozen=True)
class HookProject:
    """``folder``, a git repository whose commits run ar3cli's hook; ``env`` the environment they run in."""

    folder: Path
    env: dict[str, str]

    def git(self, *args: str) -> subprocess.CompletedProcess:
        return subprocess.run(["git", *args], cwd=self.folder, env=self.env, capture_output=True, text=True,
                              timeout=600)

    def commit(self, message: str) -> subprocess.CompletedProcess:
        """``git add -A`` and ``git commit -m message`` (the hook runs): the commit's process."""
        self.git("add", "-A")
        return self.git("commit", "-m", message)


def hook_project(folder: Path, home: Path) -> HookProject:
    """``folder`` (made if missing) as a git repository whose ``.pre-commit-config.yaml`` names this checkout's
    HEAD as the hook repository, ``pre-commit install`` done; pre-commit's cache in ``home``."""
    pytest.importorskip("pre_commit", reason="pre-commit is part of the test extra")
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=REPO, capture_output=True, text=True)
    if head.returncode != 0:
        pytest.skip("the checkout is not a git repository")
    folder.mkdir(parents=True, exist_ok=True)
    env = {**os.environ, "PRE_COMMIT_HOME": str(home), "NO_COLOR": "1",
           "GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@example.com",
           "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@example.com",
           "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}
    project = HookProject(folder, env)
    project.git("init", "-q")
    (folder / ".pre-commit-config.yaml").write_text(
        f"repos:\n  - repo: {REPO}\n    rev: {head.stdout.strip()}\n    hooks:\n      - id: ar3cli-lint\n")
    installed = subprocess.run([sys.executable, "-m", "pre_commit", "install"], cwd=folder, env=env,
                               capture_output=True, text=True)
    assert installed.returncode == 0, installed.stderr
    return project
