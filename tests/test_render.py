"""ar3cli render: a real PNG of the AR3, contacts drawn red, clear errors."""

from __future__ import annotations

import json

import numpy as np
from PIL import Image

from tests.conftest import ASSETS

AR3 = str(ASSETS / "ar3" / "ar3.urdf")
FOLDED = "joint_2=1.2,joint_3=2.4"  # link_2 and link_4 touch in this pose


def _red_pixels(path) -> int:
    rgb = np.asarray(Image.open(path).convert("RGB")).astype(int)
    return int(np.sum((rgb[:, :, 0] > 150) & (rgb[:, :, 1] < 60) & (rgb[:, :, 2] < 60)))


def test_home_pose_png(cli, tmp_path):
    out = tmp_path / "home.png"
    result = cli("render", AR3, "-o", str(out), "--width", "160", "--height", "120")
    assert result.code == 0, result.stderr
    image = Image.open(out)
    assert image.size == (160, 120)
    pixels = np.asarray(image.convert("RGB")).astype(int)
    background = pixels[0, 0]
    assert np.mean(np.any(pixels != background, axis=2)) > 0.03  # the robot is in the picture
    assert _red_pixels(out) == 0


def test_contacts_drawn_red_and_reported(cli, tmp_path):
    out = tmp_path / "folded.png"
    result = cli("render", AR3, "-o", str(out), "--config", FOLDED, "--collision", "--width", "160",
                 "--height", "120", "--format", "json")
    assert result.code == 0, result.stderr
    data = json.loads(result.stdout)
    assert {(c["link_a"], c["link_b"]) for c in data["contacts"]} == {("link_2", "link_4")}
    assert data["configuration"]["joint_2"] == 1.2 and data["configuration"]["joint_1"] == 0.0
    assert _red_pixels(out) > 100


def test_bad_config_is_one_line_error(cli, tmp_path):
    result = cli("render", AR3, "-o", str(tmp_path / "x.png"), "--config", "joint_9=1")
    assert result.code == 2
    assert result.stderr.strip().count("\n") == 0 and "joint_9" in result.stderr
    result = cli("render", AR3, "-o", str(tmp_path / "x.png"), "--config", "joint_1")
    assert result.code == 2 and "NAME=VALUE" in result.stderr
    result = cli("render", AR3, "-o", str(tmp_path / "x.png"), "--config", "joint_2=nan", "--format", "json")
    assert result.code == 2 and "finite" in result.stderr and not (tmp_path / "x.png").exists()
    result = cli("render", AR3, "-o", str(tmp_path / "missing" / "x.png"))
    assert result.code == 2 and "does not exist" in result.stderr and not (tmp_path / "missing").exists()


def _robot_with_visuals(base_visual: str, tip_visual: str) -> str:
    inertial = '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
    box = '<geometry><box size="0.2 0.2 0.2"/></geometry>'
    return (f'<robot name="r"><link name="base">{inertial}<visual>{base_visual}</visual><collision>{box}</collision></link>'
            f'<link name="tip">{inertial}<visual>{tip_visual}</visual></link>'
            '<joint name="j" type="revolute"><parent link="base"/><child link="tip"/><origin xyz="0 0 0.5"/>'
            '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')


def test_an_unloadable_visual_is_replaced_with_a_warning_and_the_picture_made(cli, write_urdf, tmp_path):
    """A .glb visual on the base (pybullet refuses it) and a missing visual mesh on the tip: the base is drawn
    by its collision box, the tip is left out, one warning line each on stderr, exit 0."""
    (tmp_path / "base.glb").write_bytes(b"glTF")
    path = write_urdf(_robot_with_visuals('<geometry><mesh filename="base.glb"/></geometry>',
                                          '<geometry><mesh filename="missing.stl"/></geometry>'))
    out = tmp_path / "r.png"
    result = cli("render", str(path), "-o", str(out), "--width", "64", "--height", "48", "--format", "json")
    assert result.code == 0, result.stderr
    assert out.exists()
    not_drawn = json.loads(result.stdout)["visuals_not_drawn"]  # the JSON says what the picture leaves out
    assert len(not_drawn) == 2 and not_drawn[0].startswith("link 'base'") and "left out" in not_drawn[1]
    warnings = [line for line in result.stderr.splitlines() if "render: warning" in line]
    assert len(warnings) == 2
    assert "link 'base'" in warnings[0] and "'.glb'" in warnings[0] and "collision shape instead" in warnings[0]
    assert "link 'tip'" in warnings[1] and "missing.stl" in warnings[1] and "left out" in warnings[1]


def test_nothing_drawable_is_an_error_suggesting_collision(cli, write_urdf, tmp_path):
    path = write_urdf(_robot_with_visuals('<geometry><mesh filename="gone.stl"/></geometry>',
                                          '<geometry><mesh filename="gone.stl"/></geometry>').replace(
        '<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>', ""))
    result = cli("render", str(path), "-o", str(tmp_path / "r.png"), "--width", "64", "--height", "48")
    assert result.code == 2 and result.stderr.count("ar3cli: error:") == 1
    assert "no visual geometry can be drawn" in result.stderr
    suggests = cli("render", str(write_urdf(_robot_with_visuals('<geometry><mesh filename="gone.stl"/></geometry>',
                                                                '<geometry><mesh filename="gone.stl"/></geometry>'))),
                   "-o", str(tmp_path / "r.png"), "--width", "64", "--height", "48")
    assert suggests.code == 0  # the base's collision box is drawn instead


def test_many_undrawable_visuals_are_counted_not_listed():
    """Talos with package:/// has 45 unreadable visuals: stderr gets the first and a count."""
    from ar3cli.pictures.draw import WARNING_LINES, _warning_lines

    warnings = [f"render: warning: link 'l{i}': a visual cannot be drawn" for i in range(45)]
    lines = _warning_lines(warnings)
    assert len(lines) == WARNING_LINES and lines[0] == warnings[0] and "and 44 more visual(s)" in lines[-1]
    assert _warning_lines(warnings[:2]) == warnings[:2]
