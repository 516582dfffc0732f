"""benchmarks/quietness.py's bookkeeping: which xacro files are macro-only, keys that survive a reworded
message, a seeded sample that keeps its findings when others come and go, verdicts carried to a
finding whose line moved, and the stratified estimate. Nothing is downloaded or linted here."""

import importlib.util
import sys

import pytest
from conftest import REPO

XACRO = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'


@pytest.fixture(scope="module")
def quietness():
    spec = importlib.util.spec_from_file_location("quietness", REPO / "benchmarks" / "quietness.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["quietness"] = module  # dataclasses look their module up while the class is built
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop("quietness", None)


@pytest.mark.parametrize(("name", "body", "macro_only"), [
    ("arm_macro.xacro", '<xacro:property name="a" value="1"/><xacro:include filename="x.xacro"/>'
                        '<xacro:macro name="arm" params="p"><link name="${p}base"/></xacro:macro>', True),
    ("materials.xacro", '<material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>', True),
    ("robot.urdf.xacro", '<xacro:include filename="arm_macro.xacro"/><xacro:arm p=""/>', False),
    ("robot2.xacro", '<xacro:if value="1"><link name="base"/></xacro:if>', False),
    ("plain.xacro", '<link name="base"/>', False),
    ("fragment.urdf", '<xacro:macro name="arm"><link name="a"/></xacro:macro>', False),
])
def test_macro_only_files_are_those_whose_top_level_makes_no_link(quietness, tmp_path, name, body, macro_only):
    path = tmp_path / name
    path.write_text(f'<?xml version="1.0"?>\n<robot {XACRO}>{body}</robot>\n')
    assert quietness.is_macro_only(path) is macro_only


def test_a_file_that_does_not_parse_is_an_entry_point(quietness, tmp_path):
    path = tmp_path / "broken.xacro"
    path.write_text("<robot><link name='a'>")
    assert quietness.is_macro_only(path) is False


def _finding(quietness, line, message, rule="G008", package="pkg", file="pkg/r.urdf"):
    return quietness.Finding(package, file, file, "entry", rule, "warning", line, message)


def test_the_digest_names_what_the_message_is_about_not_its_words(quietness):
    digest = quietness.message_digest
    assert digest("link 'a' has 1 visual shape(s) but no <collision>") == digest("no <collision> on link 'a'")
    assert digest("link 'a' has no <collision>") != digest("link 'b' has no <collision>")


def test_keys_tell_apart_the_robots_that_share_a_macro(quietness):
    findings = [quietness.Finding("p", "p/arm.xacro", entry, "entry", "I001", "error", 5, "link 'l' moves")
                for entry in ("p/a.urdf.xacro", "p/b.urdf.xacro")]
    quietness.assign_keys(findings, seed=1)
    assert len({f.key for f in findings}) == 2
    assert all(f.key.startswith("p/arm.xacro:5:I001:") and "@p/" in f.key for f in findings)


def test_the_sample_is_seeded_and_keeps_its_findings_when_others_go(quietness):
    def sample(findings, seed):
        quietness.assign_keys(findings, seed)
        quietness.mark_sample(findings, 5, 25)
        return {f.key for f in findings if f.sampled}

    many = [_finding(quietness, line, f"link 'l{line}' has no <collision>") for line in range(1, 101)]
    first = sample(many, 35)
    assert len(first) == 10  # ceil(sqrt(100))
    assert sample([_finding(quietness, f.line, f.message) for f in many], 35) == first
    assert sample([_finding(quietness, f.line, f.message) for f in many], 36) != first
    kept = [_finding(quietness, f.line, f.message) for f in many if f.key in first or f.line % 2]
    assert sample(kept, 35) <= first  # 55 findings: the 8 best-ranked, all from the first sample


def test_every_package_gets_a_share_then_the_rest_follows_their_size(quietness):
    assert quietness.allocate({"big": 900, "mid": 90, "small": 2}, ["small", "mid", "big"], 10) == \
        {"small": 1, "mid": 1, "big": 8}
    assert quietness.allocate({"a": 3, "b": 1}, ["b", "a"], 4) == {"a": 3, "b": 1}


def test_a_verdict_follows_its_finding_to_another_line_or_to_new_words(quietness):
    moved = _finding(quietness, 12, "link 'a' has no <collision>")
    reworded = _finding(quietness, 30, "link 'c' lacks collision geometry", file="pkg/s.urdf")
    quietness.assign_keys([moved, reworded], 35)
    old_moved = moved.key.replace(":12:", ":10:")
    old_reworded = "pkg/s.urdf:30:G008:" + quietness.message_digest("link 'c' has no <collision>")
    verdicts = {old_moved: {"verdict": "false"}, old_reworded: {"verdict": "true"}}
    matched = quietness.match_verdicts([moved, reworded], verdicts)
    assert matched[moved.key] == (verdicts[old_moved], old_moved)
    assert matched[reworded.key] == (verdicts[old_reworded], old_reworded)


def test_the_estimate_weighs_each_package_by_its_own_findings(quietness):
    row = quietness.Row("G008", "warning")
    row.findings.update({"big": 90, "small": 10, "unjudged": 100})
    row.judged["big"].update({"true": 2})
    row.judged["small"].update({"false": 2})
    # big 90 x 0 + small 10 x 1 + unjudged 100 x the pooled 2/4
    assert row.estimate("false") == pytest.approx(60.0)
