"""Decisions tested with more than one candidate, and mappings tested for every value they map.

Each test here exists because a small, realistic bug survived the whole suite (issue 39's mutation
spot-check): a decision that was only ever asked with one candidate, or a mapping whose other
values no test looked at. ``benchmarks/mutations.py`` re-applies those bugs and checks that this
suite catches each of them.
"""

from __future__ import annotations

import json
import math
import os
import sqlite3
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

from ar3cli.lint.rules.base import arm
from tests.conftest import REPO, run_cli


# ---- SARIF: every severity has its own level ---------------------------------------------------------
def test_sarif_level_follows_each_findings_severity(tmp_path):
    """error -> error, warning -> warning, info -> note: the level of every result, not of errors only."""
    (tmp_path / "error.urdf").write_text(arm(joint_extra=""))  # J001: no <limit>
    (tmp_path / "warning.urdf").write_text(arm(joint_extra='<limit lower="-1" upper="1" effort="0" velocity="1"/>'))
    (tmp_path / "info.urdf").write_text(arm().replace('<link name="base">', '<link name="base"><visual><geometry>'
                                                      '<box size="0.1 0.1 0.1"/></geometry><material name="nowhere"/>'
                                                      '</visual>', 1))
    args = ("lint-urdf", str(tmp_path), "--no-cache", "--no-config", "--exit-zero")
    findings = json.loads(run_cli(*args, "--format", "json", cwd=tmp_path).stdout)["findings"]
    severities = {finding["rule"]: finding["severity"] for finding in findings}
    assert set(severities.values()) == {"error", "warning", "info"}, severities
    results = json.loads(run_cli(*args, "--format", "sarif", cwd=tmp_path).stdout)["runs"][0]["results"]
    expected = {"error": "error", "warning": "warning", "info": "note"}
    assert {result["ruleId"]: result["level"] for result in results} == {
        rule: expected[severity] for rule, severity in severities.items()}


# ---- inertia rotation: R I R^T, checked against rotated point masses ----------------------------------
def test_rotated_inertia_equals_the_inertia_of_the_rotated_body():
    """A body of point masses rotated by R has the tensor R I R^T; R^T I R is another tensor unless R
    happens to be its own inverse (a 90-degree roll of a diagonal tensor is: that test could not tell)."""
    from ar3cli.maths import mass_properties as mp

    rng = np.random.default_rng(7)
    points = rng.normal(size=(6, 3)) * [0.3, 0.1, 0.05]
    masses = rng.uniform(0.5, 2.0, size=6)

    def point_masses(positions: np.ndarray) -> mp.MassProperties:
        com = (masses[:, None] * positions).sum(axis=0) / masses.sum()
        relative = positions - com
        inertia = sum(m * (r @ r * np.eye(3) - np.outer(r, r)) for m, r in zip(masses, relative))
        return mp.MassProperties(float(masses.sum()), com, inertia)

    body = point_masses(points)
    assert abs(body.inertia[0, 1]) > 1e-4  # products of inertia: the order of R and R^T matters
    for rpy in [(0.3, -0.4, 1.1), (0.0, 0.0, math.radians(30)), (1.2, 0.7, -2.0)]:
        rotation = mp.rpy_to_matrix(rpy)
        expected = point_masses(points @ rotation.T + [0.1, -0.2, 0.3])
        moved = mp.transformed(body, xyz=(0.1, -0.2, 0.3), rpy=rpy)
        np.testing.assert_allclose(moved.com, expected.com, atol=1e-12)
        np.testing.assert_allclose(moved.inertia, expected.inertia, atol=1e-12)


# ---- the collision matrix: a pair seen only at a joint limit ------------------------------------------
def test_a_pair_that_touches_only_at_a_joint_limit_is_sometimes_not_never():
    """Two pairs, both never in contact in the uniform samples: the one that touched at a limit
    sample is "sometimes" (MoveIt must keep checking it), the other "never"."""
    from ar3cli.collisions.matrix import classify

    links = ["base", "upper", "fore", "hand"]
    pairs = [(0, 2), (0, 3), (1, 3)]
    results = classify(links, pairs, counts=[0, 0, 40], samples=100, adjacent={frozenset(("base", "upper"))},
                       home_hits=set(), limit_hits={0: ["elbow at upper limit"]})
    categories = {(r.link_a, r.link_b): r.category for r in results}
    assert categories == {("base", "fore"): "sometimes", ("base", "hand"): "never", ("upper", "hand"): "sometimes"}
    assert results[0].limit_hits == ["elbow at upper limit"]


def test_always_threshold_edges():
    """95 of 100 samples is "always" (the threshold is inclusive), 94 is "sometimes"."""
    from ar3cli.collisions.matrix import classify

    results = classify(["a", "b", "c"], [(0, 1), (0, 2)], counts=[95, 94], samples=100, adjacent=set(),
                       home_hits=set(), limit_hits={})
    assert [r.category for r in results] == ["always", "sometimes"]


# ---- robot diff: two renamed candidates, one of the same joint type --------------------------------
TWO_CHILDREN = """<?xml version="1.0"?>
<robot name="twin">
  <link name="base"/>
  <joint name="{first}" type="{first_type}">
    <parent link="base"/><child link="{first}_link"/>
    <origin xyz="0 0 {first_z}"/><axis xyz="0 0 1"/>{first_limit}
  </joint>
  <link name="{first}_link"/>
  <joint name="{second}" type="{second_type}">
    <parent link="base"/><child link="{second}_link"/>
    <origin xyz="0 0 {second_z}"/><axis xyz="0 0 1"/>{second_limit}
  </joint>
  <link name="{second}_link"/>
</robot>
"""
LIMIT = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'


def _twin(tmp_path: Path, name: str, first: tuple[str, str, float], second: tuple[str, str, float]):
    from ar3cli.urdf.model import load_model

    fields = {}
    for key, (joint, kind, z) in (("first", first), ("second", second)):
        fields.update({key: joint, f"{key}_type": kind, f"{key}_z": z,
                       f"{key}_limit": LIMIT if kind == "revolute" else ""})
    path = tmp_path / name
    path.write_text(TWO_CHILDREN.format(**fields))
    return load_model(path)


def test_diff_pairs_a_renamed_joint_with_the_candidate_of_its_own_type(tmp_path):
    """Both joints renamed and their origins swapped: by position alone each would pair with the
    other type; the type decides (a revolute joint stays the revolute one)."""
    from ar3cli.robot_diff.match import match

    old = _twin(tmp_path, "old.urdf", ("hinge", "revolute", 0.10), ("weld", "fixed", 0.11))
    new = _twin(tmp_path, "new.urdf", ("weld2", "fixed", 0.10), ("hinge2", "revolute", 0.11))
    matching = match(old, new)
    assert matching.joints == {"hinge": "hinge2", "weld": "weld2"}
    assert matching.links["hinge_link"] == "hinge2_link" and matching.links["weld_link"] == "weld2_link"


def test_diff_pairs_same_type_candidates_by_position(tmp_path):
    """The other side of the same decision: two candidates of one type pair by their origins."""
    from ar3cli.robot_diff.match import match

    old = _twin(tmp_path, "old.urdf", ("a", "revolute", 0.10), ("b", "revolute", 0.30))
    new = _twin(tmp_path, "new.urdf", ("b2", "revolute", 0.30), ("a2", "revolute", 0.10))
    assert match(old, new).joints == {"a": "a2", "b": "b2"}


# ---- scan: a row stored with other settings is checked again --------------------------------------
def _scan(folder: Path, store: Path, *extra: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(REPO), "AR3CLI_NO_CACHE": "1"}
    done = subprocess.run([sys.executable, "-m", "ar3cli", "scan", str(folder), "--store", str(store), "-f", "json",
                           *extra], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def test_scan_checks_again_a_row_stored_with_other_settings(tmp_path):
    folder = tmp_path / "robots"
    folder.mkdir()
    for index in range(2):
        (folder / f"r{index}.urdf").write_text(arm())
    store = tmp_path / "scan.sqlite"
    assert _scan(folder, store)["checked"] == 2
    assert _scan(folder, store)["checked"] == 0  # same settings: nothing to do
    assert _scan(folder, store, "--select", "J")["checked"] == 2  # other rules: another settings key
    assert _scan(folder, store, "--select", "J")["checked"] == 0
    with sqlite3.connect(store) as db:
        assert len({row[0] for row in db.execute("SELECT settings FROM files")}) == 1


# ---- atomic writes: a folder nobody may write in, even as root -------------------------------------
def test_a_folder_where_no_temporary_file_can_be_made_is_one_user_error(tmp_path, monkeypatch):
    """The "cannot write in this folder" branch, reached whoever runs the tests (root may write anywhere)."""
    from ar3cli.errors import UserError
    from ar3cli.infra.atomic import atomic_write

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    target = tmp_path / "robot.urdf"
    target.write_bytes(b"old")
    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    with pytest.raises(UserError, match=r"cannot write in .*Permission denied"):
        atomic_write(target, b"new")
    assert target.read_bytes() == b"old"


# ---- package:// resolution: every candidate present, the first in the documented order wins ------------
def _mesh(folder: Path, label: str) -> Path:
    (folder / "meshes").mkdir(parents=True, exist_ok=True)
    (folder / "meshes" / "m.stl").write_text(label)
    return folder


def test_package_search_order_with_every_candidate_present(tmp_path):
    """--package-path, then ROS_PACKAGE_PATH's entries in order, then AMENT_PREFIX_PATH, then the nearest
    ancestor package, then a farther one (ar3cli.urdf.packages): each removed in turn hands over to the next."""
    import shutil

    from ar3cli.urdf.packages import PackageResolver

    outer, near = tmp_path / "outer", tmp_path / "outer" / "near"
    (near / "urdf").mkdir(parents=True)
    for folder in (outer, near):
        (folder / "package.xml").write_text("<package><name>parts</name></package>")
        _mesh(folder, folder.name)
    option = _mesh(tmp_path / "option", "option")
    ros = [_mesh(tmp_path / entry / "parts", entry) for entry in ("ros1", "ros2")]
    ament = _mesh(tmp_path / "ament" / "share" / "parts", "ament")
    environ = {"ROS_PACKAGE_PATH": f"{tmp_path / 'ros1'}:{tmp_path / 'ros2'}", "AMENT_PREFIX_PATH": str(tmp_path / "ament")}

    def winner(package_paths: dict) -> str:
        found = PackageResolver(near / "urdf", package_paths, environ=environ).resolve("package://parts/meshes/m.stl")
        return found.path.read_text()

    assert winner({"parts": option}) == "option"
    for folder, label in ((ros[0], "ros1"), (ros[1], "ros2"), (ament, "ament")):
        assert winner({}) == label
        shutil.rmtree(folder)
    assert winner({}) == "near"
    (near / "package.xml").unlink()
    assert winner({}) == "outer"


def test_pybullet_fallback_search_takes_the_nearest_folder(tmp_path):
    """No package anywhere: PyBullet's own search finds the file in the robot's folder before a folder above."""
    from ar3cli.urdf.packages import PackageResolver

    here = tmp_path / "a" / "b"
    _mesh(here / "parts", "nearest")
    _mesh(tmp_path / "a" / "parts", "above")
    found = PackageResolver(here, {}, environ={}).resolve("package://parts/meshes/m.stl")
    assert found.via == "pybullet-search" and found.path.read_text() == "nearest"
    (here / "parts" / "meshes" / "m.stl").unlink()
    assert PackageResolver(here, {}, environ={}).resolve("package://parts/meshes/m.stl").path.read_text() == "above"


def test_xacro_find_takes_the_package_path_option_over_the_ancestor_package(tmp_path):
    """$(find parts) in a xacro include: the --package-path folder, not the package the robot file sits in."""
    from ar3cli.urdf.model import load_model

    home = tmp_path / "parts"
    (home / "urdf").mkdir(parents=True)
    (home / "package.xml").write_text("<package><name>parts</name></package>")
    other = tmp_path / "other"
    (other / "urdf").mkdir(parents=True)
    for folder, link in ((home, "from_ancestor"), (other, "from_option")):
        (folder / "urdf" / "part.xacro").write_text(
            f'<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="{link}"/></robot>')
    robot = home / "urdf" / "robot.urdf.xacro"
    robot.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                     '<xacro:include filename="$(find parts)/urdf/part.xacro"/></robot>')
    assert [link.name for link in load_model(robot).links] == ["from_ancestor"]
    assert [link.name for link in load_model(robot, {"parts": other}).links] == ["from_option"]


# ---- fix-mesh-paths: nested --package folders, the deepest owns the file ---------------------------------
def test_mesh_paths_owner_is_the_deepest_package_whatever_the_order_given(tmp_path):
    from ar3cli.fix.mesh_paths_plan import _owner

    outer, inner = tmp_path / "ws", tmp_path / "ws" / "src" / "arm"
    target = inner / "meshes" / "m.stl"
    assert _owner(target, {"ws": outer, "arm": inner}) == "arm"
    assert _owner(target, {"arm": inner, "ws": outer}) == "arm"
    assert _owner(outer / "other.stl", {"arm": inner, "ws": outer}) == "ws"


# ---- [tool.ar3cli.lint]: the nearest pyproject.toml ------------------------------------------------------
def test_nearest_pyproject_configures_the_lint(tmp_path):
    from ar3cli.lint.config import load_config

    inner = tmp_path / "robots" / "arm"
    inner.mkdir(parents=True)
    (tmp_path / "pyproject.toml").write_text('[tool.ar3cli.lint]\nselect = ["G"]\n')
    (tmp_path / "robots" / "pyproject.toml").write_text('[tool.ar3cli.lint]\nselect = ["J"]\n')
    assert load_config(inner).select == ["J"]
    assert load_config(tmp_path).select == ["G"]


# ---- P005: the parent a child is measured against is its nearest ancestor with geometry ----------------
def test_pass_through_parent_is_the_nearest_ancestor_with_collision_geometry(tmp_path):
    from ar3cli.sim.pass_through import _geometric_parent
    from ar3cli.urdf.model import load_model

    chain = [("base", "mid"), ("mid", "frame"), ("frame", "tip")]
    path = tmp_path / "robot.urdf"
    path.write_text('<robot name="r">' + "".join(f'<link name="{name}"/>' for name in ("base", "mid", "frame", "tip"))
                    + "".join(f'<joint name="{b}_joint" type="fixed"><parent link="{a}"/><child link="{b}"/></joint>'
                              for a, b in chain) + "</robot>")
    model = load_model(path)
    assert _geometric_parent(model, "tip", {"base", "mid", "tip"}) == "mid"  # through the frame, not past mid
    assert _geometric_parent(model, "tip", {"base", "tip"}) == "base"
