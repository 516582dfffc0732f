"""lint-urdf through the real CLI: formats, configuration, suppression, exit codes, bad input."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from ar3cli.lint.rules import REGISTRY
from ar3cli.lint.rules.base import arm
from tests.conftest import ASSETS

ZERO_EFFORT = arm(joint_extra='<limit lower="-1" upper="1" effort="0" velocity="1"/>')  # J008 warning
NO_LIMIT = arm(joint_extra="")  # J001 error


def test_json_document_and_exit_code(cli, write_urdf):
    path = write_urdf(NO_LIMIT)
    result = cli("lint-urdf", str(path), "--format", "json")
    assert result.code == 1, result.stderr
    doc = json.loads(result.stdout)
    assert set(doc) == {"files", "findings", "summary", "suppressed"}
    (finding,) = [f for f in doc["findings"] if f["rule"] == "J001"]
    assert set(finding) == {"path", "line", "column", "rule", "severity", "message", "hint", "fixed_by"}
    assert finding["severity"] == "error" and finding["line"] == 5 and "'j1'" in finding["message"]
    assert doc["summary"]["error"] >= 1 and doc["summary"]["failed"] is True


def test_fail_on_and_exit_zero(cli, write_urdf):
    path = str(write_urdf(ZERO_EFFORT))
    assert cli("lint-urdf", path).code == 0  # a warning does not fail by default
    assert cli("lint-urdf", path, "--fail-on", "warning").code == 1
    assert cli("lint-urdf", path, "--fail-on", "warning", "--exit-zero").code == 0


def test_text_output_has_location_code_and_summary(cli, write_urdf):
    result = cli("lint-urdf", str(write_urdf(NO_LIMIT)))
    assert "robot.urdf:5:3" in result.stdout and "J001" in result.stdout
    assert "FAILED: 1 file checked, 1 errors" in result.stdout


def test_sarif_validates_against_the_schema(cli, write_urdf, tmp_path):
    import jsonschema  # part of the test extra: this test must run, not skip

    schema_path = Path(__file__).parent / "data" / "sarif-schema-2.1.0.json"
    write_urdf(NO_LIMIT)
    (tmp_path / "junk.urdf").write_bytes(b"\x00\xff binary")
    result = cli("lint-urdf", str(tmp_path), "--format", "sarif", cwd=tmp_path)
    doc = json.loads(result.stdout)
    jsonschema.validate(doc, json.loads(schema_path.read_text()))
    run = doc["runs"][0]
    results = {r["ruleId"]: r for r in run["results"]}
    assert results["J001"]["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] == "robot.urdf"
    assert results["J001"]["locations"][0]["physicalLocation"]["region"] == {"startLine": 5, "startColumn": 3}
    assert results["F002"]["level"] == "error"
    rule_ids = [r["id"] for r in run["tool"]["driver"]["rules"]]
    assert rule_ids[results["J001"]["ruleIndex"]] == "J001"
    first = run["tool"]["driver"]["rules"][0]
    assert "helpUri" not in first and "informationUri" not in run["tool"]["driver"]  # no made-up address
    assert first["help"]["markdown"].endswith("`ar3cli lint-urdf --explain F001`, or "
                                              "docs/rules.md#f001-unreadable in ar3cli's source.")


def test_github_annotations_escape_properties_and_data(cli, write_urdf):
    path = write_urdf(NO_LIMIT, "dir,with:odd/robot.urdf")
    result = cli("lint-urdf", str(path), "--format", "github")
    line = next(text for text in result.stdout.splitlines() if "title=J001" in text)
    assert line.startswith("::error file=") and "dir%2Cwith%3Aodd/robot.urdf" in line
    assert ",line=5,col=3,title=J001::" in line


def test_github_escape_functions():
    from ar3cli.output.escape import github_data, github_property
    from ar3cli.output.github_actions import workflow_command

    assert github_data("50%") == "50%25"
    assert github_data("a\r\nb") == "a\\x0d\\x0ab"  # a name's newline is shown, never a line of its own
    assert github_property("a:b,c%") == "a%3Ab%2Cc%25"
    assert workflow_command("notice", ["one", "two"], title="t") == "::notice title=t::one%0Atwo"  # ar3cli's own lines


def test_markdown_table(cli, write_urdf):
    result = cli("lint-urdf", str(write_urdf(NO_LIMIT)), "--format", "markdown")
    assert "| location | rule | severity | message | hint |" in result.stdout
    assert "| J001 | error |" in result.stdout


def test_github_format_writes_step_summary(cli, tmp_path):
    summary = tmp_path / "step_summary.md"
    summary.write_text("earlier step\n")
    example = str(ASSETS / "examples" / "ar3_no_inertia.urdf")
    result = cli("lint-urdf", example, "--format", "github", env={"GITHUB_STEP_SUMMARY": str(summary)})
    assert result.code == 1
    assert result.stdout.startswith("::error file=")
    text = summary.read_text()
    assert text.startswith("earlier step\n## ar3cli lint-urdf")  # appended, as GitHub expects
    assert "| I001 | error |" in text
    assert "&lt;inertial&gt;" in text and "<inertial>" not in text  # not swallowed as an HTML tag


def test_unwritable_step_summary_is_one_error_after_the_annotations(cli, tmp_path):
    example = str(ASSETS / "examples" / "ar3_no_inertia.urdf")
    result = cli("lint-urdf", example, "--format", "github", env={"GITHUB_STEP_SUMMARY": str(tmp_path)})  # a folder
    assert result.code == 2 and result.stdout.count("::error file=") == 1  # three I001 in one file: one annotation
    assert result.stderr.startswith("ar3cli: error: cannot append to $GITHUB_STEP_SUMMARY") and "Traceback" not in result.stderr
    assert cli("lint-urdf", example, "--format", "github", env={"GITHUB_STEP_SUMMARY": ""}).code == 1


def test_select_and_ignore(cli, write_urdf):
    path = str(write_urdf(NO_LIMIT))
    ignored = json.loads(cli("lint-urdf", path, "--ignore", "J001", "--format", "json").stdout)
    assert "J001" not in {f["rule"] for f in ignored["findings"]}
    selected = json.loads(cli("lint-urdf", path, "--select", "I,G", "--format", "json").stdout)
    assert {f["rule"][0] for f in selected["findings"]} <= {"I", "G"}
    bad = cli("lint-urdf", path, "--select", "X999")
    assert bad.code == 2 and "unknown rule code" in bad.stderr and "Traceback" not in bad.stderr


def test_pyproject_configuration(cli, tmp_path):
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "a.urdf").write_text(ZERO_EFFORT)
    (tmp_path / "models" / "b.urdf").write_text(NO_LIMIT)
    (tmp_path / "pyproject.toml").write_text(
        '[tool.ar3cli.lint]\nignore = ["G"]\nfail-on = "warning"\n'
        '[tool.ar3cli.lint.per-file-ignores]\n"models/b.urdf" = ["J001"]\n'
        '[tool.ar3cli.lint.severity]\nJ008 = "error"\n')
    result = cli("lint-urdf", "models", "--format", "json", cwd=tmp_path)
    doc = json.loads(result.stdout)
    rules = {(Path(f["path"]).name, f["rule"], f["severity"]) for f in doc["findings"]}
    assert ("a.urdf", "J008", "error") in rules
    assert not any(name == "b.urdf" and rule == "J001" for name, rule, _ in rules)
    assert doc["summary"]["fail_on"] == "warning" and result.code == 1
    assert cli("lint-urdf", "models", "--no-config", "--format", "json", cwd=tmp_path).code == 1
    (tmp_path / "pyproject.toml").write_text('[tool.ar3cli.lint]\nselekt = ["J"]\n')
    typo = cli("lint-urdf", "models", cwd=tmp_path)
    assert typo.code == 2 and "unknown key" in typo.stderr
    (tmp_path / "pyproject.toml").write_text('[tool.ar3cli.lint\nignore = ["G"]\n')
    broken = cli("lint-urdf", "models", cwd=tmp_path)
    assert broken.code == 2 and "cannot read configuration" in broken.stderr and broken.stderr.count("\n") == 1
    (tmp_path / "pyproject.toml").write_text('[tool.black\nline-length = 100\n')  # not ours, even if broken
    assert cli("lint-urdf", "models", cwd=tmp_path).code == 1


def test_inline_and_file_level_suppression(cli, write_urdf):
    inline = NO_LIMIT.replace('<joint name="j1" type="revolute">',
                              '<joint name="j1" type="revolute">\n<!-- ar3cli: ignore[J001] -->')
    doc = json.loads(cli("lint-urdf", str(write_urdf(inline, "a.urdf")), "--format", "json").stdout)
    assert "J001" not in {f["rule"] for f in doc["findings"]}
    # a comment on an ancestor (the robot) suppresses too; ignore without a list means every rule
    everything = NO_LIMIT.replace('<robot name="r">', '<robot name="r">\n<!-- ar3cli: ignore -->')
    assert json.loads(cli("lint-urdf", str(write_urdf(everything, "b.urdf")), "--format", "json").stdout)["findings"] == []
    # a comment in a sibling element does not suppress
    sibling = NO_LIMIT.replace('<link name="base">', '<link name="base"><!-- ar3cli: ignore[J001] -->')
    assert "J001" in {f["rule"] for f in json.loads(cli("lint-urdf", str(write_urdf(sibling, "c.urdf")),
                                                        "--format", "json").stdout)["findings"]}
    file_level = NO_LIMIT + "<!-- ar3cli: ignore-file[J001] -->\n"
    assert "J001" not in {f["rule"] for f in json.loads(cli("lint-urdf", str(write_urdf(file_level, "d.urdf")),
                                                            "--format", "json").stdout)["findings"]}


def test_ignore_file_counts_only_inside_a_comment(cli, tmp_path):
    """``ar3cli:ignore-file`` anywhere in the bytes silenced the file, even as the robot's name."""
    (tmp_path / "named.urdf").write_text(NO_LIMIT.replace('<robot name="r">', '<robot name="ar3cli:ignore-file">'))
    (tmp_path / "text.urdf").write_text(NO_LIMIT.replace("</robot>", "<gazebo>ar3cli: ignore-file</gazebo></robot>"))
    (tmp_path / "before.urdf").write_text(NO_LIMIT.replace("<robot", "<!-- ar3cli: ignore-file[J001] -->\n<robot"))
    (tmp_path / "b.urdf.xacro").write_text(NO_LIMIT.replace('<robot name="r">', '<robot name="r" xmlns:xacro='
                                           '"http://www.ros.org/wiki/xacro"><!-- ar3cli: ignore-file[J001] -->'))
    doc = json.loads(cli("lint-urdf", "named.urdf", "text.urdf", "before.urdf", "b.urdf.xacro", "-f", "json",
                         cwd=tmp_path).stdout)
    j001 = {f["path"] for f in doc["findings"] if f["rule"] == "J001"}
    assert j001 == {"named.urdf", "text.urdf"}
    assert {(f["path"], f["suppressed_by"]) for f in doc["suppressed"]} == {("before.urdf", "comment"),
                                                                             ("b.urdf.xacro", "comment")}


def test_every_run_says_what_was_suppressed_and_isolated_applies_nothing(cli, tmp_path):
    """A pyproject.toml with ``ignore = ["ALL"]`` or an ``ar3cli: ignore`` comment turned a failing
    file into "passed" and nothing said so: the summary line, JSON, SARIF and the GitHub step summary
    count the suppressed findings by what suppressed them; ``--isolated`` applies neither."""
    (tmp_path / "a.urdf").write_text(NO_LIMIT)
    (tmp_path / "b.urdf").write_text(NO_LIMIT.replace('<robot name="r">', '<robot name="r"><!-- ar3cli: ignore -->'))
    (tmp_path / "pyproject.toml").write_text('[tool.ar3cli.lint]\nignore = ["J001"]\n[tool.ar3cli.lint.severity]\n'
                                             'J008 = "info"\n')
    text = cli("lint-urdf", "a.urdf", "b.urdf", "--no-cache", cwd=tmp_path)
    assert text.code == 0, text.stdout
    assert text.stdout.splitlines()[-1] == (
        "passed: 2 files checked, 0 errors, 0 warnings, 0 info; 2 clean; 2 suppressed (1 by pyproject.toml, 1 by "
        "comments in the files) (fail-on: error)")
    summary = json.loads(cli("lint-urdf", "a.urdf", "b.urdf", "-f", "json", cwd=tmp_path).stdout)["summary"]
    assert summary["suppressed"] == {"config": 1, "comment": 1, "baseline": 0}
    sarif = json.loads(cli("lint-urdf", "a.urdf", "b.urdf", "-f", "sarif", cwd=tmp_path).stdout)
    kinds = sorted(r["suppressions"][0]["kind"] for r in sarif["runs"][0]["results"] if "suppressions" in r)
    assert kinds == ["external", "inSource"]
    step_summary = tmp_path / "summary.md"
    github = cli("lint-urdf", "a.urdf", "b.urdf", "-f", "github", cwd=tmp_path,
                 env={"GITHUB_STEP_SUMMARY": str(step_summary)})
    assert github.code == 0 and "2 suppressed (1 by pyproject.toml" in step_summary.read_text()
    isolated = cli("lint-urdf", "a.urdf", "b.urdf", "--isolated", "-f", "json", cwd=tmp_path)
    document = json.loads(isolated.stdout)
    assert isolated.code == 1 and document["summary"]["suppressed"] == {"config": 0, "comment": 0, "baseline": 0}
    assert sorted(f["path"] for f in document["findings"] if f["rule"] == "J001") == ["a.urdf", "b.urdf"]
    (tmp_path / "pyproject.toml").write_text('[tool.ar3cli.lint.severity]\nJ001 = "info"\n')
    lowered = cli("lint-urdf", "a.urdf", cwd=tmp_path)
    assert lowered.code == 0 and "; 1 made less severe by pyproject.toml" in lowered.stdout


def test_folders_are_searched_and_xacro_expanded(cli, tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "a.urdf").write_text(NO_LIMIT)
    (tmp_path / "sub" / "b.urdf.xacro").write_text(
        '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
        '  <xacro:arg name="effort" default="0"/>\n  <link name="base"/>\n'
        '  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>\n'
        '  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>\n'
        '    <limit lower="-1" upper="1" effort="$(arg effort)" velocity="1"/></joint>\n</robot>\n')
    (tmp_path / "sub" / "notes.txt").write_text("not a robot")
    doc = json.loads(cli("lint-urdf", str(tmp_path), "--format", "json").stdout)
    assert [Path(f["path"]).name for f in doc["files"]] == ["a.urdf", "b.urdf.xacro"]
    j008 = [f for f in doc["findings"] if f["rule"] == "J008"]
    assert len(j008) == 1 and (j008[0]["line"], j008[0]["column"]) == (7, 5)  # the <limit> in the xacro source
    assert j008[0]["path"] == str(tmp_path / "sub" / "b.urdf.xacro")
    with_arg = json.loads(cli("lint-urdf", str(tmp_path / "sub" / "b.urdf.xacro"), "--xacro-arg", "effort:=5",
                              "--format", "json").stdout)
    assert with_arg["findings"] == []


ENTITY_BOMB = ('<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;&lol;&lol;">]>\n'
               '<robot name="&lol2;"><link name="base"/></robot>\n')
EXTERNAL_ENTITY = ('<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY secret SYSTEM "file:///etc/passwd">]>\n'
                   '<robot name="r"><link name="&secret;"/></robot>\n')


@pytest.mark.parametrize("name,content,code", [
    ("empty.urdf", b"", "F002"),
    ("blank.urdf", b"   \n\n", "F002"),
    ("binary.urdf", bytes(range(256)) * 4, "F002"),
    ("truncated.urdf", b'<?xml version="1.0"?>\n<robot name="r">\n  <link name="base"', "F002"),
    ("bomb.urdf", ENTITY_BOMB.encode(), "F002"),
    ("external.urdf", EXTERNAL_ENTITY.encode(), "F002"),
    ("sdf.urdf", b'<?xml version="1.0"?><sdf version="1.6"/>', "F003"),
    ("broken.xacro", b'<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r"><link name="${nope}"/></robot>',
     "F004"),
])
def test_bad_input_is_a_finding_and_the_run_goes_on(cli, tmp_path, name, content, code):
    (tmp_path / name).write_bytes(content)
    (tmp_path / "zgood.urdf").write_text(arm())
    result = cli("lint-urdf", str(tmp_path / name), str(tmp_path / "zgood.urdf"), "--format", "json")
    assert result.code == 1 and "Traceback" not in result.stderr, result.stderr
    doc = json.loads(result.stdout)
    (finding,) = [f for f in doc["findings"] if f["path"].endswith(name)]
    assert finding["rule"] == code
    assert "root:" not in result.stdout and "/bin/" not in result.stdout  # nothing of /etc/passwd leaked
    assert len(doc["files"]) == 2


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are a POSIX feature")
def test_a_named_pipe_is_a_finding_not_a_hang(cli, tmp_path):
    """Reading a FIFO waits for a writer forever: it is refused as not a regular file."""
    os.mkfifo(tmp_path / "pipe.urdf")
    (tmp_path / "zgood.urdf").write_text(arm())
    result = cli("lint-urdf", str(tmp_path), "--format", "json", timeout=60)
    (finding,) = json.loads(result.stdout)["findings"]
    assert result.code == 1 and finding["rule"] == "F001" and "not a regular file" in finding["message"]
    fixer = cli("fix-inertia", "--check", str(tmp_path / "pipe.urdf"), timeout=60)
    assert fixer.code == 2 and fixer.stderr.count("\n") == 1 and "not a regular file" in fixer.stderr


def test_directory_named_like_a_file_and_missing_paths(cli, tmp_path):
    (tmp_path / "dir.urdf").mkdir()
    (tmp_path / "dir.urdf" / "inner.urdf").write_text(arm())
    assert cli("lint-urdf", str(tmp_path / "dir.urdf")).code == 0
    missing = cli("lint-urdf", str(tmp_path / "nope.urdf"))
    assert missing.code == 2 and missing.stderr.strip().count("\n") == 0 and "no such file" in missing.stderr
    empty = tmp_path / "empty"
    empty.mkdir()
    none = cli("lint-urdf", str(empty))
    assert none.code == 2 and "no .urdf or .xacro files" in none.stderr


def test_static_lint_does_not_import_numpy_pybullet_or_trimesh(tmp_path, pybullet_data_dir):
    """The pre-commit path stays light: the Franka Panda's 18 OBJ meshes and 11 tensors without numpy."""
    import subprocess
    import sys

    from tests.conftest import REPO

    (tmp_path / "r.urdf").write_text(arm())
    files = [str(tmp_path / "r.urdf"), str(pybullet_data_dir / "franka_panda" / "panda.urdf")]
    code = ("import sys\nfrom ar3cli.cli import main\nfrom ar3cli.infra import process_pool\n"
            "process_pool.can_fork = lambda: False\n"  # lint here, not in a worker: its imports and reads are seen
            f"try:\n    main(['lint-urdf', '--format', 'json', *{files!r}])\nexcept SystemExit:\n    pass\n"
            "from ar3cli.urdf.meshinfo import _mesh_bounds\nprint(_mesh_bounds.cache_info().currsize)\n"
            "print(sorted(m for m in ('numpy', 'pybullet', 'trimesh', 'yourdfpy') if m in sys.modules))")
    env = {"PYTHONPATH": str(REPO), "NO_COLOR": "1", "PATH": "/usr/bin:/bin", "AR3CLI_CACHE_DIR": str(tmp_path / "c")}
    runs = []
    for _ in range(2):
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, env=env)
        doc, meshes_read, modules = out.stdout.strip().rsplit("\n", 2)
        assert modules == "[]", out.stderr
        runs.append((json.loads(doc), meshes_read))
    (first, first_read), (second, second_read) = runs
    assert first["summary"]["files"] == 2 and first_read == "18"  # all 18 panda meshes were read
    assert second == first and second_read == "0"  # the next process takes their bounds from the disk cache


def test_sim_rules_run_only_with_sim(cli, write_urdf):
    path = str(write_urdf(NO_LIMIT))
    static = json.loads(cli("lint-urdf", path, "--format", "json").stdout)
    assert not any(f["rule"].startswith("P") for f in static["findings"])
    simulated = cli("lint-urdf", path, "--sim", "--format", "json")
    doc = json.loads(simulated.stdout)  # stdout is JSON alone even though pybullet printed
    rules = [f["rule"] for f in doc["findings"]]
    assert "J001" in rules and "P001" not in rules  # PyBullet refuses it, and J001 already says why, at its line
    unexplained = str(write_urdf(REGISTRY["P001"].bad))  # a <cylinder> without length: no static rule sees it
    (p001,) = [f for f in json.loads(cli("lint-urdf", unexplained, "--sim", "--format", "json").stdout)["findings"]
               if f["rule"] == "P001"]
    assert "has no length attribute" in p001["message"], p001


def test_select_never_hides_a_file_that_cannot_be_loaded(cli, tmp_path):
    junk = tmp_path / "junk.urdf"
    junk.write_bytes(b"\x00\xff not xml")
    selected = cli("lint-urdf", str(junk), "--select", "I", "--format", "json")
    assert selected.code == 1 and [f["rule"] for f in json.loads(selected.stdout)["findings"]] == ["F002"]
    ignored = cli("lint-urdf", str(junk), "--select", "I", "--ignore", "F002", "--format", "json")
    assert ignored.code == 0 and json.loads(ignored.stdout)["findings"] == []


def test_fix_hint_prints_the_command_lines_that_fix_the_findings(cli):
    """Issue 17: each rule names its fixer; --fix-hint turns a file's findings into command lines."""
    broken = "assets/examples/ar3_no_inertia.urdf"  # shown as given, relative to the working folder
    text = cli("lint-urdf", broken, "--fix-hint", "--no-cache")
    assert f"to fix: ar3cli fix-inertia {broken} --density KG_PER_M3  # I001" in text.stdout
    data = json.loads(cli("lint-urdf", broken, "--fix-hint", "--no-cache", "--format", "json").stdout)
    assert data["fix_commands"] == [f"ar3cli fix-inertia {broken} --density KG_PER_M3  # I001"]
    assert {f["fixed_by"] for f in data["findings"]} == {"fix-inertia"}
