"""fk-verify: PyBullet vs an independent URDF FK, DH tables and their diagnoses, on real models."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from ar3cli.kinematics import compare as fk_compare
from ar3cli.kinematics import dh
from ar3cli.kinematics import fk as kinematics
from ar3cli.urdf.model import load_model
from tests.conftest import ASSETS

AR3 = ASSETS / "ar3" / "ar3.urdf"
AR3_DH = ASSETS / "ar3" / "ar3_dh.yaml"
PYBULLET_FLOOR_M = 5e-7
"""pybullet reports link frames in single precision; measured worst ~1.2e-7 m, ~6.8e-7 rad."""

# The Franka Panda's published (Craig / modified) DH parameters, typed in mm and degrees.
PANDA_CRAIG = """
convention: modified
base: panda_link0
tip: panda_link8
units: {length: mm, angle: deg}
tool: {xyz: [0, 0, 107], rpy: [0, 0, 0]}
joints:
  - {joint: panda_joint1, a: 0, alpha: 0, d: 333}
  - {joint: panda_joint2, a: 0, alpha: -90, d: 0}
  - {joint: panda_joint3, a: 0, alpha: 90, d: 316}
  - {joint: panda_joint4, a: 82.5, alpha: 90, d: 0}
  - {joint: panda_joint5, a: -82.5, alpha: -90, d: 384}
  - {joint: panda_joint6, a: 0, alpha: 90, d: 0}
  - {joint: panda_joint7, a: 88, alpha: 90, d: 0}
"""


def run_json(cli, *args: str):
    result = cli("fk-verify", *args, "--format", "json")
    assert result.stdout.strip(), result.stderr
    return result, json.loads(result.stdout)


# ---- PyBullet vs URDF ------------------------------------------------------------------------------

@pytest.mark.parametrize("relative", ["kuka_iiwa/model.urdf", "franka_panda/panda.urdf"])
def test_pybullet_models_pass(cli, pybullet_data_dir: Path, relative: str) -> None:
    result, data = run_json(cli, str(pybullet_data_dir / relative), "--samples", "150", "--seed", "3")
    assert result.code == 0, result.stderr
    assert data["passed"] is True and data["samples"] == 150 and data["seed"] == 3
    assert 0 < data["max_position_error_m"] < PYBULLET_FLOOR_M
    assert 0 < data["max_orientation_error_rad"] < 1e-6
    assert len(data["links"]) >= 8 and data["dh"] is None


def test_json_shape_and_seed_determinism(cli) -> None:
    _, first = run_json(cli, str(AR3), "--samples", "20", "--seed", "7")
    _, again = run_json(cli, str(AR3), "--samples", "20", "--seed", "7")
    _, other = run_json(cli, str(AR3), "--samples", "20", "--seed", "8")
    assert first == again
    assert first["worst"]["configuration"] != other["worst"]["configuration"]
    for key in ("samples", "seed", "passed", "max_position_error_m", "max_orientation_error_rad", "links", "dh"):
        assert key in first
    assert {"link", "max_position_error_m", "mean_position_error_m", "max_orientation_error_rad"} <= set(first["links"][0])
    assert [link["link"] for link in first["links"]][:3] == ["base_link", "link_1", "link_2"]


def test_independent_fk_matches_yourdfpy_to_machine_precision(pybullet_data_dir: Path) -> None:
    """Our vectorised FK against yourdfpy's, per config: agreement at ~1e-15 shows the floor is pybullet's."""
    import yourdfpy

    path = pybullet_data_dir / "franka_panda" / "panda.urdf"
    model = load_model(path)
    robot = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False,
                               load_collision_meshes=False)
    rng = np.random.default_rng(1)
    names = [f"panda_joint{i}" for i in range(1, 8)] + ["panda_finger_joint1"]
    q = rng.uniform(-2.5, 2.5, size=(20, len(names)))
    q[:, -1] = rng.uniform(0, 0.04, 20)
    frames = kinematics.urdf_link_frames(model, {n: q[:, i] for i, n in enumerate(names)}, 20)
    worst = 0.0
    for n in range(20):
        robot.update_cfg({name: q[n, i] for i, name in enumerate(names)})
        for link in ("panda_link7", "panda_hand", "panda_rightfinger"):
            worst = max(worst, float(np.abs(robot.get_transform(link) - frames[link][n]).max()))
    assert worst < 1e-12


def _com_frames(session, body, samples) -> dict[str, np.ndarray]:
    """The tutorial mistake: the raw base pose and getLinkState(...)[0:2], i.e. centre-of-mass frames."""
    p, client = session.p, session.client
    indices = [joint.index for joint in body.joints]
    poses = []
    for q in fk_compare.body_configurations(body, samples):
        body.set_positions(q)
        base = p.getBasePositionAndOrientation(body.id, physicsClientId=client)
        states = p.getLinkStates(body.id, indices, computeForwardKinematics=True, physicsClientId=client)
        poses.append([base, *((state[0], state[1]) for state in states)])
    return fk_compare.frames_from_poses(body.link_names, poses)


def test_com_instead_of_link_frame_fails_by_the_com_offset(write_urdf) -> None:
    """The tutorial trap: getLinkState[0] is the COM. [4] passes; [0] is off by exactly the inertial offset."""
    from ar3cli.sim.session import Session

    path = write_urdf(_two_link_urdf(inertial_xyz="0.03 0.04 0.12"))
    model = load_model(path)
    with Session() as session:
        body = session.load(model)
        samples = fk_compare.draw_samples(model, body, 30, 0)
        reference = kinematics.urdf_link_frames(model, samples.all_values, samples.count)
        right = fk_compare.compare_links(reference, fk_compare.pybullet_frames(body, samples))
        wrong = fk_compare.compare_links(reference, _com_frames(session, body, samples))
    by_link = {e.link: e for e in right}
    assert by_link["arm"].max_position < PYBULLET_FLOOR_M
    offset = {e.link: e for e in wrong}["arm"]
    assert offset.max_position == pytest.approx(0.13, abs=1e-6)  # |(0.03, 0.04, 0.12)|
    assert offset.mean_position == pytest.approx(0.13, abs=1e-6)


def test_mimic_joint_is_set_explicitly_and_explained(cli, write_urdf) -> None:
    path = write_urdf(_two_link_urdf(mimic=True))
    result, data = run_json(cli, str(path), "--samples", "40")
    assert result.code == 0, result.stderr
    assert any("mimics drive" in note and "does not enforce" in note for note in data["notes"])
    # without the explicit value pybullet leaves the mimic joint at 0: that would be a real error
    from ar3cli.sim.session import Session

    model = load_model(path)
    with Session() as session:
        body = session.load(model)
        body.set_positions({"drive": 0.5})
        finger = body.link_frames()["finger"]
    reference = kinematics.urdf_link_frames(model, {"drive": np.array([0.5])}, 1)["finger"][0]
    assert np.linalg.norm(np.array(finger[0]) - reference[:3, 3]) == pytest.approx(2 * 0.5 - 0.1, abs=1e-6)


def test_non_unit_prismatic_axis_fails_with_an_explanation(cli, write_urdf) -> None:
    path = write_urdf(_two_link_urdf(prismatic_axis="0 0 3"))
    result, data = run_json(cli, str(path), "--samples", "30")
    assert result.code == 1
    assert data["passed"] is False and data["worst"]["link"] == "slider"
    assert any("non-unit axis" in note and "pybullet moves the joint 3 x q" in note for note in data["notes"])


def _mobile_urdf(x_axis: str = "1 0 0") -> str:
    """A virtual planar base (prismatic x, y of +-20 m, a yaw joint) carrying a two-link arm, like Fetch or a
    mobile Panda: pybullet's float32 frames are off by ~1e-6 m out there although nothing is wrong."""
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
                '</inertial>')
    links = "".join(f'<link name="{name}">{inertial}</link>' for name in ("x_link", "y_link", "base", "upper", "fore"))

    def joint(name: str, kind: str, parent: str, child: str, axis: str, limit: float, xyz: str = "0 0 0") -> str:
        return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
                f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>'
                f'<limit lower="{-limit}" upper="{limit}" effort="100" velocity="1"/></joint>')

    return (f'<robot name="mobile"><link name="world"/>{links}'
            + joint("x", "prismatic", "world", "x_link", x_axis, 20) + joint("y", "prismatic", "x_link", "y_link", "0 1 0", 20)
            + joint("theta", "revolute", "y_link", "base", "0 0 1", 3.14)
            + joint("shoulder", "revolute", "base", "upper", "0 1 0", 2, "0.1 0 0.4")
            + joint("elbow", "revolute", "upper", "fore", "0 1 0", 2, "0 0 0.3") + "</robot>")


def test_a_mobile_base_20_m_out_passes_with_a_tolerance_scaled_to_its_reach(cli, write_urdf) -> None:
    path = str(write_urdf(_mobile_urdf()))
    result, data = run_json(cli, path, "--samples", "300")
    assert result.code == 0, result.stderr
    assert data["passed"] is True and data["tolerance_scaled"] is True and data["tolerance_m"] == 1e-6
    assert data["max_position_error_m"] > 1e-6  # float32 at ~20 m: an absolute 1e-6 m would call it FAIL
    fore = next(link for link in data["links"] if link["link"] == "fore")
    assert fore["max_reach_m"] > 20 and fore["position_tolerance_m"] == pytest.approx(4 * 2.0**-23 * fore["max_reach_m"])
    assert data["largest_position_tolerance_m"] == pytest.approx(max(link["position_tolerance_m"] for link in data["links"]))
    text = cli("fk-verify", path, "--samples", "300")
    assert "PASS" in text.stdout and "float32 epsilons x reach" in text.stdout and "m reach)" in text.stdout
    given = cli("fk-verify", path, "--samples", "300", "--tolerance-m", "1e-6")  # a tolerance the user gives is used as is
    assert given.code == 1 and "1e-06 m as given" in given.stdout


def test_a_real_error_on_a_mobile_base_still_fails(cli, write_urdf) -> None:
    """An axis 1e-5 too long: pybullet moves x by |axis| q, 0.2 mm off at 20 m, far above the scaled 1e-5 m."""
    result, data = run_json(cli, str(write_urdf(_mobile_urdf(x_axis="1.00001 0 0"))), "--samples", "300")
    assert result.code == 1 and data["passed"] is False
    assert data["max_position_error_m"] > 1e-4 > data["largest_position_tolerance_m"]


def test_a_robot_without_movable_joints_says_so_instead_of_an_empty_configuration(cli, write_urdf) -> None:
    path = write_urdf('<robot name="r"><link name="a"/><link name="b"/>'
                      '<joint name="f" type="fixed"><parent link="a"/><child link="b"/><origin xyz="0 0 1"/></joint></robot>')
    result = cli("fk-verify", str(path), "--samples", "3")
    assert result.code == 0, result.stderr
    assert "(no movable joint: every sample is the same configuration)" in result.stdout
    assert "(sample 0: )" not in result.stdout


def test_link_reach_includes_the_ancestors() -> None:
    """An arm folded back to the origin from a base 20 m out is rounded like a point 20 m out."""
    frames = {name: np.tile(np.eye(4), (1, 1, 1)) for name in ("base", "arm")}
    frames["base"][0, :3, 3] = (20, 0, 0)
    reaches = fk_compare.link_reaches(frames, {"arm": "base"})
    assert reaches["arm"][0] == pytest.approx(20) and reaches["base"][0] == pytest.approx(20)


# ---- DH tables ----------------------------------------------------------------------------------

def test_ar3_dh_passes(cli) -> None:
    result, data = run_json(cli, str(AR3), "--dh", str(AR3_DH), "--samples", "200")
    assert result.code == 0, result.stderr
    assert data["dh"]["passed"] is True and data["dh"]["diagnoses"] == []
    assert data["dh"]["max_position_error_m"] < 1e-12 and data["dh"]["max_orientation_error_rad"] < 1e-12


def test_shipped_ar3_dh_is_the_derivation() -> None:
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_ar3_dh", ASSETS / "make_ar3_dh.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    derived, shipped = module.table_text(), AR3_DH.read_text(encoding="utf-8")
    # The comments and keys match exactly; the numbers to 1e-12 (the last digit of a derived number
    # depends on numpy's and libm's rounding, which differ between releases).
    assert _comments(derived) == _comments(shipped), "run python assets/make_ar3_dh.py"
    assert _numbers_close(yaml.safe_load(derived), yaml.safe_load(shipped)), "run python assets/make_ar3_dh.py"


def _comments(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.startswith("#")]


def _numbers_close(a, b) -> bool:
    """Same structure and strings; floats equal to 1e-12 (absolute)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_numbers_close(a[key], b[key]) for key in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_numbers_close(x, y) for x, y in zip(a, b))
    if isinstance(a, float) or isinstance(b, float):
        return math.isclose(a, b, rel_tol=0.0, abs_tol=1e-12)
    return a == b


def test_published_panda_craig_table_passes(cli, pybullet_data_dir: Path, tmp_path: Path) -> None:
    table = tmp_path / "panda_dh.yaml"
    table.write_text(PANDA_CRAIG, encoding="utf-8")
    result, data = run_json(cli, str(pybullet_data_dir / "franka_panda" / "panda.urdf"), "--dh", str(table),
                            "--samples", "100")
    assert result.code == 0, result.stderr
    assert data["dh"]["convention"] == "modified" and data["dh"]["max_position_error_m"] < 1e-9


@pytest.fixture(scope="module")
def ar3_setup():
    """The AR3 model, its URDF frames over 150 samples, and the correct table as a dict."""
    model = load_model(AR3)
    rng = np.random.default_rng(5)
    names = [f"joint_{i}" for i in range(1, 7)]
    q = rng.uniform(-2.5, 2.5, size=(150, 6))
    frames = kinematics.urdf_link_frames(model, {n: q[:, i] for i, n in enumerate(names)}, 150)
    return model, frames, q, yaml.safe_load(AR3_DH.read_text(encoding="utf-8"))


def _diagnose(ar3_setup, tmp_path: Path, document: dict) -> list[dh.Diagnosis]:
    model, frames, q, _ = ar3_setup
    path = tmp_path / "broken.yaml"
    path.write_text(yaml.safe_dump(document), encoding="utf-8")
    table = dh.load_dh(path, model)
    assert not dh.evaluate(table, frames, q).within(1e-6, 1e-6)
    return dh.diagnose(table, frames, q, 1e-6, 1e-6)


def test_diagnosis_d_off_by_1cm(ar3_setup, tmp_path: Path) -> None:
    document = copy.deepcopy(ar3_setup[3])
    correct = document["joints"][3]["d"]
    document["joints"][3]["d"] = correct + 0.01
    diagnoses = _diagnose(ar3_setup, tmp_path, document)
    fits = [d for d in diagnoses if d.kind == "wrong-value"]
    assert [(d.fix["row"], d.fix["joint"]) for d in fits] == [(4, "joint_4")]
    assert fits[0].fix["d"] == pytest.approx(correct, abs=1e-9)
    assert any(d.kind == "wrong-row" and d.fix["row"] == 5 for d in diagnoses)  # joint_5's axis is the first off


def test_diagnosis_sign_flipped(ar3_setup, tmp_path: Path) -> None:
    document = copy.deepcopy(ar3_setup[3])
    document["joints"][1]["sign"] = -document["joints"][1]["sign"]
    diagnoses = _diagnose(ar3_setup, tmp_path, document)
    assert [(d.kind, d.fix.get("joint")) for d in diagnoses] == [("sign-flipped", "joint_2")]


def test_diagnosis_degrees_as_radians(ar3_setup, tmp_path: Path) -> None:
    document = copy.deepcopy(ar3_setup[3])
    for row in document["joints"]:
        row["alpha"], row["theta_offset"] = math.degrees(row["alpha"]), math.degrees(row["theta_offset"])
    diagnoses = _diagnose(ar3_setup, tmp_path, document)
    assert [d.kind for d in diagnoses] == ["angles-in-degrees"]
    assert diagnoses[0].fix == {"units": {"angle": "deg"}}


def test_diagnosis_missing_tool_offset(ar3_setup, tmp_path: Path) -> None:
    document = copy.deepcopy(ar3_setup[3])
    document["tip"] = "tcp"  # the tcp is 74.5 mm along link_6's z; the table has no tool for it
    diagnoses = _diagnose(ar3_setup, tmp_path, document)
    assert [d.kind for d in diagnoses] == ["tool-offset"]
    assert diagnoses[0].fix["tool"]["xyz"] == pytest.approx([0.0, 0.0, 0.0745], abs=1e-12)
    assert "looks like a tool offset of" in diagnoses[0].message and "add it as tool:" in diagnoses[0].message
    document["tool"] = diagnoses[0].fix["tool"]  # applying the suggestion makes it pass
    model, frames, q, _ = ar3_setup
    fixed = tmp_path / "fixed.yaml"
    fixed.write_text(yaml.safe_dump(document), encoding="utf-8")
    assert dh.evaluate(dh.load_dh(fixed, model), frames, q).within(1e-9, 1e-9)


def test_wrong_dh_fails_on_the_cli_with_diagnosis(cli, tmp_path: Path) -> None:
    document = yaml.safe_load(AR3_DH.read_text(encoding="utf-8"))
    document["joints"][2]["sign"] = -document["joints"][2]["sign"]
    path = tmp_path / "flipped.yaml"
    path.write_text(yaml.safe_dump(document), encoding="utf-8")
    result, data = run_json(cli, str(AR3), "--dh", str(path), "--samples", "50")
    assert result.code == 1
    assert data["passed"] is False and data["dh"]["passed"] is False
    assert data["dh"]["diagnoses"][0]["kind"] == "sign-flipped" and data["dh"]["diagnoses"][0]["fix"]["row"] == 3
    text = cli("fk-verify", str(AR3), "--dh", str(path), "--samples", "50")
    assert text.code == 1 and "row 3 (joint_3): the sign looks flipped" in text.stdout


@pytest.mark.parametrize("mutate, expected", [
    (lambda d: "convention: [standard\n", "not valid YAML"),
    (lambda d: {**d, "joints": [{**d["joints"][0], "joint": "joint_9"}, *d["joints"][1:]]}, "'joint_9', which is not in"),
    (lambda d: {**d, "tip": "hand"}, "tip link 'hand' is not a link of"),
    (lambda d: {**d, "joints": d["joints"][:5]}, "5 DH row(s), but the chain base_link -> link_6 has 6"),
    (lambda d: {**d, "joints": [{k: v for k, v in d["joints"][0].items() if k != "d"}, *d["joints"][1:]]},
     "joints[0] is missing 'd'"),
    (lambda d: {**d, "units": {"length": "inch"}}, "length unit 'inch' is not supported"),
    (lambda d: {**d, "joints": [d["joints"][1], d["joints"][0], *d["joints"][2:]]}, "rows go in chain order"),
    (lambda d: {**d, "base": "link_6", "tip": "tcp", "joints": []}, "has no movable joint"),
])
def test_bad_dh_files_exit_2_with_one_line(cli, tmp_path: Path, mutate, expected: str) -> None:
    document = mutate(yaml.safe_load(AR3_DH.read_text(encoding="utf-8")))
    path = tmp_path / "bad.yaml"
    path.write_text(document if isinstance(document, str) else yaml.safe_dump(document), encoding="utf-8")
    result = cli("fk-verify", str(AR3), "--dh", str(path), "--samples", "5")
    assert result.code == 2, result.stderr
    assert result.stdout == ""
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ar3cli: error: ") and str(path) in lines[0]
    assert expected in lines[0]


def test_missing_dh_file_and_bad_options_exit_2(cli, tmp_path: Path) -> None:
    result = cli("fk-verify", str(AR3), "--dh", str(tmp_path / "nope.yaml"))
    assert result.code == 2 and "DH file not found" in result.stderr
    result = cli("fk-verify", str(AR3), "--samples", "0")
    assert result.code == 2 and "--samples" in result.stderr and "1<=x" in result.stderr
    assert len(result.stderr.splitlines()) == 1


def test_rotation_angle_resolves_tiny_angles() -> None:
    for angle in (1e-12, 3e-9, 0.5, math.pi - 1e-3):
        rotation = kinematics.axis_rotations(np.array([0.6, 0.0, 0.8]), np.array([angle]))[0, :3, :3]
        assert kinematics.rotation_angles(rotation) == pytest.approx(angle, rel=1e-6)


# ---- fixtures -----------------------------------------------------------------------------------

def _two_link_urdf(inertial_xyz: str = "0 0 0", mimic: bool = False, prismatic_axis: str = "0 0 1") -> str:
    """base -> arm (revolute 'drive') -> slider (prismatic 'slide'); optional mimic finger on 'drive'."""
    inertia = '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
    finger = f"""
  <link name="finger"><inertial><mass value="0.1"/>{inertia}</inertial></link>
  <joint name="finger_joint" type="prismatic"><parent link="arm"/><child link="finger"/>
    <origin xyz="0 0.1 0.2"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="drive" multiplier="2" offset="-0.1"/></joint>""" if mimic else ""
    return f"""<robot name="two">
  <link name="base"><inertial><origin xyz="0 0 0.05"/><mass value="2"/>{inertia}</inertial></link>
  <link name="arm"><inertial><origin xyz="{inertial_xyz}"/><mass value="1"/>{inertia}</inertial></link>
  <link name="slider"><inertial><mass value="0.5"/>{inertia}</inertial></link>
  <joint name="drive" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1" rpy="0.1 0.2 0.3"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="arm"/><child link="slider"/>
    <origin xyz="0.3 0 0"/><axis xyz="{prismatic_axis}"/><limit lower="-0.2" upper="0.2" effort="1" velocity="1"/></joint>
{finger}
</robot>
"""


def test_tree_order_survives_a_loop_and_long_chains(write_urdf) -> None:
    """A joint leading back to a link already reached is skipped (it used to loop forever)."""
    from ar3cli.kinematics.fk import tree_order

    links = "".join(f'<link name="l{i}"/>' for i in range(4))
    joints = "".join(f'<joint name="j{i}" type="fixed"><parent link="l{i}"/><child link="l{i + 1}"/></joint>'
                     for i in range(3))
    loop = '<joint name="back" type="fixed"><parent link="l3"/><child link="l1"/></joint>'
    model = load_model(write_urdf(f'<robot name="r">{links}{joints}{loop}</robot>'))
    assert [joint.name for joint in tree_order(model)] == ["j0", "j1", "j2"]
