"""The real pre-commit, with this checkout as the hook repository, blocks a broken URDF."""

from __future__ import annotations

import shutil

import pytest

from tests.conftest import ASSETS, REPO
from tests.hook_project import hook_project


@pytest.mark.slow
def test_pre_commit_hook_blocks_broken_urdf_and_passes_good_one(tmp_path):
    project = hook_project(tmp_path / "robot_project", tmp_path / "pre-commit-home")
    shutil.copy(ASSETS / "examples" / "ar3_no_inertia.urdf", project.folder / "arm.urdf")
    blocked = project.commit("broken arm")
    assert blocked.returncode != 0, blocked.stdout + blocked.stderr
    output = blocked.stdout + blocked.stderr
    assert "ar3cli" in output and "I001" in output and "arm.urdf" in output
    # pre-commit's output is not a terminal: one line per finding, no table rows of 200+ characters
    assert "arm.urdf:152:3: I001 [error] link 'link_4' moves" in output and "+---" not in output

    shutil.copy(ASSETS / "ar3" / "ar3.urdf", project.folder / "arm.urdf")
    passed = project.commit("fixed arm")
    assert passed.returncode == 0, passed.stdout + passed.stderr


def test_each_hook_runs_ar3cli_once_per_commit():
    """pre-commit splits the files of a hook without require_serial into one batch per CPU: a commit of a
    folder printed two summary lines (found on the newcomer walk). ar3cli shares files across CPUs itself."""
    yaml = pytest.importorskip("yaml", reason="PyYAML comes with pre-commit (the test extra)")
    hooks = yaml.safe_load((REPO / ".pre-commit-hooks.yaml").read_text())
    assert hooks and all(hook.get("require_serial") is True for hook in hooks), hooks
