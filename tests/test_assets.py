"""Tests for the generated robot assets in ``assets/`` (AR3 arm, cube, broken examples).

They check that the committed files are exactly what ``assets/make_ar3.py`` writes, that
the AR3 loads cleanly in pybullet with the real robot's joint limits and kinematics, that
its inertials are physical, and that each example file differs from ``ar3.urdf`` only by
its intended mistake. Comparisons against the real AR3 description run only when the
``shared/`` folder beside the repository clone is present.
"""

from __future__ import annotations

import importlib.util
import io
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import numpy as np
import pybullet as p
import pytest
from lxml import etree

from ar3cli.maths import mass_properties as mp
from ar3cli.sim.capture import capture_fds
from tests.conftest import ASSETS, REPO, SHARED

AR3 = ASSETS / "ar3" / "ar3.urdf"
AR3_XACRO = ASSETS / "ar3" / "ar3.urdf.xacro"
CUBE = ASSETS / "objects" / "cube.urdf"
EXAMPLES = ASSETS / "examples"
REAL = SHARED / "models" / "ar3_description"

ARM_JOINTS = [f"joint_{i}" for i in range(1, 7)]
FINGER_JOINTS = ["gripper_finger_left", "gripper_finger_right"]
# ar3_moveit_config/config/joint_limits.yaml (ongdexter/ar3_core), min/max_position.
EXPECTED_LIMITS = {
    "joint_1": (-2.96706, 2.96706),
    "joint_2": (-0.6911504, 1.57079632679),
    "joint_3": (0.0, 2.5080381),
    "joint_4": (-2.8710666, 2.8710666),
    "joint_5": (-1.81776042, 1.81776042),
    "joint_6": (-2.5848326, 2.5848326),
}
FINGER_TRAVEL = 0.04  # 0 = open (80 mm jaw), 0.04 = closed
# The real ar3.urdf has a different joint_3 zero (origin yaw -1.4953816339 instead of the
# xacro's -1.04720367321) and joint_5 axis -x instead of +x; see make_ar3.py.
JOINT_3_OFFSET_URDF = 1.4953816339 - 1.04720367321


def _load_module(path: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location("make_ar3", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up in sys.modules
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def generator() -> ModuleType:
    """The generator script, imported (not run as a subprocess)."""
    return _load_module(ASSETS / "make_ar3.py")


@pytest.fixture
def pb() -> Iterator[int]:
    """A fresh DIRECT pybullet client per test (file caching off), disconnected afterwards.

    A fresh client per test costs about a millisecond and means no body, gravity or
    motor setting leaks from one test into the next.
    """
    cid = p.connect(p.DIRECT)
    p.setPhysicsEngineParameter(enableFileCaching=0, physicsClientId=cid)
    yield cid
    p.disconnect(cid)


def load(cid: int, path: Path, flags: int = 0) -> tuple[int, str]:
    """Load a URDF with a fixed base and inertia from the file; return (body, C output text)."""
    with capture_fds() as captured:
        body = p.loadURDF(str(path), useFixedBase=True, physicsClientId=cid,
                          flags=p.URDF_USE_INERTIA_FROM_FILE | flags)
    return body, captured.text


def joint_table(cid: int, body: int) -> dict[str, tuple]:
    """name -> getJointInfo tuple."""
    infos = (p.getJointInfo(body, j, physicsClientId=cid) for j in range(p.getNumJoints(body, physicsClientId=cid)))
    return {info[1].decode(): info for info in infos}


def link_index(cid: int, body: int, name: str) -> int:
    return next(info[0] for info in joint_table(cid, body).values() if info[12].decode() == name)


def canonical(root: etree._Element) -> list[tuple]:
    """Elements as (tag, sorted attributes, text), comments and layout ignored."""
    return [(e.tag, tuple(sorted(e.attrib.items())), (e.text or "").strip())
            for e in root.iter() if isinstance(e.tag, str)]


def parse(path: Path) -> etree._Element:
    return etree.parse(str(path)).getroot()


# ---------------------------------------------------------------------------------------


def test_generator_output_equals_committed_files(generator: ModuleType, tmp_path: Path) -> None:
    assert generator.main([str(tmp_path)]) == 0
    written = sorted(f.relative_to(tmp_path).as_posix() for f in tmp_path.rglob("*") if f.is_file())
    assert written == sorted(generator.outputs())
    for rel in written:
        assert (tmp_path / rel).read_bytes() == (ASSETS / rel).read_bytes(), f"{rel} is stale: run assets/make_ar3.py"


def test_ar3_loads_without_warnings(pb: int) -> None:
    body, printed = load(pb, AR3)
    assert printed.strip() == ""
    joints = joint_table(pb, body)
    movable = [n for n, info in joints.items() if info[2] != p.JOINT_FIXED]
    assert movable == ARM_JOINTS + FINGER_JOINTS
    assert all(joints[n][2] == p.JOINT_REVOLUTE for n in ARM_JOINTS)
    assert all(joints[n][2] == p.JOINT_PRISMATIC for n in FINGER_JOINTS)
    links = [info[12].decode() for info in joints.values()]
    assert links == [f"link_{i}" for i in range(1, 7)] + ["gripper_base", "finger_left", "finger_right", "tcp"]


def test_ar3_limits(pb: int) -> None:
    body, _ = load(pb, AR3)
    joints = joint_table(pb, body)
    for name, (lower, upper) in EXPECTED_LIMITS.items():
        _, _, _, _, _, _, _, _, lo, hi, effort, velocity, *_ = joints[name]
        assert (lo, hi) == pytest.approx((lower, upper), abs=1e-12)
        assert lo <= 0.0 <= hi, "home pose must be inside the limits"
        assert effort > 0 and 0.5 <= velocity <= 3.0
    efforts = [joints[n][10] for n in ARM_JOINTS]
    assert min(efforts[:3]) > max(efforts[3:]), "shoulder/elbow stronger than the wrist"
    for name in FINGER_JOINTS:
        lo, hi, effort, velocity = joints[name][8:12]
        assert (lo, hi) == (0.0, FINGER_TRAVEL)
        assert 20.0 <= effort <= 40.0 and 0.05 <= velocity <= 0.1


def test_ar3_limits_match_real_joint_limits_yaml() -> None:
    yaml_path = REAL / "extra" / "ar3_moveit_config" / "config" / "joint_limits.yaml"
    if not yaml_path.is_file():
        pytest.skip("the real AR3 description (shared/models/ar3_description beside the clone) is not present")
    import yaml

    real = yaml.safe_load(yaml_path.read_text())["joint_limits"]
    joints = {j.get("name"): j for j in parse(AR3).iter("joint")}
    for name in ARM_JOINTS:
        assert real[name]["has_position_limits"] is True
        limit = joints[name].find("limit")
        assert float(limit.get("lower")) == pytest.approx(real[name]["min_position"], abs=1e-12)
        assert float(limit.get("upper")) == pytest.approx(real[name]["max_position"], abs=1e-12)
        assert float(limit.get("velocity")) >= real[name]["max_velocity"]
        assert EXPECTED_LIMITS[name] == pytest.approx((real[name]["min_position"], real[name]["max_position"]))


def _configurations() -> list[np.ndarray]:
    """A few deterministic arm configurations inside the limits, home first."""
    rng = np.random.default_rng(3)
    lows = np.array([v[0] for v in EXPECTED_LIMITS.values()])
    highs = np.array([v[1] for v in EXPECTED_LIMITS.values()])
    return [np.zeros(6), (lows + highs) / 2] + [rng.uniform(lows, highs) for _ in range(4)]


def _yourdfpy(source: Path | io.StringIO):  # noqa: ANN202 - yourdfpy.URDF
    yourdfpy = pytest.importorskip("yourdfpy")
    return yourdfpy.URDF.load(source, build_scene_graph=True, load_meshes=False, load_collision_meshes=False)


def _link_positions(robot, q: dict[str, float]) -> np.ndarray:
    robot.update_cfg(q)
    return np.array([robot.get_transform(f"link_{i}")[:3, 3] for i in range(1, 7)])


def test_kinematics_match_real_ar3_xacro() -> None:
    """Link frames equal the real ar3.urdf.xacro's (the file the kinematics come from)."""
    real_xacro = REAL / "urdf" / "ar3.urdf.xacro"
    if not real_xacro.is_file():
        pytest.skip("the real AR3 description (shared/models/ar3_description beside the clone) is not present")
    xacro = pytest.importorskip("xacro")
    real = _yourdfpy(io.StringIO(xacro.process_file(str(real_xacro)).toxml()))
    ours = _yourdfpy(AR3)
    for q in _configurations():
        cfg = dict(zip(ARM_JOINTS, q))
        np.testing.assert_allclose(_link_positions(ours, cfg), _link_positions(real, cfg), rtol=0, atol=1e-6)


def test_kinematics_match_real_ar3_urdf() -> None:
    """Link frames equal the real ar3.urdf's after mapping its joint_3 zero and joint_5 sign.

    ar3.urdf rounds pi to 3.1416 and has a -1.67e-5 rad yaw on joint_1, which moves its
    link frames by up to ~1.1e-5 m; hence 2e-5 m here and 1e-6 m against the xacro.
    """
    real_urdf = REAL / "urdf" / "ar3.urdf"
    if not real_urdf.is_file():
        pytest.skip("the real AR3 description (shared/models/ar3_description beside the clone) is not present")
    real = _yourdfpy(real_urdf)
    ours = _yourdfpy(AR3)
    for q in _configurations():
        q_real = q.copy()
        q_real[2] -= JOINT_3_OFFSET_URDF
        q_real[4] = -q_real[4]
        np.testing.assert_allclose(_link_positions(ours, dict(zip(ARM_JOINTS, q))),
                                   _link_positions(real, dict(zip(ARM_JOINTS, q_real))), rtol=0, atol=2e-5)


def test_home_frames_and_gripper_layout(pb: int, generator: ModuleType) -> None:
    """Arm stands up at home; pads 80 mm apart open, touching closed; tcp centred between them."""
    body, _ = load(pb, AR3)

    def frame(name: str) -> np.ndarray:
        return np.array(p.getLinkState(body, link_index(pb, body, name), computeForwardKinematics=True,
                                       physicsClientId=pb)[4])

    for name, world in generator.HOME.items():  # pybullet agrees with the generator's own FK
        if name != "base_link":
            np.testing.assert_allclose(frame(name), world[:3, 3], atol=1e-6)
    left, right, tcp = frame("finger_left"), frame("finger_right"), frame("tcp")
    assert np.linalg.norm(left - right) == pytest.approx(2 * FINGER_TRAVEL, abs=1e-6)
    np.testing.assert_allclose(tcp[:2], ((left + right) / 2)[:2], atol=1e-6)
    assert tcp[2] - frame("link_6")[2] == pytest.approx(0.0745, abs=1e-6)
    for name in FINGER_JOINTS:
        p.resetJointState(body, link_index(pb, body, name.replace("gripper_", "")), FINGER_TRAVEL, physicsClientId=pb)
    assert np.linalg.norm(frame("finger_left") - frame("finger_right")) == pytest.approx(0.0, abs=1e-6)
    for name in ("finger_left", "finger_right"):
        assert p.getDynamicsInfo(body, link_index(pb, body, name), physicsClientId=pb)[1] == pytest.approx(1.0)


def test_mass_and_inertials_are_physical(pb: int) -> None:
    root = parse(AR3)
    total = 0.0
    for link in root.iter("link"):
        inertial = link.find("inertial")
        assert inertial is not None, f"{link.get('name')} has no <inertial>"
        mass = float(inertial.find("mass").get("value"))
        i = {k: float(v) for k, v in inertial.find("inertia").attrib.items()}
        tensor = np.array([[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]], [i["ixz"], i["iyz"], i["izz"]]])
        assert mass > 0
        assert mp.is_positive_definite(tensor), link.get("name")
        assert mp.satisfies_triangle_inequality(tensor, tol=1e-15), link.get("name")
        total += mass
    assert 2.5 < total < 3.5  # real AR3 arm 2.83 kg + gripper
    body, _ = load(pb, AR3)
    joints = joint_table(pb, body)
    masses = {info[12].decode(): p.getDynamicsInfo(body, info[0], physicsClientId=pb)[0] for info in joints.values()}
    assert masses["link_1"] == pytest.approx(0.88065) and masses["link_6"] == pytest.approx(0.013863)
    assert masses["tcp"] <= 1e-5, "tcp must not get pybullet's default 1 kg"


def test_no_self_collision_at_home(pb: int) -> None:
    body, _ = load(pb, AR3, p.URDF_USE_SELF_COLLISION)
    p.performCollisionDetection(physicsClientId=pb)
    assert p.getContactPoints(body, body, physicsClientId=pb) == ()


def test_stands_still_under_gravity(pb: int) -> None:
    body, _ = load(pb, AR3)
    p.setGravity(0, 0, -9.81, physicsClientId=pb)
    joints = [info for info in joint_table(pb, body).values() if info[2] != p.JOINT_FIXED]
    for info in joints:
        p.setJointMotorControl2(body, info[0], p.POSITION_CONTROL, targetPosition=0.0, force=info[10], physicsClientId=pb)
    for _ in range(480):
        p.stepSimulation(physicsClientId=pb)
    q = np.array([p.getJointState(body, info[0], physicsClientId=pb)[0] for info in joints])
    np.testing.assert_allclose(q, 0.0, atol=1e-3)


def test_cube(pb: int) -> None:
    body, printed = load(pb, CUBE)
    assert printed.strip() == ""
    lo, hi = (np.array(v) for v in p.getAABB(body, -1, physicsClientId=pb))
    # The AABB is padded by the collision margin; the file's size is the truth.
    size = [float(v) for v in parse(CUBE).find(".//collision/geometry/box").get("size").split()]
    assert len(set(size)) == 1 and 0.04 <= size[0] <= 0.05
    assert np.all(np.abs((hi - lo) - size[0]) < 0.01)
    inertial = parse(CUBE).find(".//inertial")
    mass = float(inertial.find("mass").get("value"))
    assert 0.05 <= mass <= 0.1
    expected = mass * size[0] ** 2 / 6
    for key in ("ixx", "iyy", "izz"):
        assert float(inertial.find("inertia").get(key)) == pytest.approx(expected, rel=1e-7)
    assert float(parse(CUBE).find(".//contact/lateral_friction").get("value")) >= 0.8


def test_xacro_default_equals_urdf_and_arg_works() -> None:
    xacro = pytest.importorskip("xacro")
    default = etree.fromstring(xacro.process_file(str(AR3_XACRO)).toxml().encode())
    assert canonical(default) == canonical(parse(AR3))
    bare = etree.fromstring(xacro.process_file(str(AR3_XACRO), mappings={"with_gripper": "false"}).toxml().encode())
    assert [link.get("name") for link in bare.iter("link")] == ["base_link"] + [f"link_{i}" for i in range(1, 7)] + ["tcp"]
    assert [j.get("name") for j in bare.iter("joint") if j.get("type") != "fixed"] == ARM_JOINTS


# --- examples ---------------------------------------------------------------------------


def _without_inertials(root: etree._Element, links: set[str]) -> etree._Element:
    for link in root.iter("link"):
        if link.get("name") in links:
            link.remove(link.find("inertial"))
    return root


def _fake_continuous(root: etree._Element) -> etree._Element:
    for joint in root.iter("joint"):
        if joint.get("name") in ARM_JOINTS:
            joint.set("type", "continuous")
            joint.find("limit").set("lower", "-100")
            joint.find("limit").set("upper", "100")
    return root


def _zero_effort(root: etree._Element) -> etree._Element:
    for limit in root.iter("limit"):
        limit.set("effort", "0")
        limit.set("velocity", "0")
    return root


@pytest.mark.parametrize(
    ("name", "mutate"),
    [
        ("ar3_no_inertia.urdf", lambda r: _without_inertials(r, {"link_4", "link_5", "link_6"})),
        ("ar3_fake_continuous.urdf", _fake_continuous),
        ("ar3_zero_effort.urdf", _zero_effort),
    ],
)
def test_examples_differ_only_where_intended(name: str, mutate) -> None:
    example = (EXAMPLES / name).read_text()
    assert canonical(parse(EXAMPLES / name)) == canonical(mutate(parse(AR3)))
    assert "<!-- EXAMPLE WITH A DELIBERATE MISTAKE:" in example
    assert name in (EXAMPLES / "README.md").read_text()


def test_examples_show_their_mistake_in_pybullet(pb: int) -> None:
    body, printed = load(pb, EXAMPLES / "ar3_no_inertia.urdf")
    assert "No inertial data for link" in printed
    assert p.getDynamicsInfo(body, link_index(pb, body, "link_5"), physicsClientId=pb)[0] == 1.0
    body, _ = load(pb, EXAMPLES / "ar3_fake_continuous.urdf")
    info = joint_table(pb, body)["joint_1"]
    assert info[2] == p.JOINT_REVOLUTE and (info[8], info[9]) == (-100.0, 100.0)
    body, _ = load(pb, EXAMPLES / "ar3_zero_effort.urdf")
    assert all(info[10] == 0.0 and info[11] == 0.0 for info in joint_table(pb, body).values() if info[2] != p.JOINT_FIXED)


def _project_files() -> Iterator[Path]:
    """Every file of the project's own, walking past git's store and any virtual environment
    (the README's .venv and .venv-test, or one of another name, known by its pyvenv.cfg)."""
    for folder, subfolders, files in os.walk(REPO):
        subfolders[:] = [name for name in subfolders
                         if name != ".git" and not (Path(folder) / name / "pyvenv.cfg").is_file()]
        yield from (Path(folder) / name for name in files)


def test_real_description_is_not_copied_into_the_repo() -> None:
    """Only numbers from the real AR3 may be used, never its files (checked anywhere in the repo)."""
    real_files = {path.read_bytes() for path in REAL.rglob("*") if path.is_file()} if REAL.is_dir() else set()
    tracked = [path for path in _project_files() if path.is_file()]
    for path in tracked:
        assert not path.name.lower().endswith(".stl"), path
        if real_files and path.stat().st_size < 2_000_000:
            assert path.read_bytes() not in real_files, f"{path} is a copy of a file from the real AR3 description"
