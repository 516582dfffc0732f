"""Lint v3 (issue 24), each injected defect class: schema, geometric consistency, plausibility and target-engine rules.

Each defect class of the issue, injected by hand into a small robot (tests/data/lint_v3/), is found
at the line of the element that holds it; a file full of extensions stays quiet; ``--target`` adds
the engines' traps and refuses unknown engines.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ar3cli.lint.engine import LintOptions, lint_file
from ar3cli.lint.rules import REGISTRY

DATA = Path(__file__).parent / "data" / "lint_v3"
NEW = ("S016", "S017", "S018", "S019", "S020", "G014", "G015", "G016", "I013", "I014", "I015")


def _findings(path: Path, select=NEW, targets=("pybullet", "ros")):
    options = LintOptions(select=list(select), targets=targets)
    return lint_file(path, options.rules(), options).findings


def _line_of(path: Path, needle: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if needle in line)


@pytest.mark.parametrize(("code", "needle", "words"), [
    ("S016", "<orign", "did you mean <origin>"),
    ("S016", "<axes", "did you mean <axis>"),
    ("S017", 'xzy="0 1 0"', "did you mean xyz"),
    ("S017", 'ryp="0 0 1"', "did you mean rpy"),
    ("S017", 'iyx="0.5"', "parsers read ixy and ignore iyx"),
    ("S018", "<damping>5", "damping"),
    ("S019", '<visual><origin ryp', "no <geometry>"),
    ("G014", '<origin xyz="0 0 3.0"/>', "joint 'j2'"),
    ("G015", '<collision><origin xyz="0.3 0 0.1"/>', "covers 0%"),
])
def test_each_injected_class_is_found_at_its_element(code, needle, words):
    path = DATA / "injected.urdf"
    line = _line_of(path, needle)
    hits = [f for f in _findings(path) if f.rule == code and f.line == line]
    assert hits and words in hits[0].message, [(f.rule, f.line, f.message) for f in _findings(path)]


def test_misspelt_names_get_a_rename_hint():
    hints = {f.hint for f in _findings(DATA / "injected.urdf", select=("S016", "S017"))}
    assert {"Rename <orign> to <origin>.", "Rename xzy= to xyz=.", "Keep the value you mean in ixy= and delete iyx=."}.issubset(hints)


def test_extensions_and_declared_urdf_12_stay_quiet():
    """gazebo, transmission, ros2_control, sensor, mujoco, drake: and xacro namespaces, PyBullet's <contact> and
    <specular>, <material> in <collision>, extension attributes, capsule and quat_xyzw in a 1.2 file."""
    assert _findings(DATA / "clean_extensions.urdf", select=(*NEW, "G010")) == []


def test_undeclared_version_feature_is_a_hint(tmp_path):
    text = (DATA / "clean_extensions.urdf").read_text().replace(' version="1.2"', "")
    path = tmp_path / "r.urdf"
    path.write_text(text)
    messages = [f.message for f in _findings(path, select=("S020",))]
    assert len(messages) == 3 and "quat_xyzw" in messages[0] and "acceleration" in messages[1] and "jerk" in messages[2]


def test_target_rules_run_only_for_their_engines():
    default = {r.code for r in LintOptions().rules() if r.code.startswith("T")}
    assert default == {"T001", "T009"}
    isaac = {r.code for r in LintOptions(targets=("isaac",)).rules() if r.code.startswith("T")}
    assert isaac == {"T005", "T006", "T007"}
    assert "T003" in {r.code for r in LintOptions(select=["ALL", "T003"]).rules()}  # naming the code runs it
    assert all(REGISTRY[code].targets for code in REGISTRY if code.startswith("T"))


def test_cli_target_option(cli, tmp_path):
    path = tmp_path / "r.urdf"
    path.write_text(REGISTRY["T004"].bad)
    args = ("lint-urdf", "--no-cache", "--format", "json", "--exit-zero", "--select", "T", str(path))
    quiet = cli(*args)
    assert quiet.code == 0 and not [f for f in json.loads(quiet.stdout)["findings"] if f["rule"] == "T004"]
    loud = cli(*args, "--target", "mujoco,isaac")
    assert [f["rule"] for f in json.loads(loud.stdout)["findings"]].count("T004") == 1
    bad = cli(*args, "--target", "unity")
    assert bad.code == 2 and "unknown engine 'unity'" in bad.stderr
