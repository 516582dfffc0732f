"""A xacro file that only defines macros (or properties, or materials) is a library, not a broken robot
(issue 36 item 1): one info line (F008, naming the entry file that includes it) in lint, every format,
the pre-commit hook, scan and info; tests/data/xacro_library is a description package with an entry
file and three such libraries."""

from __future__ import annotations

import json
import os
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO
from tests.hook_project import hook_project

PACKAGE = Path(__file__).parent / "data" / "xacro_library"
LIBRARIES = ("urdf/leg.xacro", "urdf/materials.xacro", "urdf/utils/inertia.xacro")


def test_lint_gives_each_library_one_info_line_naming_its_includer(cli):
    result = cli("lint-urdf", "--no-cache", "--format", "json", str(PACKAGE.relative_to(REPO)))
    assert result.code == 0, result.stderr
    findings = json.loads(result.stdout)["findings"]
    by_file: dict[str, list] = {}
    for finding in findings:
        by_file.setdefault(finding["path"], []).append(finding)
    assert set(by_file) == {f"tests/data/xacro_library/{name}" for name in LIBRARIES}  # the entry file is clean
    for found in by_file.values():
        (finding,) = found
        assert finding["rule"] == "F008" and finding["severity"] == "info" and finding["line"] == 2, finding
        assert "instantiates no robot" in finding["message"]
    assert "included by tests/data/xacro_library/urdf/robot.urdf.xacro" in by_file[
        "tests/data/xacro_library/urdf/leg.xacro"][0]["message"]
    assert "included by tests/data/xacro_library/urdf/leg.xacro" in by_file[
        "tests/data/xacro_library/urdf/utils/inertia.xacro"][0]["message"]


@pytest.mark.parametrize("fmt", ["text", "github", "markdown", "sarif", "junit"])
def test_every_format_says_it_once_and_passes(cli, fmt):
    result = cli("lint-urdf", "--no-cache", "--format", fmt, "--no-group", str(PACKAGE.relative_to(REPO)))
    assert result.code == 0, result.stdout + result.stderr
    if fmt == "sarif":  # the run lists every rule's documentation: its results are what it says
        output = " ".join(result["ruleId"] for result in json.loads(result.stdout)["runs"][0]["results"])
    else:
        output = result.stdout + result.stderr
    assert output.count("F008") >= len(LIBRARIES) and "S011" not in output and "S001" not in output


def test_a_library_whose_code_is_ignored_says_nothing_and_other_rules_stay_silent(cli):
    result = cli("lint-urdf", "--no-cache", "--format", "json", "--ignore", "F008", str(PACKAGE / "urdf" / "leg.xacro"))
    assert result.code == 0 and json.loads(result.stdout)["findings"] == []


def test_info_on_a_library_is_one_line(cli):
    text = cli("info", str(PACKAGE / "urdf" / "leg.xacro"))
    assert text.code == 0 and "a xacro library, not a robot" in text.stdout and "(no name)" not in text.stdout
    data = json.loads(cli("info", "--format", "json", str(PACKAGE / "urdf" / "leg.xacro")).stdout)
    assert data["macro_library"]["macros"] == ["leg"] and data["macro_library"]["properties"] == 2
    assert data["macro_library"]["included_by"][0].endswith("robot.urdf.xacro")


def test_scan_stores_the_library_with_its_info_line(tmp_path):
    store = tmp_path / "scan.sqlite"
    env = {**os.environ, "PYTHONPATH": str(REPO), "AR3CLI_NO_CACHE": "1"}
    done = subprocess.run([sys.executable, "-m", "ar3cli", "scan", str(PACKAGE), "--store", str(store), "-f", "json",
                           "--jobs", "1"], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    with sqlite3.connect(store) as db:
        rows = dict(db.execute("SELECT path, findings FROM files").fetchall())
    for name in LIBRARIES:
        assert [f["rule"] for f in json.loads(rows[str((PACKAGE / name).resolve())])] == ["F008"]
    assert json.loads(rows[str((PACKAGE / "urdf" / "robot.urdf.xacro").resolve())]) == []


@pytest.mark.slow
def test_the_pre_commit_hook_passes_a_package_with_macro_files(tmp_path):
    """As tests/test_pre_commit.py: the real pre-commit, this checkout as the hook repository."""
    shutil.copytree(PACKAGE, tmp_path / "robot_project")
    project = hook_project(tmp_path / "robot_project", tmp_path / "pre-commit-home")
    committed = project.commit("a description package with macro files")
    output = committed.stdout + committed.stderr
    assert committed.returncode == 0, output
    assert "S011" not in output and "S001" not in output


def test_an_includer_names_the_file_in_an_include_not_anywhere_in_its_text(tmp_path):
    """``e.xacro`` inside ``.secret_name.xacro`` made a stranger's include of a secret an includer of
    ``e.xacro`` (its F004 became an F008 info: existence told apart); a glob that matches the name counts."""
    from ar3cli.urdf.macro_library import includers

    (tmp_path / "e.xacro").write_text("<robot/>")
    (tmp_path / "d.xacro").write_text('<robot><xacro:include filename="parts/.secret_name.xacro"/></robot>')
    assert includers(tmp_path / "e.xacro") == ()
    (tmp_path / "g.xacro").write_text("<robot><xacro:include filename='$(find p)/*.xacro'/></robot>")
    (tmp_path / "h.urdf").write_text('<robot><include filename="sub/e.xacro" /></robot>')
    assert sorted(Path(name).name for name in includers(tmp_path / "e.xacro")) == ["g.xacro", "h.urdf"]
