"""The real pre-commit, with this checkout as the hook repository, blocks a broken URDF."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ASSETS, REPO


def _git(*args: str, cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run(["git", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_pre_commit_hook_blocks_broken_urdf_and_passes_good_one(tmp_path):
    pytest.importorskip("pre_commit", reason="pre-commit is part of the test extra")
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=REPO, capture_output=True, text=True)
    if head.returncode != 0:
        pytest.skip("the checkout is not a git repository")
    project = tmp_path / "robot_project"
    project.mkdir()
    env = {**os.environ, "PRE_COMMIT_HOME": str(tmp_path / "pre-commit-home"), "NO_COLOR": "1",
           "GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@example.com",
           "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@example.com",
           "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}
    _git("init", "-q", cwd=project, env=env)
    (project / ".pre-commit-config.yaml").write_text(
        f"repos:\n  - repo: {REPO}\n    rev: {head.stdout.strip()}\n    hooks:\n      - id: ar3cli-lint\n")
    installed = subprocess.run([sys.executable, "-m", "pre_commit", "install"], cwd=project, env=env,
                               capture_output=True, text=True)
    assert installed.returncode == 0, installed.stderr

    shutil.copy(ASSETS / "examples" / "ar3_no_inertia.urdf", project / "arm.urdf")
    _git("add", "-A", cwd=project, env=env)
    blocked = _git("commit", "-m", "broken arm", cwd=project, env=env)
    assert blocked.returncode != 0, blocked.stdout + blocked.stderr
    output = blocked.stdout + blocked.stderr
    assert "ar3cli" in output and "I001" in output and "arm.urdf" in output
    # pre-commit's output is not a terminal: one line per finding, no table rows of 200+ characters
    assert "arm.urdf:152:3: I001 [error] link 'link_4' moves" in output and "+---" not in output

    shutil.copy(ASSETS / "ar3" / "ar3.urdf", project / "arm.urdf")
    _git("add", "-A", cwd=project, env=env)
    passed = _git("commit", "-m", "fixed arm", cwd=project, env=env)
    assert passed.returncode == 0, passed.stdout + passed.stderr
