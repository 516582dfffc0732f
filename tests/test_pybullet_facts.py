"""The PyBullet behaviours that docs/pybullet-facts.md states, checked against the installed pybullet.

If a pybullet release changes one of them, this file fails and the docs must change with it.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from ar3cli.infra.isolation import CrashError, run_isolated
from ar3cli.infra.process_pool import can_fork
from ar3cli.sim.session import Session
from ar3cli.urdf.model import load_model

CYLINDER = """<robot name="c"><link name="a"><inertial><mass value="1"/>
<inertia ixx="0.0158333333333" ixy="0" ixz="0" iyy="0.0158333333333" iyz="0" izz="0.005"/></inertial>
<collision><geometry><cylinder radius="0.1" length="0.4"/></geometry></collision></link></robot>"""

TWO_LINKS = """<robot name="t"><link name="a"><inertial><mass value="1"/>
<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
<joint name="j" type="{type}"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>{limit}</joint>
<link name="b">{inertial}<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link></robot>"""
INERTIAL = '<inertial><mass value="0.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'


def test_link_without_inertial_gets_one_kilogram(session, write_urdf):
    model = load_model(write_urdf(TWO_LINKS.format(type="revolute", inertial="",
                                                   limit='<limit lower="-1" upper="1" effort="1" velocity="1"/>')))
    body = session.load(model)
    mass, _, inertia = session.p.getDynamicsInfo(body.id, 0, physicsClientId=session.client)[:3]
    assert (mass, inertia) == (1.0, (1.0, 1.0, 1.0))


def test_default_flags_recompute_inertia_from_collision_aabb(session, write_urdf):
    model = load_model(write_urdf(CYLINDER))
    p = session.p
    default = session.load(model, fixed_base=False, flags=0)
    from_file = session.load(model, fixed_base=False, flags=p.URDF_USE_INERTIA_FROM_FILE)
    default_inertia = p.getDynamicsInfo(default.id, -1, physicsClientId=session.client)[2]
    file_inertia = p.getDynamicsInfo(from_file.id, -1, physicsClientId=session.client)[2]
    assert file_inertia == pytest.approx((0.0158333333333, 0.0158333333333, 0.005), rel=1e-9)
    # a solid box the size of the AABB padded by the collision margin, not the cylinder
    assert default_inertia == pytest.approx((0.017273, 0.017273, 0.007073), abs=2e-6)


@pytest.mark.parametrize(
    ("limit", "expected"),
    [
        ("", (0.0, -1.0, 0.0, 0.0)),
        ('<limit effort="3" velocity="2"/>', (0.0, -1.0, 3.0, 2.0)),
        ('<limit lower="-100" upper="100" effort="3" velocity="2"/>', (-100.0, 100.0, 3.0, 2.0)),
    ],
)
def test_continuous_joints_report_revolute_type(session, write_urdf, limit, expected):
    body = session.load(load_model(write_urdf(TWO_LINKS.format(type="continuous", inertial=INERTIAL, limit=limit))))
    info = session.p.getJointInfo(body.id, 0, physicsClientId=session.client)
    assert info[2] == session.p.JOINT_REVOLUTE
    assert tuple(info[8:12]) == expected
    assert not hasattr(session.p, "JOINT_CONTINUOUS")
    assert body.joints[0].urdf_type == "continuous"  # ar3cli knows better


def test_position_targets_are_clamped_to_fake_limits(write_urdf):
    """The popular "add lower=-100 upper=100" advice: targets beyond the fake limit stop at it."""
    fake = TWO_LINKS.format(type="continuous", inertial=INERTIAL,
                            limit='<limit lower="-1" upper="1" effort="50" velocity="10"/>')
    with Session() as session:
        body = session.load(load_model(write_urdf(fake)))
        p = session.p
        p.setJointMotorControl2(body.id, 0, p.POSITION_CONTROL, targetPosition=3.0, force=50,
                                physicsClientId=session.client)
        session.step(480)
        assert body.positions()[0] == pytest.approx(1.0, abs=0.01)


def test_revolute_without_lower_upper_is_unlimited(session, write_urdf):
    body = session.load(load_model(write_urdf(TWO_LINKS.format(
        type="revolute", inertial=INERTIAL, limit='<limit effort="3" velocity="2"/>'))))
    assert tuple(session.p.getJointInfo(body.id, 0, physicsClientId=session.client)[8:10]) == (0.0, -1.0)
    assert body.joints[0].lower is None and body.joints[0].sample_range() == (-math.pi, math.pi)


def test_random_seed_is_not_a_physics_parameter(session):
    with pytest.raises(TypeError):
        session.p.setPhysicsEngineParameter(randomSeed=1, physicsClientId=session.client)


def test_file_caching_serves_stale_content_under_the_same_name(tmp_path):
    """Why ar3cli's Session turns caching off and loads fresh copies: pybullet caches by file name."""
    from ar3cli.sim.capture import capture_fds
    from ar3cli.sim.session import import_pybullet

    p = import_pybullet()
    path = tmp_path / "r.urdf"
    with capture_fds():
        client = p.connect(p.DIRECT)
        try:
            path.write_text(TWO_LINKS.format(type="fixed", inertial=INERTIAL, limit=""))
            first = p.loadURDF(str(path), physicsClientId=client)
            path.write_text(TWO_LINKS.format(type="fixed", inertial=INERTIAL.replace('"0.5"', '"7"'), limit=""))
            second = p.loadURDF(str(path), physicsClientId=client)
            masses = [p.getDynamicsInfo(b, 0, physicsClientId=client)[0] for b in (first, second)]
        finally:
            p.disconnect(physicsClientId=client)
    assert masses == [0.5, 0.5]  # the rewrite is ignored


# ---- link order (docs: "Link order matters ...") ------------------------------------------------
LINK_ORDER = Path(__file__).parent / "data" / "link_order"


def _raw_load_nan_links(path: Path, maintain_order: bool) -> list[str]:
    """Load ``path`` as it is (no ar3cli copy) and list the links whose frame is NaN."""
    import pybullet as p

    client = p.connect(p.DIRECT)
    try:
        flags = p.URDF_USE_INERTIA_FROM_FILE | (p.URDF_MAINTAIN_LINK_ORDER if maintain_order else 0)
        body = p.loadURDF(str(path), useFixedBase=True, flags=flags, physicsClientId=client)
        return [p.getJointInfo(body, i, physicsClientId=client)[12].decode()
                for i in range(p.getNumJoints(body, physicsClientId=client))
                if any(math.isnan(v) for v in p.getLinkState(body, i, computeForwardKinematics=True,
                                                             physicsClientId=client)[4])]
    finally:
        p.disconnect(physicsClientId=client)


@pytest.mark.skipif(not can_fork(), reason="a pybullet crash can only be observed from a forked child")
@pytest.mark.parametrize("name", ["root_last.urdf", "root_middle.urdf"])
def test_maintain_link_order_crashes_when_the_root_is_not_first(name):
    path = LINK_ORDER / name
    with pytest.raises(CrashError):
        run_isolated(lambda: _raw_load_nan_links(path, maintain_order=True), name)
    assert run_isolated(lambda: _raw_load_nan_links(path, maintain_order=False), name) == []


@pytest.mark.skipif(not can_fork(), reason="loads in a forked child, in case pybullet crashes")
def test_maintain_link_order_gives_nan_to_a_link_declared_before_its_parent():
    path = LINK_ORDER / "child_before_parent.urdf"
    nan = run_isolated(lambda: _raw_load_nan_links(path, maintain_order=True), path.name)
    assert set(nan) == {"b1", "l2", "l3", "l4"}
    assert run_isolated(lambda: _raw_load_nan_links(path, maintain_order=False), path.name) == []


@pytest.mark.skipif(not can_fork(), reason="a pybullet crash can only be observed from a forked child")
def test_a_link_with_two_parents_crashes_pybullet_whatever_the_flags():
    path = LINK_ORDER / "two_parents.urdf"
    with pytest.raises(CrashError):
        run_isolated(lambda: _raw_load_nan_links(path, maintain_order=False), path.name)
