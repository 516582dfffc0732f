"""The CI recipes in docs/ci.md work: every run/script line is executed here on the bundled AR3."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys

import pytest
import yaml
from lxml import etree

from tests.conftest import ASSETS, REPO

CI_DOC = REPO / "docs" / "ci.md"


def _yaml_blocks() -> list:
    text = CI_DOC.read_text(encoding="utf-8")
    return [yaml.safe_load(block) for block in re.findall(r"```yaml\n(.*?)```", text, re.DOTALL)]


def _recipe_commands() -> list[tuple[str, str]]:
    """(ci system, command) for every command line in the GitHub Actions and GitLab CI recipes."""
    commands: list[tuple[str, str]] = []
    for document in _yaml_blocks():
        if "jobs" in document:
            for job in document["jobs"].values():
                commands += [("github", step["run"]) for step in job["steps"] if "run" in step]
        else:
            for job in document.values():
                if isinstance(job, dict) and "script" in job:
                    commands += [("gitlab", line) for line in job["script"]]
    unique = list(dict.fromkeys(commands))
    return [(system, command) for system, command in unique if not command.startswith("pip install")]


def test_recipes_are_found():
    systems = {system for system, _ in _recipe_commands()}
    assert systems == {"github", "gitlab"}
    assert any("--format sarif" in command for _, command in _recipe_commands())


@pytest.mark.slow
@pytest.mark.parametrize(("system", "command"), _recipe_commands())
def test_recipe_command_runs(system, command, tmp_path):
    (tmp_path / "assets").symlink_to(ASSETS, target_is_directory=True)
    summary = tmp_path / "step_summary.md"
    env = {**os.environ, "PYTHONPATH": str(REPO), "NO_COLOR": "1"}
    if system == "github":
        env["GITHUB_STEP_SUMMARY"] = str(summary)
    shell_command = re.sub(r"^ar3cli ", f'"{sys.executable}" -m ar3cli ', command)
    done = subprocess.run(["bash", "-euo", "pipefail", "-c", shell_command], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600, stdin=subprocess.DEVNULL)
    assert done.returncode == 0, f"{command}\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}"
    if "--format github" in command:
        assert "## ar3cli lint-urdf" in summary.read_text()
    for produced in tmp_path.iterdir():
        if produced.suffix in (".json", ".sarif"):
            document = json.loads(produced.read_text())
            if produced.suffix == ".sarif":
                assert document["version"] == "2.1.0"
            if produced.name == "grasp.json":
                assert document["success_rate"] >= 0.95 or document.get("success") is True
        elif produced.suffix == ".srdf":
            root = etree.parse(str(produced)).getroot()
            assert root.tag == "robot" and root.findall("disable_collisions")
