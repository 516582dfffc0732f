"""README's "first five minutes", as a new user runs it: lint the broken AR3, fix it, lint again."""

from __future__ import annotations

import shutil

from tests.conftest import ASSETS


def test_fix_inertia_walkthrough(cli, tmp_path):
    arm = tmp_path / "my_ar3.urdf"
    shutil.copy(ASSETS / "examples" / "ar3_no_inertia.urdf", arm)
    before = cli("lint-urdf", str(arm))
    assert before.code == 1 and before.stdout.count("I001") == 3
    original = arm.read_bytes()
    refused = cli("fix-inertia", str(arm))  # no mass source: refuse, change nothing
    assert refused.code == 1 and arm.read_bytes() == original
    diff = cli("fix-inertia", str(arm), "--density", "1200", "--diff")
    assert diff.code == 0 and diff.stdout.count("+    <inertial>") == 3 and arm.read_bytes() == original
    assert cli("fix-inertia", str(arm), "--density", "1200").code == 0
    after = cli("lint-urdf", "--sim", str(arm))
    assert after.code == 0, after.stdout
    assert cli("fix-inertia", str(arm), "--density", "1200", "--check").code == 0  # idempotent


def test_fix_continuous_walkthrough_restores_the_real_arm(cli, tmp_path):
    arm = tmp_path / "arm2.urdf"
    shutil.copy(ASSETS / "examples" / "ar3_fake_continuous.urdf", arm)
    assert cli("lint-urdf", str(arm), "--no-group").stdout.count("J006") == 6
    assert "6x: " in cli("lint-urdf", str(arm)).stdout  # the six alike warnings fold into one row by default
    fixed = cli("fix-continuous", str(arm), "--limits-from", str(ASSETS / "ar3" / "joint_limits.yaml"))
    assert fixed.code == 0, fixed.stderr
    expected = (ASSETS / "ar3" / "ar3.urdf").read_text().splitlines()
    got = [line for line in arm.read_text().splitlines() if "EXAMPLE WITH A DELIBERATE MISTAKE" not in line]
    assert got == expected
    assert cli("lint-urdf", str(arm)).code == 0
