"""Joint rules (J): degrees taken for radians, arms and casters, J012/J013, virtual base joints and
PyBullet's "no limit" idiom, on the small robots that set their limits.

Each case is a small robot written to tmp_path; tests/test_lint_pybullet_data.py keeps the real-robot
counts honest.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from ar3cli.findings import Severity
from ar3cli.lint.rules.base import LINK_INERTIAL, arm, robot
from tests.lint_helpers import tensor
from tests.test_lint_rules import codes_for, write_fixture

# ---- J005: degrees, not multi-turn radians ---------------------------------------------------------

@pytest.mark.parametrize("lower,upper", [(-3 * math.pi, 3 * math.pi), (-3.05433, 6.80678), (-10, 10), (-6.3, 6.3),
                                         (-1e16, 1e16), (-2.53073, 9.25025), (-12.5, 12.5)],
                         ids=["pm3pi-anymal", "tiago-hand", "pm10-solo", "pm6.3", "unlimited", "tiago-mrl", "pm12.5"])
def test_radian_ranges_of_multi_turn_joints_are_not_degrees(tmp_path, lower, upper):
    text = arm(joint_extra=f'<limit lower="{lower}" upper="{upper}" effort="10" velocity="1"/>')
    assert codes_for(write_fixture(tmp_path, text), "J005") == []


@pytest.mark.parametrize("lower,upper", [(-90, 90), (0, 180), (-170, 170), (-360, 360), (-135, 45), (-720, 720)])
def test_typed_degrees_are_reported(tmp_path, lower, upper):
    text = arm(joint_extra=f'<limit lower="{lower}" upper="{upper}" effort="10" velocity="1"/>')
    (finding,) = codes_for(write_fixture(tmp_path, text), "J005")
    assert "look like degrees" in finding.message and f"{math.radians(upper):.4f}" in finding.hint


# ---- J011: arms, not casters, gears, pendulums or virtual bases --------------------------------------

def _chain(kinds: list[str], names: list[str], shapes: list[str], root_shape: str = "box") -> str:
    geometry = {"box": '<box size="0.1 0.1 0.3"/>', "cylinder": '<cylinder radius="0.05" length="0.02"/>',
                "sphere": '<sphere radius="0.05"/>', "none": ""}

    def link(name: str, shape: str) -> str:
        body = f"<collision><geometry>{geometry[shape]}</geometry></collision>" if shape != "none" else ""
        return f'<link name="{name}">{LINK_INERTIAL}{body}</link>'

    parts = [link("base", root_shape)]
    parent = "base"
    for i, (kind, name, shape) in enumerate(zip(kinds, names, shapes)):
        limit = '<limit lower="-1" upper="1" effort="10" velocity="1"/>' if kind in ("revolute", "prismatic") else ""
        parts.append(link(name, shape))
        parts.append(f'<joint name="j{i}" type="{kind}"><parent link="{parent}"/><child link="{name}"/>'
                     f'<axis xyz="0 0 1"/>{limit}</joint>')
        parent = name
    return robot("\n".join(parts))


def test_cad_exported_arm_is_flagged(tmp_path):
    text = _chain(["continuous"] * 4, ["link_1", "link_2", "link_3", "link_4"], ["box"] * 4)
    found = codes_for(write_fixture(tmp_path, text), "J011")
    assert [f.message.split("'")[1] for f in found] == ["j0", "j1", "j2"]  # the last one carries nothing


@pytest.mark.parametrize("kinds,names,shapes,root", [
    (["continuous", "continuous"], ["caster_swivel_link", "caster_wheel_link"], ["box", "cylinder"], "box"),
    (["continuous", "continuous"], ["swivel_1_link", "swivel_2_link"], ["box", "cylinder"], "box"),  # by geometry
    (["continuous", "continuous", "continuous"], ["link1", "link2", "link3"], ["sphere"] * 3, "none"),  # pendulum
    (["continuous", "continuous"], ["diff_ring", "diff_spider"], ["cylinder", "cylinder"], "box"),  # differential
    (["prismatic", "continuous", "revolute"], ["x_slider", "torso", "leg"], ["none", "box", "box"], "none"),  # planar base
], ids=["caster-by-name", "caster-by-geometry", "pendulum", "differential", "virtual-planar-base"])
def test_joints_that_spin_by_design_are_not_flagged(tmp_path, kinds, names, shapes, root):
    assert codes_for(write_fixture(tmp_path, _chain(kinds, names, shapes, root)), "J011") == []


# ---- J012, J013 ---------------------------------------------------------------------------------------

def _mimic(follower: str, leader: str, target: str = "left_finger") -> str:
    def limit(kind):
        return '<limit lower="-1" upper="1" effort="10" velocity="1"/>' if kind in ("revolute", "prismatic") else ""

    return robot(f"""
        <link name="base">{LINK_INERTIAL}</link><link name="l">{LINK_INERTIAL}</link><link name="r">{LINK_INERTIAL}</link>
        <joint name="left_finger" type="{leader}"><parent link="base"/><child link="l"/><axis xyz="0 1 0"/>{limit(leader)}</joint>
        <joint name="right_finger" type="{follower}"><parent link="base"/><child link="r"/><axis xyz="0 1 0"/>{limit(follower)}
          <mimic joint="{target}"/></joint>""")


@pytest.mark.parametrize("follower,leader", [("fixed", "revolute"), ("revolute", "fixed"), ("fixed", "fixed"),
                                             ("prismatic", "floating")])
def test_mimic_needs_single_dof_joints(tmp_path, follower, leader):
    assert codes_for(write_fixture(tmp_path, _mimic(follower, leader)), "J012")


def test_mimic_of_a_missing_joint_is_s007_only(tmp_path):
    path = write_fixture(tmp_path, _mimic("revolute", "revolute", target="nope"))
    assert codes_for(path, "S007") and codes_for(path, "J012") == []
    assert codes_for(write_fixture(tmp_path, _mimic("prismatic", "revolute")), "J012") == []


def test_planar_and_floating_joints_are_a_portability_note(tmp_path):
    for kind in ("planar", "floating"):
        (finding,) = codes_for(write_fixture(tmp_path, arm(joint_type=kind, joint_extra="")), "J013")
        assert finding.severity == Severity.INFO and "PyBullet" in finding.message
    spherical = write_fixture(tmp_path, arm(joint_type="spherical", joint_extra=""))
    assert codes_for(spherical, "J013") == [] and codes_for(spherical, "S010")


# ---- J005 and J003/J014 on virtual base joints and PyBullet's "no limit" idiom (issue 30) ----------
JOINT_DATA = Path(__file__).parent / "data" / "joints"


def _hand(massive_dummies: bool = False, prismatic_range: str = "-20 20") -> str:
    """The floating hand fixture, with heavier dummy links or other prismatic limits."""
    text = (JOINT_DATA / "floating_hand.urdf").read_text()
    if massive_dummies:
        for name in ("dummy_x", "dummy_y", "dummy_z", "dummy_ry"):
            text = text.replace(f'<link name="{name}"/>', f'<link name="{name}">{tensor(0.01, 0.01, 0.01, 0.5)}</link>')
    lower, upper = prismatic_range.split()
    for axis in "xyz":
        start = text.index(f'<joint name="virtual_{axis}"')
        end = text.index("</joint>", start)
        text = text[:start] + text[start:end].replace('lower="-20" upper="20"', f'lower="{lower}" upper="{upper}"') \
            + text[end:]
    return text


@pytest.mark.parametrize("massive_dummies,prismatic_range", [(False, "-20 20"), (True, "-20 20"), (False, "-1 1")],
                         ids=["both-kinds-of-evidence", "shared-range-only", "massless-chain-only"])
def test_virtual_base_joints_are_not_degrees(tmp_path, massive_dummies, prismatic_range):
    text = _hand(massive_dummies, prismatic_range)
    (finding,) = codes_for(write_fixture(tmp_path, text), "J005")
    assert "'finger_joint'" in finding.message  # the real degree typo of the same hand is still reported


def test_heavy_dummies_with_other_ranges_are_judged_as_usual(tmp_path):
    """Neither shared limits nor a massless chain: nothing says 'virtual', so ±20 still looks like degrees."""
    reported = codes_for(write_fixture(tmp_path, _hand(True, "-1 1")), "J005")
    assert sorted(f.message.split("'")[1] for f in reported) == ["finger_joint", "virtual_rx", "virtual_ry", "virtual_rz"]


def test_first_joint_from_an_empty_root_is_still_judged(tmp_path):
    """An empty root link alone (no moving joint between dummies) is no floating chain."""
    text = arm(joint_extra='<limit lower="-170" upper="170" effort="10" velocity="1"/>')
    assert len(codes_for(write_fixture(tmp_path, text), "J005")) == 1


def test_pybullet_no_limit_idiom_is_explained_not_inverted(tmp_path):
    path = write_fixture(tmp_path, (JOINT_DATA / "pybullet_unlimited.urdf").read_text())
    (inverted,) = codes_for(path, "J003")
    assert "'shoulder'" in inverted.message
    idioms = codes_for(path, "J014")
    assert [f.message.split("'")[1] for f in idioms] == ["x_to_world", "z_to_x"]
    assert all(f.severity == Severity.INFO and "no limit" in f.message for f in idioms)


@pytest.mark.parametrize("lower,upper,code", [(1, -1, "J014"), (0, -1, "J014"), (1.5, -1.5, "J003"), (2, -1, "J003")])
def test_only_the_exact_idiom_pairs_are_pybullets(tmp_path, lower, upper, code):
    text = arm(joint_type="prismatic", joint_extra=f'<limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/>')
    path = write_fixture(tmp_path, text)
    assert len(codes_for(path, code)) == 1 and codes_for(path, {"J003": "J014", "J014": "J003"}[code]) == []
