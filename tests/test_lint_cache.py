"""The lint result cache: unchanged files are answered from it, and any change it depends on is seen."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ar3cli import lint_cache, model
from ar3cli.cache import FileFacts
from ar3cli.lint import LintOptions, _result_cache, lint_paths

MESH_ROBOT = """<?xml version="1.0"?>
<robot name="r">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="{uri}"/></geometry></visual>
    <collision><geometry><mesh filename="{uri}"/></geometry></collision>
  </link>
</robot>
"""


def write_stl(path: Path, size: float) -> None:
    """An ASCII STL triangle spanning ``size`` (file units) along x, y and z."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex {size} 0 0\n"
                    f"vertex 0 {size} {size}\nendloop\nendfacet\nendsolid t\n", encoding="ascii")


@pytest.fixture
def store(tmp_path, monkeypatch) -> Path:
    """A private, empty result store (and cache folder) for one test; returns the folder."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("AR3CLI_CACHE_DIR", str(folder))
    monkeypatch.delenv("AR3CLI_NO_CACHE", raising=False)
    monkeypatch.setattr(lint_cache, "_STORE", FileFacts("lint-results", version=1))
    return folder


@pytest.fixture
def loads(monkeypatch) -> list[Path]:
    """Paths the linter really loaded (a cache hit loads nothing)."""
    loaded: list[Path] = []
    real = model.load_model

    def counting(path, *args, **kwargs):
        loaded.append(Path(path))
        return real(path, *args, **kwargs)

    monkeypatch.setattr(model, "load_model", counting)
    return loaded


def findings(path: Path, options: LintOptions | None = None, use_cache: bool = True) -> list[dict]:
    (result,) = lint_paths([path], options or LintOptions(), use_cache=use_cache)
    return [f.to_dict() for f in result.findings]


def codes(path: Path) -> set[str]:
    return {f["rule"] for f in findings(path)}


def test_an_unchanged_file_is_answered_from_the_cache(store, loads, write_urdf) -> None:
    path = write_urdf(MESH_ROBOT.format(uri="meshes/missing.stl"))
    first = findings(path)
    second = findings(path)
    assert loads == [path]
    assert second == first and "G001" in {f["rule"] for f in first}


def test_an_edited_file_is_checked_again_and_replaces_its_entry(store, loads, write_urdf) -> None:
    path = write_urdf(MESH_ROBOT.format(uri="meshes/missing.stl"))
    assert "G001" in codes(path)
    write_urdf(MESH_ROBOT.format(uri="meshes/missing.stl").replace('name="r"', ""))
    assert {"G001", "S001"} <= codes(path)
    assert len(loads) == 2
    assert len(lint_cache._STORE._load()) == 1  # a file edited a thousand times keeps one entry


def test_a_mesh_that_appears_or_disappears_is_noticed(store, loads, write_urdf, tmp_path) -> None:
    path = write_urdf(MESH_ROBOT.format(uri="meshes/part.stl"))
    assert "G001" in codes(path)
    write_stl(tmp_path / "meshes" / "part.stl", 0.1)  # its folder did not exist either
    assert "G001" not in codes(path)
    (tmp_path / "meshes" / "part.stl").unlink()
    assert "G001" in codes(path)
    assert len(loads) == 3


def test_a_mesh_rewritten_in_millimetres_is_noticed(store, loads, write_urdf, tmp_path) -> None:
    path = write_urdf(MESH_ROBOT.format(uri="meshes/part.stl"))
    write_stl(tmp_path / "meshes" / "part.stl", 0.1)
    assert "G006" not in codes(path)
    assert "G006" not in codes(path)
    write_stl(tmp_path / "meshes" / "part.stl", 100.0)
    assert "G006" in codes(path)
    assert len(loads) == 2


def test_other_settings_or_another_ar3cli_do_not_reuse_results(store, loads, write_urdf, monkeypatch) -> None:
    path = write_urdf(MESH_ROBOT.format(uri="meshes/missing.stl"))
    assert findings(path)
    assert findings(path, LintOptions(ignore=["G001"])) != findings(path)
    assert findings(path, LintOptions(ignore=["G001"])) != findings(path)  # both answered from the cache now
    assert len(loads) == 2
    monkeypatch.setenv("ROS_PACKAGE_PATH", "/nonexistent")
    findings(path)
    monkeypatch.setattr(lint_cache, "code_fingerprint", lambda: "ar3cli with an edited rule")
    findings(path)
    assert len(loads) == 4


def test_xacro_sim_and_no_cache_are_never_answered_from_it(store, loads, write_urdf, monkeypatch) -> None:
    xacro = write_urdf('<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r"><link name="base"/></robot>',
                       "robot.urdf.xacro")
    findings(xacro)
    findings(xacro)
    assert len(loads) == 2
    assert _result_cache(LintOptions(sim=True), []) is None
    urdf = write_urdf(MESH_ROBOT.format(uri="meshes/missing.stl"))
    findings(urdf, use_cache=False)
    findings(urdf, use_cache=False)
    monkeypatch.setenv("AR3CLI_NO_CACHE", "1")
    findings(urdf)
    findings(urdf)
    assert len(loads) == 6
    assert not lint_cache._STORE._load()  # nothing was remembered


def test_a_damaged_store_or_entry_means_checking_again(store, loads, write_urdf) -> None:
    path = write_urdf(MESH_ROBOT.format(uri="meshes/missing.stl"))
    store.mkdir()
    (store / "lint-results-v1.json").write_bytes(b"\x00not json")
    expected = findings(path)
    (entry,) = lint_cache._STORE._load().values()
    entry["findings"] = [["G001", "fatal"]]
    assert findings(path) == expected
    assert len(loads) == 2


def test_results_persist_between_processes(cli, tmp_path, write_urdf) -> None:
    """Two real runs: the second answers from the store the first saved, with identical output;
    a package.xml that appears later changes how package:// resolves, and is noticed."""
    path = write_urdf(MESH_ROBOT.format(uri="package://mypkg/meshes/part.stl"), "mypkg/urdf/robot.urdf")
    write_stl(tmp_path / "mypkg" / "meshes" / "part.stl", 0.1)
    env = {"AR3CLI_CACHE_DIR": str(tmp_path / "cache")}
    first = cli("lint-urdf", "-f", "json", "--no-config", str(path), env=env)
    store = json.loads((tmp_path / "cache" / "lint-results-v1.json").read_text())
    second = cli("lint-urdf", "-f", "json", "--no-config", str(path), env=env)
    assert len(store) == 1 and second.stdout == first.stdout and first.stderr == second.stderr == ""
    assert {f["rule"] for f in json.loads(first.stdout)["findings"]} == set()  # the folder is named mypkg
    (tmp_path / "mypkg").rename(tmp_path / "renamed")
    moved = tmp_path / "renamed" / "urdf" / "robot.urdf"
    before = cli("lint-urdf", "-f", "json", "--no-config", str(moved), env=env)
    assert "G001" in {f["rule"] for f in json.loads(before.stdout)["findings"]}  # no folder is named mypkg now
    (tmp_path / "renamed" / "package.xml").write_text("<package><name>mypkg</name></package>")
    after = cli("lint-urdf", "-f", "json", "--no-config", str(moved), env=env)
    assert json.loads(after.stdout)["findings"] == []  # the package.xml names the folder mypkg
    uncached = cli("lint-urdf", "-f", "json", "--no-config", "--no-cache", str(moved), env=env)
    assert uncached.stdout == after.stdout
