"""The lint result cache: unchanged files are answered from it, and any change it depends on is seen."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from ar3cli.infra import file_cache as cache
from ar3cli.infra.file_cache import FileFacts, shard_of
from ar3cli.lint import result_cache as lint_cache
from ar3cli.lint.engine import LintOptions, _result_cache, lint_paths
from ar3cli.urdf import model
from tests.conftest import cache_entries, cache_files

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
    """A binary STL triangle spanning ``size`` (file units) along x, y and z (an ASCII STL is G011:
    PyBullet and MuJoCo cannot read it)."""
    import struct

    path.parent.mkdir(parents=True, exist_ok=True)
    corners = (0, 0, 0, size, 0, 0, 0, size, size)
    path.write_bytes(b"t".ljust(80) + struct.pack("<I", 1) + struct.pack("<12f", 0, 0, 1, *corners) + b"\0\0")


@pytest.fixture(autouse=True)
def in_this_process(monkeypatch) -> None:
    """Lint here, not in a forked worker, so that the tests see what the linter loads (a worker's
    answers and cache entries come back the same: tests/test_hostile_inputs.py)."""
    from ar3cli.infra import process_pool

    monkeypatch.setattr(process_pool, "can_fork", lambda: False)


@pytest.fixture
def store(tmp_path, monkeypatch) -> Path:
    """A private, empty result store (and cache folder) for one test; returns the folder."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("AR3CLI_CACHE_DIR", str(folder))
    monkeypatch.delenv("AR3CLI_NO_CACHE", raising=False)
    store = FileFacts("lint-results", version=1)
    monkeypatch.setattr(lint_cache, "_STORE", store)
    monkeypatch.setitem(cache._OPEN, "lint-results", store)  # what workers' facts merge into
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
    assert sum(map(len, lint_cache._STORE._shards.values())) == 1  # a file edited a thousand times keeps one entry


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
    assert not any(lint_cache._STORE._shards.values())  # nothing was remembered


def test_a_damaged_store_or_entry_means_checking_again(store, loads, write_urdf) -> None:
    path = write_urdf(MESH_ROBOT.format(uri="meshes/missing.stl"))
    (store / "lint-results-v1").mkdir(parents=True)
    (store / "lint-results-v1" / f"{shard_of(path)}.json").write_bytes(b"\x00not json")
    expected = findings(path)
    (entry,) = [entry for shard in lint_cache._STORE._shards.values() for entry in shard.values()]
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
    store = cache_entries(tmp_path / "cache", "lint-results-v1")
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


def test_a_repointed_symlinked_folder_is_another_file(store, loads, tmp_path, monkeypatch) -> None:
    """current -> A (mesh present), then current -> B (same URDF bytes, no mesh): checked again."""
    for name in ("A", "B"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "robot.urdf").write_text(MESH_ROBOT.format(uri="meshes/base.stl"))
    write_stl(tmp_path / "A" / "meshes" / "base.stl", 0.1)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "current").symlink_to("A")
    assert "G001" not in codes(Path("current/robot.urdf"))
    (tmp_path / "current").unlink()
    (tmp_path / "current").symlink_to("B")
    assert "G001" in codes(Path("current/robot.urdf"))
    assert len(loads) == 2


def test_a_dotdot_through_a_symlink_is_not_merged_with_another_file(store, loads, tmp_path, monkeypatch) -> None:
    """link/../r.urdf is sub/r.urdf (the OS follows the link), not r.urdf beside it."""
    (tmp_path / "sub" / "deep").mkdir(parents=True)
    text = MESH_ROBOT.format(uri="meshes/base.stl")
    (tmp_path / "r.urdf").write_text(text)
    (tmp_path / "sub" / "r.urdf").write_text(text)
    write_stl(tmp_path / "sub" / "meshes" / "base.stl", 0.1)
    (tmp_path / "link").symlink_to("sub/deep")
    monkeypatch.chdir(tmp_path)
    both = lint_paths([Path("link/../r.urdf"), Path("r.urdf")], LintOptions())
    assert [r.path for r in both] == ["link/../r.urdf", "r.urdf"]
    assert [{f.rule for f in r.findings} >= {"G001"} for r in both] == [False, True]
    assert "G001" in codes(Path("r.urdf"))  # answered for r.urdf itself, not from sub/r.urdf's entry


def test_a_dependency_that_changes_during_the_check_makes_the_entry_stale(store, loads, write_urdf, tmp_path,
                                                                           monkeypatch) -> None:
    """States are recorded when a path is looked at: a mesh deleted after that, before the entry is
    stored, cannot hide behind its new state."""
    import ar3cli.lint.engine as engine

    path = write_urdf(MESH_ROBOT.format(uri="meshes/part.stl"))
    write_stl(tmp_path / "meshes" / "part.stl", 0.1)
    real = engine.lint_model

    def lint_then_delete(*args, **kwargs):
        result = real(*args, **kwargs)
        (tmp_path / "meshes" / "part.stl").unlink()  # e.g. a git checkout while the hook runs
        return result

    monkeypatch.setattr(engine, "lint_model", lint_then_delete)
    assert "G001" not in codes(path)
    monkeypatch.setattr(engine, "lint_model", real)
    assert "G001" in codes(path)
    assert len(loads) == 2


@pytest.mark.parametrize("damage", ["nested", "fifo", "types"])
def test_a_damaged_store_never_breaks_a_run(store, cli, write_urdf, damage, tmp_path) -> None:
    path = write_urdf(MESH_ROBOT.format(uri="meshes/part.stl").replace('name="r"', ""))  # S001: no name
    write_stl(tmp_path / "meshes" / "part.stl", 0.1)
    env = {"AR3CLI_CACHE_DIR": str(store)}
    clean = cli("lint-urdf", "--no-cache", "--no-config", "-f", "sarif", str(path), env=env)
    cli("lint-urdf", "--no-config", str(path), env=env)
    (results,) = cache_files(store, "lint-results-v1")
    (meshes,) = cache_files(store, "mesh-bounds-v2")
    if damage == "nested":
        for target in (results, meshes):
            target.write_text("[" * 5000 + "]" * 5000)
    elif damage == "fifo":
        results.unlink()
        os.mkfifo(results)
    else:
        entries = json.loads(results.read_text())
        for entry in entries.values():
            entry["findings"] = [[f[0], f[1], None, [1], f[4], f[5]] for f in entry["findings"]]
        results.write_text(json.dumps(entries))
        meshes.write_text(json.dumps({key: "junk" for key in json.loads(meshes.read_text())}))
    for fmt in ("sarif", "github", "json"):
        result = cli("lint-urdf", "--no-config", "-f", fmt, str(path), env=env, timeout=60)
        assert result.code == 1 and "error" not in result.stderr, result.stderr
    assert cli("lint-urdf", "--no-config", "-f", "sarif", str(path), env=env).stdout == clean.stdout
