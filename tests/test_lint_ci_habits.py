"""lint-urdf's CI habits: --baseline/--write-baseline, --changed-since, --format junit, --explain."""

from __future__ import annotations

import json
import os
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from ar3cli.lint.rules import REGISTRY
from ar3cli.lint.rules.base import LINK_INERTIAL, arm, robot

NO_LIMIT = arm(joint_extra="")  # J001 error
ZERO_EFFORT = arm(joint_extra='<limit lower="-1" upper="1" effort="0" velocity="1"/>')  # J008 warning
TWO_BAD_JOINTS = robot(f"""
    <link name="base"/>
    <link name="a">{LINK_INERTIAL}</link>
    <link name="b">{LINK_INERTIAL}</link>
    <joint name="ja" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
    <joint name="jb" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
    """)


def _json(result) -> dict:
    assert "Traceback" not in result.stderr, result.stderr
    return json.loads(result.stdout)


def _one_line_error(result, text: str) -> None:
    assert result.code == 2, (result.stdout, result.stderr)
    assert result.stderr.startswith("ar3cli: error: ") and result.stderr.count("\n") == 1, result.stderr
    assert text in result.stderr and "Traceback" not in result.stderr


# ---- --explain -----------------------------------------------------------------------------------


def test_explain_prints_the_rules_documentation(cli):
    code = next(code for code, rule in REGISTRY.items() if rule.fixed_by)  # a rule with every paragraph
    rule = REGISTRY[code]
    result = cli("lint-urdf", "--explain", code.lower())
    assert result.code == 0 and result.stderr == ""
    text = result.stdout
    assert text.startswith(f"{code} {rule.name} ({rule.severity.value}, {rule.family}")
    assert rule.why.split()[0] in text and "Why it matters:" in text and "Fix:" in text
    assert f"Fixed by:\n  ar3cli {rule.fixed_by}" in text
    assert "Failing example:" in text and "Passing example:" in text and rule.bad.splitlines()[1].strip() in text
    assert text.rstrip().endswith(f"Docs: docs/rules.md#{rule.anchor} in ar3cli's source")
    by_name = cli("lint-urdf", "--explain", rule.name)
    assert by_name.code == 0 and by_name.stdout == text


def test_explain_json_has_every_documented_field(cli):
    import dataclasses

    rule = REGISTRY["J001"]
    doc = _json(cli("lint-urdf", "--explain", "J001", "--format", "json"))
    expected = {f.name for f in dataclasses.fields(rule)} - {"check"}
    assert expected <= set(doc) and "check" not in doc
    assert doc["code"] == "J001" and doc["severity"] == rule.severity.value and doc["bad"] == rule.bad


def test_explain_shows_fields_a_rule_may_gain(monkeypatch):
    """--explain reads the Rule generically: a field added later is shown without a change here."""
    from ar3cli.lint.engine import rule_document
    from ar3cli.output.explain import explain_text

    document = {**rule_document(REGISTRY["J001"]), "doc": "u", "measured_on": "Talos, TIAGo"}
    assert "Measured on:\n  Talos, TIAGo" in explain_text(document)


def test_explain_errors_and_path_rules(cli, write_urdf):
    _one_line_error(cli("lint-urdf", "--explain", "X999"), "unknown rule code 'X999'")
    _one_line_error(cli("lint-urdf", "--explain", "J001", str(write_urdf(NO_LIMIT))), "--explain takes")
    _one_line_error(cli("lint-urdf"), "missing PATH")
    _one_line_error(cli("lint-urdf", "--format", "json"), "missing PATH")


# ---- --format junit ------------------------------------------------------------------------------


def test_junit_report(cli, tmp_path):
    (tmp_path / "bad.urdf").write_text(NO_LIMIT)
    (tmp_path / "warn.urdf").write_text(ZERO_EFFORT)
    (tmp_path / "zgood.urdf").write_text(arm())
    result = cli("lint-urdf", ".", "--format", "junit", cwd=tmp_path)
    assert result.code == 1 and "FAILED: 3 files checked" in result.stderr  # the summary stays off stdout
    root = ET.fromstring(result.stdout)
    assert root.tag == "testsuites" and [child.tag for child in root] == ["testsuite"] * 3  # one per file
    suites = {suite.get("name"): suite for suite in root}
    assert list(suites) == ["bad.urdf", "warn.urdf", "zgood.urdf"]
    assert (root.get("tests"), root.get("failures"), root.get("errors")) == ("3", "1", "0")
    (case,) = suites["bad.urdf"].findall("testcase")  # one testcase per failing finding
    (failure,) = case.findall("failure")
    assert case.get("name") == "J001 bad.urdf:5:3" and case.get("classname") == "bad.urdf"
    assert failure.get("type") == "J001" and failure.get("message").startswith("bad.urdf:5:3: J001 ")
    assert "fix: Add <limit" in failure.text
    (passing,) = suites["warn.urdf"].findall("testcase")
    assert passing.find("failure") is None and "J008" in passing.find("system-out").text
    assert [len(case) for case in suites["zgood.urdf"]] == [0]  # a clean file is one passing testcase
    strict = ET.fromstring(cli("lint-urdf", ".", "-f", "junit", "--fail-on", "warning", cwd=tmp_path).stdout)
    assert strict.get("failures") == "2" and strict.find(".//testsuite[@name='warn.urdf']/testcase/failure") is not None


def test_junit_escapes_markup_and_forbidden_characters(cli, tmp_path):
    from ar3cli.output.junit import xml_text

    odd = NO_LIMIT.replace('name="j1"', 'name="j&amp;1 &lt;x&gt; &quot;q&quot;"')
    (tmp_path / "odd & <name>.urdf").write_text(odd)
    (tmp_path / "junk.urdf").write_bytes(b"\x00\x1b binary")
    result = cli("lint-urdf", ".", "--format", "junit", cwd=tmp_path)
    root = ET.fromstring(result.stdout)  # well-formed
    messages = [failure.get("message") for failure in root.iter("failure")]
    assert any("joint 'j&1 <x> \"q\"' has no <limit>" in message for message in messages)
    assert root.find(".//testsuite[@name='odd & <name>.urdf']") is not None
    assert xml_text("a\x00b\x1bc\td") == "a\\x00b\\x1bc\td"


# ---- --baseline / --write-baseline --------------------------------------------------------------


def test_baseline_hides_known_findings_and_fails_on_new_ones(cli, tmp_path):
    models = tmp_path / "models"
    models.mkdir()
    (models / "a.urdf").write_text(TWO_BAD_JOINTS)
    (models / "b.urdf").write_text(ZERO_EFFORT)
    (tmp_path / "ci").mkdir()
    written = cli("lint-urdf", "models", "--write-baseline", "ci/baseline.json", cwd=tmp_path)
    assert written.code == 0 and "wrote ci/baseline.json: 3 findings in 2 files" in written.stdout
    stored = json.loads((tmp_path / "ci" / "baseline.json").read_text())
    assert set(stored["files"]) == {"../models/a.urdf", "../models/b.urdf"}  # relative to the baseline's folder
    assert {entry["rule"] for entry in stored["files"]["../models/a.urdf"]} == {"J001"}
    assert "line" not in json.dumps(stored["files"])

    clean = cli("lint-urdf", "models", "--baseline", "ci/baseline.json", "--fail-on", "warning", cwd=tmp_path)
    assert clean.code == 0 and "2 clean; 3 baselined" in clean.stdout and "J001" not in clean.stdout

    # lines shift (a comment and a link above), and a new finding appears: only that one counts
    shifted = TWO_BAD_JOINTS.replace('<robot name="r">', '<robot name="r">\n  <!-- moved -->\n\n')
    shifted = shifted.replace('<joint name="ja"', f'<link name="c">{LINK_INERTIAL}</link>\n  <joint name="ja"')
    shifted = shifted.replace("</robot>", '  <joint name="jc" type="prismatic"><parent link="b"/><child link="c"/>'
                                          '<axis xyz="0 0 1"/></joint>\n</robot>')
    (models / "a.urdf").write_text(shifted)
    doc = _json(cli("lint-urdf", "models", "--baseline", "ci/baseline.json", "-f", "json", cwd=tmp_path))
    assert [(f["rule"], "'jc'" in f["message"]) for f in doc["findings"]] == [("J001", True)]
    assert doc["summary"]["baselined"] == 3 and doc["summary"]["failed"] is True
    assert doc["summary"]["suppressed"]["baseline"] == 3 and {f["suppressed_by"] for f in doc["suppressed"]} == {"baseline"}

    # from another working directory, and with a relative path to the baseline
    elsewhere = cli("lint-urdf", str(models / "b.urdf"), "--baseline", str(tmp_path / "ci" / "baseline.json"),
                    "--fail-on", "warning", cwd=tmp_path / "ci")
    assert elsewhere.code == 0 and "1 baselined" in elsewhere.stdout


def test_baseline_counts_alike_findings(cli, tmp_path):
    """Two findings with one fingerprint are accepted twice, a third is new; a fixed one is said."""
    from ar3cli.findings import Finding, Severity
    from ar3cli.lint.baseline import apply_baseline, fingerprint, read_baseline, write_baseline
    from ar3cli.lint.engine import LintResult

    def finding(line: int, message: str = "link has no name") -> Finding:
        return Finding("S001", Severity.ERROR, message, str(tmp_path / "r.urdf"), line, 3)

    assert fingerprint(finding(3)) == fingerprint(finding(300))
    assert fingerprint(finding(3, "link 'a' mass 0")) == fingerprint(finding(3, "link 'a' mass -1.5"))
    assert fingerprint(finding(3, "link 'a' mass 0")) != fingerprint(finding(3, "link 'b' mass 0"))
    baseline_path = tmp_path / "baseline.json"
    write_baseline(baseline_path, [LintResult("r.urdf", True, [finding(3), finding(9), finding(12, "other 'x'")])])
    accepted = read_baseline(baseline_path)
    results, dropped, unused = apply_baseline([LintResult("r.urdf", True, [finding(1), finding(2), finding(4)])],
                                              accepted)
    assert [f.line for f in results[0].findings] == [4] and (dropped, unused) == (2, 1)


@pytest.mark.parametrize(("content", "text"), [
    (None, "no such file"),
    (b"{not json", "not JSON"),
    (b'{"files": []}', "not an ar3cli baseline"),
    (b'{"ar3cli-baseline": 1, "files": {"a.urdf": [{"rule": "J001"}]}}', "no rule, fingerprint or count"),
])
def test_unreadable_baseline_is_one_line(cli, write_urdf, tmp_path, content, text):
    baseline = tmp_path / "baseline.json"
    if content is not None:
        baseline.write_bytes(content)
    _one_line_error(cli("lint-urdf", str(write_urdf(NO_LIMIT)), "--baseline", str(baseline)), text)


# ---- --changed-since -----------------------------------------------------------------------------

STL = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\nendloop\nendfacet\nendsolid t\n"
WITH_MESH = arm(link_extra=LINK_INERTIAL + '<visual><geometry><mesh filename="../meshes/part.stl"/></geometry></visual>')
TOP_XACRO = ('<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="x">\n'
             '  <xacro:include filename="macros/parts.xacro"/>\n  <link name="base"/>\n'
             '  <xacro:part parent="base"/>\n</robot>\n')
MACROS = ('<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
          '  <xacro:macro name="part" params="parent">\n'
          f'    <link name="arm">{LINK_INERTIAL}</link>\n'
          '    <joint name="j1" type="revolute"><parent link="${parent}"/><child link="arm"/><axis xyz="0 0 1"/>\n'
          '      <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>\n'
          '  </xacro:macro>\n</robot>\n')
GIT_ENV = {"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@example.com", "GIT_COMMITTER_NAME": "t",
           "GIT_COMMITTER_EMAIL": "t@example.com", "GIT_CONFIG_NOSYSTEM": "1", "GIT_CONFIG_GLOBAL": os.devnull}


def git(repo: Path, *args: str) -> str:
    environment = {key: value for key, value in os.environ.items() if not key.startswith("GIT_")}
    done = subprocess.run(["git", "-C", str(repo), "-c", "commit.gpgsign=false", *args], capture_output=True,
                          text=True, env={**environment, **GIT_ENV}, check=True)
    return done.stdout


@pytest.fixture
def repo(tmp_path) -> Path:
    """A git repository: two URDFs (one using a mesh), a xacro with an include, committed."""
    root = tmp_path / "repo"
    (root / "robots" / "macros").mkdir(parents=True)
    (root / "meshes").mkdir()
    (root / "meshes" / "part.stl").write_text(STL)
    (root / "robots" / "a_mesh.urdf").write_text(WITH_MESH)
    (root / "robots" / "b_plain.urdf").write_text(arm())
    (root / "robots" / "c_top.urdf.xacro").write_text(TOP_XACRO)
    (root / "robots" / "macros" / "parts.xacro").write_text(MACROS)
    (root / "README.md").write_text("robots\n")
    git(root, "init", "-q")
    git(root, "add", ".")
    git(root, "commit", "-qm", "robots")
    return root


def _linted(cli, repo: Path, *args: str) -> list[str]:
    result = cli("lint-urdf", "robots", "--changed-since", "HEAD", "--format", "json", *args, cwd=repo,
                 env={"GIT_CONFIG_NOSYSTEM": "1"})
    return [entry["path"] for entry in _json(result)["files"]]


def test_changed_since_nothing_changed(cli, repo):
    (repo / "README.md").write_text("docs only\n")
    result = cli("lint-urdf", "robots", "--changed-since", "HEAD", cwd=repo)
    assert result.code == 0 and "nothing to check" in result.stdout and "4 not checked" in result.stdout
    doc = _json(cli("lint-urdf", "robots", "--changed-since", "HEAD", "-f", "json", cwd=repo))
    assert doc["files"] == [] and doc["summary"]["files"] == 0


def test_changed_since_picks_changed_files_and_their_users(cli, repo):
    (repo / "robots" / "b_plain.urdf").write_text(NO_LIMIT)
    assert _linted(cli, repo) == ["robots/b_plain.urdf"]
    git(repo, "commit", "-qam", "b")
    (repo / "meshes" / "part.stl").write_text(STL.replace("0.1", "0.2"))  # a mesh the first robot uses
    assert _linted(cli, repo) == ["robots/a_mesh.urdf"]
    from_inside = cli("lint-urdf", ".", "--changed-since", "HEAD", "-f", "json", cwd=repo / "robots")
    assert [entry["path"] for entry in _json(from_inside)["files"]] == ["a_mesh.urdf"]
    text = cli("lint-urdf", "robots", "--changed-since", "HEAD~1", cwd=repo)
    assert "2 of 4 robot files: 1 changed (robots/b_plain.urdf); 1 uses a changed file " \
           "(robots/a_mesh.urdf uses meshes/part.stl)" in text.stdout
    git(repo, "checkout", "-q", "--", "meshes/part.stl")
    (repo / "robots" / "macros" / "parts.xacro").write_text(MACROS.replace('effort="10"', 'effort="0"'))
    assert _linted(cli, repo) == ["robots/c_top.urdf.xacro", "robots/macros/parts.xacro"]
    git(repo, "checkout", "-q", "--", "robots/macros/parts.xacro")
    (repo / "meshes" / "part.stl").unlink()  # a deleted mesh: its users now lack it
    assert _linted(cli, repo) == ["robots/a_mesh.urdf"]
    git(repo, "checkout", "-q", "--", "meshes/part.stl")
    (repo / "robots" / "new.urdf").write_text(arm())  # untracked
    (repo / ".gitignore").write_text("ignored.urdf\n")
    (repo / "robots" / "ignored.urdf").write_text(arm())
    assert _linted(cli, repo) == ["robots/new.urdf"]
    assert git(repo, "status", "--porcelain") == "?? .gitignore\n?? robots/new.urdf\n"


def test_changed_since_only_reads_the_repository(cli, repo):
    """A file whose time stamps changed but not its bytes is not 'changed', and git's index (whose
    stat cache ``git diff`` would refresh) is left alone."""
    index = repo / ".git" / "index"
    before = (index.read_bytes(), index.stat().st_mtime_ns)
    os.utime(repo / "robots" / "b_plain.urdf", ns=(1, 1))
    assert _linted(cli, repo) == []
    assert (index.read_bytes(), index.stat().st_mtime_ns) == before


def test_changed_since_errors(cli, repo, tmp_path):
    _one_line_error(cli("lint-urdf", "robots", "--changed-since", "no-such-branch", cwd=repo),
                    "unknown git ref 'no-such-branch'")
    _one_line_error(cli("lint-urdf", "robots", "--changed-since", "--output=x", cwd=repo), "is not a git ref")
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "r.urdf").write_text(arm())
    _one_line_error(cli("lint-urdf", str(outside), "--changed-since", "HEAD", cwd=outside,
                        env={"GIT_CEILING_DIRECTORIES": str(tmp_path)}), "not in a git working tree")
    _one_line_error(cli("lint-urdf", "robots", "--changed-since", "HEAD", "--write-baseline", "b.json", cwd=repo),
                    "cannot be combined")
