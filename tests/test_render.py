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
