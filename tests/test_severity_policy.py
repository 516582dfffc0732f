"""The severity policy of docs/rules.md, held for every rule (issue 35).

error: some engine or tool refuses the file or measurably misbehaves on it, and the rule names which;
every rule says which engines it is about; a rule about some engines only follows ``--target``.
"""

from __future__ import annotations

import re

import pytest

from ar3cli.findings import Severity
from ar3cli.lint.engine import LintOptions, lint_file
from ar3cli.lint.rules import OPT_IN_CODES, REGISTRY, RULES, validate_patterns
from ar3cli.lint.rules.base import ENGINES, EVERY_ENGINE
from ar3cli.lint.rules.docs import generate

TOOLS = re.compile(r"urdfdom|check_urdf|PyBullet|MuJoCo|Drake|Isaac|Gazebo|gazebo_ros_control|ros_control|ROS|RViz|"
                   r"MoveIt|xacro|XML parser|engine|tool")
"""Names a ``breaks`` sentence may use for the engine or tool that refuses or misbehaves."""


@pytest.mark.parametrize("rule", RULES, ids=lambda rule: rule.code)
def test_every_rule_says_what_it_is_about(rule):
    assert rule.engines, rule.code
    assert set(rule.engines) <= {*ENGINES, EVERY_ENGINE}, rule.engines
    assert set(rule.refused_by) <= set(ENGINES), rule.refused_by
    if rule.targets:  # a T rule is about the engines it runs for
        assert set(rule.targets) <= set(rule.engines)


@pytest.mark.parametrize("rule", [r for r in RULES if r.severity is Severity.ERROR], ids=lambda rule: rule.code)
def test_an_error_names_the_engine_that_refuses_or_misbehaves(rule):
    assert rule.breaks and TOOLS.search(rule.breaks), f"{rule.code} is an error but does not say which engine breaks"


@pytest.mark.parametrize("rule", [r for r in RULES if r.severity is not Severity.ERROR], ids=lambda rule: rule.code)
def test_only_errors_claim_a_refusal(rule):
    assert rule.breaks is None and not rule.refused_by, f"{rule.code}: a refusal is an error, or the claim is wrong"


def test_severity_follows_the_targets():
    i002, s001, j001 = REGISTRY["I002"], REGISTRY["S001"], REGISTRY["J001"]
    assert i002.target_bound and i002.severity_for(("pybullet", "ros")) is Severity.WARNING
    assert i002.severity_for(("ros",)) is Severity.INFO
    assert s001.severity_for(("pybullet",)) is Severity.INFO and s001.severity_for(("ros",)) is Severity.ERROR
    assert not j001.target_bound and j001.severity_for(("isaac",)) is Severity.ERROR
    assert REGISTRY["P004"].severity_for(("ros",)) is Severity.ERROR  # about the engine --engine chose


def test_a_ros_only_robot_gets_pybullets_default_mass_as_an_info(tmp_path):
    path = tmp_path / "r.urdf"
    path.write_text(REGISTRY["I002"].bad)
    for targets, expected in ((("pybullet", "ros"), Severity.WARNING), (("ros",), Severity.INFO)):
        options = LintOptions(targets=targets)
        (finding,) = [f for f in lint_file(path, options.rules(), options).findings if f.rule == "I002"]
        assert finding.severity is expected


def test_select_all_means_every_rule_and_the_default_leaves_opt_in_rules_out():
    assert OPT_IN_CODES == ("G012", "G013")
    everything = LintOptions(select=validate_patterns(["ALL"], "--select"))
    assert {r.code for r in everything.rules()} >= set(OPT_IN_CODES)
    assert not {r.code for r in LintOptions().rules()} & set(OPT_IN_CODES)


def test_the_policy_is_written_in_the_rules_document():
    text = generate()
    assert "## Severity policy" in text and "**Severity follows `--target`.**" in text
    for rule in RULES:
        section = text.split(f"### {rule.code} ")[1].split("\n### ")[0]
        assert "**About.**" in section
        assert ("**Error because.**" in section) == (rule.severity is Severity.ERROR)
