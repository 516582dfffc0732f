"""URDF 1.1/1.2 in the model (issue 24 item 2): ``<origin quat_xyzw>``, ``<capsule>``, the new ``<limit>``
attributes and the declared ``<robot version>``.

The fixtures in tests/data/urdf12: ``arm_rpy.urdf`` and its twin ``arm_quat.urdf`` (every rotation as
``quat_xyzw``, generated from the rpy values), which must give the same frames everywhere; and
``capsule.urdf`` (version 1.2: a capsule rod turned by a quaternion, a joint with acceleration,
deceleration and jerk limits).
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from ar3cli.maths import mass_properties as mp
from ar3cli.maths import tensor_math as tm
from ar3cli.urdf.model import load_model

DATA = Path(__file__).parent / "data" / "urdf12"
ARM_RPY, ARM_QUAT, CAPSULE = DATA / "arm_rpy.urdf", DATA / "arm_quat.urdf", DATA / "capsule.urdf"
RADIUS, LENGTH = 0.04, 0.3
"""The capsule rod of capsule.urdf."""


def quaternion_of_rpy(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of ``Rz(yaw) Ry(pitch) Rx(roll)`` (urdfdom_headers' setFromRPY)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def _angles(count: int, seed: int = 3) -> np.ndarray:
    """Random rpy, a third of them at gimbal lock (pitch +-pi/2) and a third within 1e-16..1e-3 of it."""
    rng = np.random.default_rng(seed)
    angles = rng.uniform(-math.pi, math.pi, (count, 3))
    for index in range(count):
        side = rng.choice([-1.0, 1.0])
        if index % 3 == 1:
            angles[index, 1] = side * math.pi / 2
        elif index % 3 == 2:
            angles[index, 1] = side * (math.pi / 2 - 10.0 ** rng.uniform(-16, -3))
    return angles


# ---- the maths --------------------------------------------------------------------------------------------

def test_quaternion_matrix_is_the_rpy_matrix():
    for rpy in _angles(300):
        np.testing.assert_allclose(tm.quaternion_to_matrix(quaternion_of_rpy(*rpy)), tm.rpy_to_matrix(rpy),
                                   rtol=0, atol=1e-15)


def test_matrix_to_rpy_rebuilds_the_matrix_even_at_gimbal_lock():
    for rpy in _angles(600):
        matrix = tm.rpy_to_matrix(rpy)
        np.testing.assert_allclose(tm.rpy_to_matrix(tm.matrix_to_rpy(matrix)), matrix, rtol=0, atol=1e-15)


def test_quaternion_is_normalised_and_an_empty_one_refused():
    assert tm.unit_quaternion((0, 0, 2, 2)) == pytest.approx((0, 0, math.sqrt(0.5), math.sqrt(0.5)), abs=2e-16)
    for bad in ((0, 0, 0, 0), (0, 0, float("nan"), 1), (0, 0, float("inf"), 1), (0, 0, 1)):
        assert tm.unit_quaternion(bad) is None
    assert tm.quaternion_to_matrix((0, 0, 0, 0)) == tm.rpy_to_matrix((0, 0, 0))


def test_capsule_mass_properties_closed_form():
    r, length, density = 0.05, 0.3, 7.0
    cylinder_mass, cap_mass = density * math.pi * r**2 * length, density * 2 / 3 * math.pi * r**3
    props = mp.capsule(r, length, density=density)
    assert props.mass == pytest.approx(cylinder_mass + 2 * cap_mass, rel=1e-15)
    axis = cylinder_mass * r**2 / 2 + 2 * (2 / 5 * cap_mass * r**2)
    # a cap about a diameter of its flat face: 2/5 m r^2; its COM 3r/8 from the face; moved to the centre
    cap_side = 2 / 5 * cap_mass * r**2 - cap_mass * (3 * r / 8) ** 2 + cap_mass * (length / 2 + 3 * r / 8) ** 2
    side = cylinder_mass * (3 * r**2 + length**2) / 12 + 2 * cap_side
    np.testing.assert_allclose(props.inertia, np.diag((side, side, axis)), rtol=1e-14, atol=0)
    assert np.all(props.com == 0)
    by_mass = mp.capsule(r, length, mass=props.mass)
    np.testing.assert_allclose(by_mass.inertia, props.inertia, rtol=1e-14)
    sphere = mp.capsule(r, 0.0, density=1.0)  # no cylinder: a sphere
    np.testing.assert_allclose(sphere.inertia, mp.sphere(r, density=1.0).inertia, rtol=1e-14)
    assert mp.capsule_volume(r, length) == pytest.approx(mp.cylinder_volume(r, length) + mp.sphere_volume(r))


# ---- the model --------------------------------------------------------------------------------------------

def _joint_origin(write_urdf, origin: str, version: str = ' version="1.1"'):
    text = (f'<?xml version="1.0"?>\n<robot name="r"{version}><link name="a"/><link name="b"/>'
            f'<joint name="j" type="fixed"><parent link="a"/><child link="b"/>{origin}</joint></robot>')
    return load_model(write_urdf(text)).joint("j").origin


def test_origin_reads_quat_xyzw(write_urdf):
    turned = _joint_origin(write_urdf, '<origin xyz="1 2 3" quat_xyzw="0 0 2 2"/>')  # not normalised
    assert turned.xyz == (1, 2, 3)
    assert turned.quat_xyzw == pytest.approx((0, 0, math.sqrt(0.5), math.sqrt(0.5)), abs=2e-16)
    assert turned.rpy == pytest.approx((0, 0, math.pi / 2), abs=1e-15)
    np.testing.assert_allclose(turned.rotation, tm.rpy_to_matrix((0, 0, math.pi / 2)), rtol=0, atol=1e-15)
    undeclared = _joint_origin(write_urdf, '<origin quat_xyzw="0 0 1 1"/>', version="")
    assert undeclared.rpy == pytest.approx((0, 0, math.pi / 2))  # read in a 1.0 file too (G-rules say so)


@pytest.mark.parametrize("origin,rpy", [
    ('<origin rpy="0.1 0 0" quat_xyzw="0 0 1 1"/>', (0.1, 0, 0)),  # both: rpy wins, as in urdfdom's 1.0
    ('<origin quat_xyzw="0 0 0 0"/>', (0, 0, 0)),  # no direction: identity
    ('<origin quat_xyzw="0 0 1"/>', (0, 0, 0)),  # three numbers: malformed (F007), identity
    ('<origin quat_xyzw="0 0 nan 1"/>', (0, 0, 0)),
])
def test_origin_with_an_unusable_or_competing_quaternion(write_urdf, origin, rpy):
    read = _joint_origin(write_urdf, origin)
    assert read.quat_xyzw is None and read.rpy == rpy
    assert np.all(np.isfinite(read.rotation))


def test_malformed_quaternion_is_reported(cli, write_urdf):
    text = ARM_QUAT.read_text().replace('quat_xyzw="0.0 0.0 0.19866933079506122 0.9800665778412416"',
                                        'quat_xyzw="0 0 0.2"', 1)
    assert text != ARM_QUAT.read_text()
    result = cli("lint-urdf", str(write_urdf(text)), "--select", "F007", "--format", "json")
    (finding,) = json.loads(result.stdout)["findings"]
    assert "quat_xyzw" in finding["message"] and "expected 4" in finding["message"]


@pytest.mark.parametrize("declared,version", [
    ("", (1, 0)), (' version="1.0"', (1, 0)), (' version="1.1"', (1, 1)), (' version="1.2"', (1, 2)),
    (' version="1"', None), (' version="1.0.0"', None), (' version="1.x"', None),
])
def test_declared_version(write_urdf, declared, version):
    model = load_model(write_urdf(f'<robot name="r"{declared}><link name="a"/></robot>'))
    assert model.urdf_version == version
    assert model.declares("capsule") == (version is not None and version >= (1, 1))
    assert model.declares("jerk") == (version == (1, 2))


def test_limit_keeps_the_urdf_1_2_attributes():
    limit = load_model(CAPSULE).joint("turn").limit
    assert (limit.lower, limit.upper, limit.effort, limit.velocity) == (-2, 2, 10, 2)
    assert (limit.acceleration, limit.deceleration, limit.jerk) == (5, 8, 100)
    assert load_model(ARM_RPY).joint("shoulder").limit.jerk is None


def test_every_origin_of_the_twins_is_the_same_rotation():
    rpy_model, quat_model = load_model(ARM_RPY), load_model(ARM_QUAT)
    for a, b in zip(rpy_model.joints, quat_model.joints):
        assert b.origin.quat_xyzw is not None
        np.testing.assert_allclose(b.origin.rotation, a.origin.rotation, rtol=0, atol=1e-15)
        np.testing.assert_allclose(tm.rpy_to_matrix(b.origin.rpy), a.origin.rotation, rtol=0, atol=1e-15)
    for a, b in zip(rpy_model.links, quat_model.links):
        shapes_a = [*a.visuals, *a.collisions, *([a.inertial] if a.inertial else [])]
        shapes_b = [*b.visuals, *b.collisions, *([b.inertial] if b.inertial else [])]
        assert len(shapes_a) == len(shapes_b)
        for shape_a, shape_b in zip(shapes_a, shapes_b):
            np.testing.assert_allclose(tm.rpy_to_matrix(shape_b.origin.rpy), shape_a.origin.rotation, atol=1e-15)


def test_fk_of_the_twins_is_equal():
    from ar3cli.kinematics.fk import urdf_link_frames

    rpy_model, quat_model = load_model(ARM_RPY), load_model(ARM_QUAT)
    rng = np.random.default_rng(5)
    positions = {joint.name: rng.uniform(-2, 2, 20) for joint in rpy_model.movable_joints()}
    frames_rpy, frames_quat = urdf_link_frames(rpy_model, positions, 20), urdf_link_frames(quat_model, positions, 20)
    assert set(frames_rpy) == set(frames_quat) == {"base", "upper", "fore", "hand", "tool"}
    for link, frames in frames_rpy.items():
        np.testing.assert_allclose(frames_quat[link], frames, rtol=0, atol=1e-12)
    assert not np.allclose(frames_rpy["tool"][:, :3, :3], np.eye(3))  # the frames do turn


def test_capsule_bounds_along_the_turned_axis():
    from ar3cli.urdf.bounds import shape_bounds

    (collision,) = load_model(CAPSULE).link("rod").collisions
    assert collision.geometry.kind == "capsule"
    low, high = shape_bounds(collision)
    half = LENGTH / 2 + RADIUS  # along z in the shape frame, turned on to x by the quaternion
    np.testing.assert_allclose(low, (0.1 - half, -RADIUS, -RADIUS), atol=1e-15)
    np.testing.assert_allclose(high, (0.1 + half, RADIUS, RADIUS), atol=1e-15)


# ---- what pybullet is given -------------------------------------------------------------------------------

def test_loadable_copy_gives_pybullet_rpy():
    from lxml import etree

    from ar3cli.sim.loadable_copy import loadable_document

    model = load_model(ARM_QUAT)
    copy = etree.fromstring(loadable_document(model))
    origins = list(copy.iter("origin"))
    assert origins and not any(o.get("quat_xyzw") for o in origins)
    for element, joint in zip(copy.iter("joint"), model.joints):
        rpy = tuple(map(float, element.find("origin").get("rpy").split()))
        assert rpy == joint.origin.rpy  # full precision


def _pybullet_link_orientation(path: Path, link_index: int) -> tuple[float, ...]:
    import pybullet

    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(path), physicsClientId=client)
        return pybullet.getLinkState(body, link_index, physicsClientId=client)[5]
    finally:
        pybullet.disconnect(client)


def test_pybullet_ignores_quat_xyzw_and_reads_the_copy(tmp_path):
    """Measured: pybullet 3.2.7 leaves a quat_xyzw origin unrotated; the copy's rpy turns it."""
    from ar3cli.sim.loadable_copy import write_loadable_copy

    model = load_model(CAPSULE)
    text = CAPSULE.read_text().replace('<origin xyz="0 0 0.2"/>', '<origin xyz="0 0 0.2" quat_xyzw="0 0 1 1"/>')
    raw = tmp_path / "raw.urdf"
    raw.write_text(text)
    assert _pybullet_link_orientation(raw, 0) == pytest.approx((0, 0, 0, 1))
    copy = write_loadable_copy(load_model(raw), tmp_path / "copy.urdf")
    assert _pybullet_link_orientation(copy, 0) == pytest.approx((0, 0, math.sqrt(0.5), math.sqrt(0.5)), abs=1e-7)
    assert model.link("rod").collisions[0].geometry.params == {"radius": RADIUS, "length": LENGTH}


def _pybullet_capsule(path: Path) -> tuple[int, tuple[float, ...], np.ndarray]:
    """(shape type, dimensions, AABB size) of link 0's collision shape as pybullet loads ``path``."""
    import pybullet

    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(path), physicsClientId=client)
        ((kind, dimensions),) = [(shape[2], shape[3]) for shape in pybullet.getCollisionShapeData(body, 0, client)]
        low, high = pybullet.getAABB(body, 0, physicsClientId=client)
    finally:
        pybullet.disconnect(client)
    return kind, dimensions, np.subtract(high, low)


def test_pybullet_reads_a_capsule_as_urdfdom_does(tmp_path):
    """Measured: radius and cylinder length along z; the file as written stays along z (the quaternion is
    ignored), the loadable copy turns it on to x as the Model does."""
    import pybullet

    from ar3cli.sim.loadable_copy import write_loadable_copy

    kind, dimensions, raw_size = _pybullet_capsule(CAPSULE)
    assert kind == pybullet.GEOM_CAPSULE and dimensions[:2] == pytest.approx((LENGTH, RADIUS))
    np.testing.assert_allclose(raw_size, (2 * RADIUS, 2 * RADIUS, LENGTH + 2 * RADIUS), atol=1e-6)
    _, _, copy_size = _pybullet_capsule(write_loadable_copy(load_model(CAPSULE), tmp_path / "copy.urdf"))
    # bullet pads the box of a turned child shape by its collision margin (measured: 0.001 m a side)
    np.testing.assert_allclose(copy_size, (LENGTH + 2 * RADIUS, 2 * RADIUS, 2 * RADIUS), atol=2.5e-3)


# ---- the commands -----------------------------------------------------------------------------------------

@pytest.mark.parametrize("path", [ARM_RPY, ARM_QUAT])
def test_fk_verify_passes(cli, path):
    result = cli("fk-verify", str(path), "--samples", "50", "--seed", "1", "--format", "json")
    assert result.code == 0, result.stderr
    assert json.loads(result.stdout)["passed"] is True


def _numbers_equal(a, b, path="") -> None:
    if isinstance(a, dict):
        assert set(a) == set(b), path
        for key in a:
            if key != "path":
                _numbers_equal(a[key], b[key], f"{path}.{key}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for index, (x, y) in enumerate(zip(a, b)):
            _numbers_equal(x, y, f"{path}[{index}]")
    elif isinstance(a, float):
        assert b == pytest.approx(a, rel=1e-12, abs=1e-15), path
    else:
        assert a == b, path


def test_info_json_of_the_twins_is_equal(cli):
    results = [cli("info", str(path), "--format", "json") for path in (ARM_RPY, ARM_QUAT)]
    assert all(result.code == 0 for result in results), [result.stderr for result in results]
    _numbers_equal(*(json.loads(result.stdout) for result in results))


def test_render_of_the_twins_is_the_same_picture(cli, tmp_path):
    from PIL import Image

    pictures = []
    for path in (ARM_RPY, ARM_QUAT):
        out = tmp_path / f"{path.stem}.png"
        result = cli("render", str(path), "-o", str(out), "--width", "160", "--height", "120",
                     "--config", "shoulder=0.5,elbow=0.7,wrist=1")
        assert result.code == 0, result.stderr
        pictures.append(np.asarray(Image.open(out).convert("RGB"), dtype=int))
    differing = np.any(pictures[0] != pictures[1], axis=-1).sum()
    assert differing <= 10, f"{differing} pixels differ"  # measured: 0
    assert np.any(pictures[0] != pictures[0][0, 0])  # something is drawn


@pytest.mark.parametrize("path", [ARM_RPY, ARM_QUAT, CAPSULE])
def test_lint_sim_has_no_warning(cli, path):
    result = cli("lint-urdf", str(path), "--sim", "--format", "json")
    assert result.code == 0, result.stderr
    findings = json.loads(result.stdout)["findings"]
    quaternions = [f for f in findings if f["rule"] == "T009"]  # a PyBullet user's loadURDF ignores them
    assert bool(quaternions) == ("quat_xyzw=" in path.read_text())
    findings = [f for f in findings if f["rule"] != "T009"]
    assert [f for f in findings if f["severity"] != "info"] == [], findings
    assert {f["rule"] for f in findings} <= {"P003"}  # pybullet's default load recomputes inertia (info)


def test_fix_inertia_computes_the_capsule(cli, tmp_path):
    path = tmp_path / "capsule.urdf"
    shutil.copy(CAPSULE, path)
    text = path.read_text()
    original = 'ixx="0.0007758490566037736" ixy="0" ixz="0" iyy="0.010879622641509434" iyz="0" izz="0.010879622641509434"'
    assert original in text
    path.write_text(text.replace(original, 'ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"'))
    result = cli("fix-inertia", str(path), "--format", "json")
    assert result.code == 0, result.stderr
    inertial = load_model(path).link("rod").inertial
    cylinder_mass = math.pi * RADIUS**2 * LENGTH
    cap_mass = 2 / 3 * math.pi * RADIUS**3
    scale = 1.0 / (cylinder_mass + 2 * cap_mass)  # the file's 1 kg
    cylinder_mass, cap_mass = cylinder_mass * scale, cap_mass * scale
    axis = cylinder_mass * RADIUS**2 / 2 + 4 / 5 * cap_mass * RADIUS**2
    side = (cylinder_mass * (3 * RADIUS**2 + LENGTH**2) / 12
            + 2 * cap_mass * (2 / 5 * RADIUS**2 + LENGTH**2 / 4 + 3 * LENGTH * RADIUS / 8))
    assert inertial.mass == 1.0
    np.testing.assert_allclose(inertial.origin.xyz, (0.1, 0, 0), atol=1e-12)
    np.testing.assert_allclose(inertial.matrix(), np.diag((axis, side, side)), rtol=1e-6, atol=1e-12)
    assert (axis, side) == pytest.approx((0.0007758490566037736, 0.010879622641509434), rel=1e-14)  # the fixture's


def test_fix_inertia_turns_a_quaternion_inertial_origin_to_the_identity(cli, tmp_path):
    """The tensor is written in the link frame: a quat_xyzw on the inertial origin must become 0 0 0 1 (left
    alone, the Model and urdfdom would turn the new tensor by it; an added rpy would make urdfdom 1.1 refuse
    an origin with both)."""
    path = tmp_path / "capsule.urdf"
    turned = '<origin xyz="0.1 0 0" quat_xyzw="0 0 0.3826834323650898 0.9238795325112867"/>'
    text = CAPSULE.read_text().replace('<origin xyz="0.1 0 0" rpy="0 0 0"/>', turned)
    path.write_text(text.replace('ixx="0.0007758490566037736"', 'ixx="0.5"'))  # breaks the triangle inequality
    result = cli("fix-inertia", str(path), "--format", "json")
    assert result.code == 0, result.stderr
    fixed = path.read_text()
    assert '<origin xyz="0.1 0 0" quat_xyzw="0 0 0 1"/>' in fixed and fixed.count("rpy=") == text.count("rpy=")
    inertial = load_model(path).link("rod").inertial
    np.testing.assert_allclose(inertial.origin.rotation, np.eye(3), atol=0)
    np.testing.assert_allclose(inertial.matrix(), np.diag((0.0007758490566037736, 0.010879622641509434,
                                                           0.010879622641509434)), rtol=1e-6)


# ---- G010 -------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("declared,reported", [
    ("", True), (' version="1.0"', True), (' version="1.1"', False), (' version="1.2"', False), (' version="1"', True),
])
def test_g010_capsule_follows_the_declared_version(cli, write_urdf, declared, reported):
    text = CAPSULE.read_text().replace('<robot name="capsule12" version="1.2">', f'<robot name="capsule12"{declared}>')
    result = cli("lint-urdf", str(write_urdf(text)), "--select", "G010", "--format", "json")
    findings = json.loads(result.stdout)["findings"]
    assert len(findings) == (2 if reported else 0)  # the rod's visual and collision
    for finding in findings:
        assert "URDF 1.1" in finding["message"] and "urdfdom refuses the whole file" in finding["message"]
        assert 'version="1.1"' in finding["hint"]


def test_new_limit_attributes_are_not_findings(cli):
    result = cli("lint-urdf", str(CAPSULE), "--format", "json")
    findings = json.loads(result.stdout)["findings"]
    assert not any(word in f["message"] for f in findings for word in ("acceleration", "deceleration", "jerk"))
