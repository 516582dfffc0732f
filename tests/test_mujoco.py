"""MuJoCo: lint-urdf --sim --engine mujoco (M rules) and cross-check, with the real engine and small fixtures."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from ar3cli.sim.mujoco_session import mujoco_available

pytestmark = pytest.mark.skipif(not mujoco_available(), reason="mujoco is not installed (pip install 'ar3cli[mujoco]')")

DATA = Path(__file__).parent / "data" / "mujoco"
MIMIC = DATA / "gripper_arm.urdf"
FREE = DATA / "gripper_arm_free.urdf"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "ar3cli", *args], capture_output=True, text=True, timeout=300)


def test_cross_check_names_the_mimic_joint_and_the_engine_that_enforces_it():
    result = run("cross-check", str(MIMIC), "-n", "2", "--format", "json")
    assert result.returncode == 1, result.stderr
    data = json.loads(result.stdout)
    assert not data["agree"] and data["seed"] == 0
    (diagnosis,) = data["diagnoses"]
    assert "'finger_right_joint' mimics 'finger_left_joint'" in diagnosis and "MuJoCo enforces it" in diagnosis
    assert "PyBullet ignores it" in diagnosis and "line 38" in diagnosis


def test_cross_check_holds_the_joints_nothing_couples():
    """The reaction of a mimic constraint turns a light arm in MuJoCo (ERD's panda: panda_joint6 when
    panda_finger_joint1 moves): the probe holds every joint without <mimic>, so no undiagnosed row is left."""
    result = run("cross-check", str(DATA / "gripper_arm_light.urdf"), "-n", "1", "--format", "json")
    data = json.loads(result.stdout)
    constraint = [row for row in data["rows"] if row["quantity"].startswith("constraint")]
    assert [row["where"] for row in constraint] == ["'finger_right_joint' when 'finger_left_joint' moves +0.005"]
    assert all(row["diagnosis"] for row in data["rows"]), data["rows"]


def test_cross_check_agrees_without_the_mimic():
    result = run("cross-check", str(FREE), "-n", "2", "--seed", "3")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "agree:" in result.stdout and "fuses 1 link" in result.stdout


def test_cross_check_stability_runs_both_engines_at_two_timesteps():
    result = run("cross-check", str(FREE), "-n", "1", "--stability", "--format", "json")
    assert result.returncode == 0, result.stderr
    drops = json.loads(result.stdout)["stability"]
    assert [d["engine"] for d in drops] == ["pybullet", "pybullet", "mujoco", "mujoco"]
    assert all(d["stable"] for d in drops)


def test_lint_engine_mujoco_maps_the_compile_error_to_the_link_line(tmp_path):
    from ar3cli.lint.rules.base import arm
    from ar3cli.lint.rules.mujoco import TOO_LIGHT

    path = tmp_path / "r.urdf"
    path.write_text(arm(link_extra=TOO_LIGHT))  # a link without <inertial> is I001's: M001 would restate it
    result = run("lint-urdf", "--sim", "--engine", "mujoco", "--select", "M", "--format", "json", str(path))
    findings = json.loads(result.stdout)["findings"]
    (finding,) = [f for f in findings if f["rule"] == "M001"]
    assert "mjMINVAL" in finding["message"] and finding["line"] == 4  # <link name="arm">


def test_collada_and_missing_meshes_are_boxed_and_reported(tmp_path):
    from ar3cli.lint.rules.base import LINK_INERTIAL, robot

    (tmp_path / "part.dae").write_text("<COLLADA/>")
    (tmp_path / "ascii.stl").write_bytes(_cube_stl(0.1, binary=False))
    (tmp_path / "binary.stl").write_bytes(_cube_stl(0.1))
    path = tmp_path / "r.urdf"
    path.write_text(robot(f"""
        <link name="base">{LINK_INERTIAL}<collision><geometry><mesh filename="part.dae"/></geometry></collision>
          <collision><geometry><mesh filename="gone.stl"/></geometry></collision>
          <collision><geometry><mesh filename="ascii.stl"/></geometry></collision>
          <collision><geometry><mesh filename="binary.stl"/></geometry></collision></link>"""))
    result = run("lint-urdf", "--sim", "--engine", "all", "--select", "M,G", "--format", "json", str(path))
    findings = json.loads(result.stdout)["findings"]
    by_rule = {rule: [f["message"] for f in findings if f["rule"] == rule] for rule in ("M002", "G001", "G011")}
    (collada,) = by_rule["M002"]  # the missing and the ASCII mesh are G001's and G011's, said once
    assert "part.dae" in collada and "is .dae: MuJoCo reads STL, OBJ and MSH meshes only" in collada
    assert "gone.stl" in by_rule["G001"][0] and "ASCII STL" in by_rule["G011"][0]
    assert "binary.stl" not in " ".join(f["message"] for f in findings)


def test_same_named_meshes_in_two_folders_stay_two_meshes(tmp_path):
    from ar3cli.sim.mujoco_copy import mujoco_copy
    from ar3cli.urdf.model import load_model

    for folder, size in (("a", 1.0), ("b", 2.0)):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "part.stl").write_bytes(_cube_stl(size))
    path = tmp_path / "r.urdf"
    path.write_text('<robot name="r"><link name="base"><collision><geometry><mesh filename="a/part.stl"/></geometry>'
                    '</collision><collision><geometry><mesh filename="b/part.stl"/></geometry></collision></link></robot>')
    (tmp_path / "out").mkdir()
    built = mujoco_copy(load_model(path), tmp_path / "out")
    assert len(set(built.mesh_elements)) == 2 and b'strippath="false"' in built.document


def test_missing_extra_is_one_line(monkeypatch):
    import builtins

    from ar3cli.errors import UserError
    from ar3cli.sim.mujoco_session import import_mujoco

    real = builtins.__import__

    def refuse(name, *args, **kwargs):
        if name == "mujoco":
            raise ImportError("No module named 'mujoco'")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", refuse)
    with pytest.raises(UserError) as caught:
        import_mujoco()
    assert "pip install 'ar3cli[mujoco]'" in caught.value.message and "\n" not in caught.value.message


def _cube_stl(size: float, binary: bool = True) -> bytes:
    """An STL cube of edge ``size`` (12 triangles), binary (what MuJoCo reads) or ASCII (what it refuses)."""
    import struct

    s = size
    corners = [(x, y, z) for x in (0, s) for y in (0, s) for z in (0, s)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    if binary:
        body = b"".join(struct.pack("<12fH", 0, 0, 0, *corners[a], *corners[b], *corners[c], 0) for a, b, c in faces)
        return b"\0" * 80 + struct.pack("<I", len(faces)) + body
    lines = ["solid cube"]
    for a, b, c in faces:
        lines += ["facet normal 0 0 0", "outer loop", *(f"vertex {x} {y} {z}" for x, y, z in
                                                       (corners[a], corners[b], corners[c])), "endloop", "endfacet"]
    return ("\n".join([*lines, "endsolid cube"]) + "\n").encode()


def test_engine_mujoco_implies_sim(tmp_path):
    from ar3cli.lint.rules import REGISTRY

    path = tmp_path / "stacked.urdf"
    path.write_text(REGISTRY["M003"].bad)
    result = run("lint-urdf", "--engine", "mujoco", "--select", "M003", str(path), "--format", "json")
    assert [finding["rule"] for finding in json.loads(result.stdout)["findings"]] == ["M003"], result.stderr


def test_engine_all_reports_a_pair_both_engines_find_once_in_one_unit(tmp_path):
    """P002 and M003 on one pair were two findings, in '150.0 mm' and '150 mm': now P002's names MuJoCo's too."""
    from ar3cli.lint.rules import REGISTRY

    path = tmp_path / "stacked.urdf"
    path.write_text(REGISTRY["M003"].bad)
    result = run("lint-urdf", "--engine", "all", "--select", "P002,M003", str(path), "--format", "json")
    (finding,) = json.loads(result.stdout)["findings"]
    assert finding["rule"] == "P002"
    assert finding["message"] == ("links 'base' and 'tip' interpenetrate by 150.0 mm at the home pose; "
                                  "in MuJoCo too (150.0 mm, M003)")


def test_mujoco_compile_error_names_the_link_and_its_line(tmp_path):
    from ar3cli.lint.rules.base import arm

    path = tmp_path / "r.urdf"
    path.write_text(arm(link_extra='<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
                                   'izz="5"/></inertial>'))
    result = run("cross-check", str(path), "-n", "1")
    assert result.returncode == 2
    assert f"{path}:4: MuJoCo cannot compile it: inertia must satisfy A + B >= C" in result.stderr
    assert "(link 'arm')" in result.stderr


def test_mujoco_xml_error_points_at_the_users_line(tmp_path):
    from ar3cli.lint.rules.base import arm

    path = tmp_path / "r.urdf"
    text = arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/>\n    <origin xyz="0.07, 0, 0"/>')
    path.write_text(text)
    line = text.splitlines().index('    <origin xyz="0.07, 0, 0"/>') + 1
    from ar3cli.sim.mujoco_session import MjRobot, MujocoCompileError
    from ar3cli.urdf.model import load_model

    with pytest.raises(MujocoCompileError) as refused:
        MjRobot(load_model(path), fuse=False)
    assert "bad format in attribute 'xyz'" in refused.value.reason and refused.value.element.sourceline == line
    result = run("lint-urdf", "--sim", "--engine", "mujoco", "--select", "M001,F007", "--format", "json", str(path))
    (finding,) = json.loads(result.stdout)["findings"]  # F007 says it at that line: M001 does not again
    assert finding["rule"] == "F007" and finding["line"] == line
