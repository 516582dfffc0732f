"""Findings on a .xacro point at the file and line that wrote the element: the top file, or the
included macro file whose macro produced it (tests/data/xacro/: arm.urdf.xacro includes
macros/arm_segment.xacro)."""

from __future__ import annotations

import io
import json
import shutil
from contextlib import redirect_stderr
from pathlib import Path

from ar3cli.lint.engine import LintOptions, lint_paths
from ar3cli.urdf.model import load_model
from ar3cli.urdf.packages import PackageResolver
from ar3cli.urdf.xacro_expand import ORIGIN_ATTRIBUTE, Origin, expand, origins
from tests.conftest import REPO

DATA = REPO / "tests" / "data" / "xacro"
TOP = DATA / "arm.urdf.xacro"
MACROS = DATA / "macros" / "arm_segment.xacro"


def _line_of(path: Path, text: str, occurrence: int = 1) -> int:
    """1-based line of the ``occurrence``-th line holding ``text`` (so the asserts follow the fixture)."""
    found = [number for number, line in enumerate(path.read_text().splitlines(), 1) if text in line]
    return found[occurrence - 1]


def _findings(cli, *args: str, cwd: Path | None = None) -> list[dict]:
    result = cli("lint-urdf", "--no-cache", "--format", "json", *args, cwd=cwd)
    assert result.code in (0, 1), result.stderr
    return json.loads(result.stdout)["findings"]


def test_a_defect_inside_a_macro_points_at_the_macro_file(cli):
    findings = _findings(cli, str(TOP.relative_to(REPO)))
    by_message = {(f["rule"], f["message"].split("'")[1]): f for f in findings}
    joint_line = _line_of(MACROS, '<joint name="${name}_joint"')
    for joint in ("shoulder_joint", "elbow_joint"):  # both calls of the macro: the macro's line
        finding = by_message["J001", joint]
        assert (finding["path"], finding["line"], finding["column"]) == (
            "tests/data/xacro/macros/arm_segment.xacro", joint_line, 5)
    tool = by_message["I002", "tool0"]
    assert (tool["path"], tool["line"], tool["column"]) == (
        "tests/data/xacro/macros/arm_segment.xacro", _line_of(MACROS, '<link name="tool0"/>'), 5)


def test_a_defect_in_the_top_file_points_at_the_top_file(cli):
    (wrist,) = [f for f in _findings(cli, str(TOP.relative_to(REPO))) if f["rule"] == "I001"]
    assert (wrist["path"], wrist["line"], wrist["column"]) == (
        "tests/data/xacro/arm.urdf.xacro", _line_of(TOP, '<link name="wrist_link"/>'), 3)


def test_no_finding_is_left_without_a_location(cli):
    findings = _findings(cli, str(TOP.relative_to(REPO)))
    assert len(findings) == 4 and all(f["line"] > 0 and f["column"] > 0 for f in findings)


def test_paths_follow_how_the_top_file_was_named(cli, tmp_path):
    shutil.copytree(DATA, tmp_path / "xacro")
    absolute = {f["path"] for f in _findings(cli, str(tmp_path / "xacro" / "arm.urdf.xacro"))}
    assert absolute == {str(tmp_path / "xacro" / "arm.urdf.xacro"), str(tmp_path / "xacro" / "macros" / "arm_segment.xacro")}
    from_below = {f["path"] for f in _findings(cli, "../arm.urdf.xacro", cwd=tmp_path / "xacro" / "macros")}
    assert from_below == {"../arm.urdf.xacro", "../macros/arm_segment.xacro"}
    text = cli("lint-urdf", "--no-cache", "xacro/arm.urdf.xacro", cwd=tmp_path).stdout
    tool_line = _line_of(MACROS, '<link name="tool0"/>')
    assert f"\nxacro/macros/arm_segment.xacro:{tool_line}:5: " in text  # piped: path:line:col: CODE, a line each


def test_per_file_ignores_apply_to_the_included_file(cli, tmp_path):
    shutil.copytree(DATA, tmp_path / "xacro")
    (tmp_path / "pyproject.toml").write_text('[tool.ar3cli.lint.per-file-ignores]\n"xacro/macros/*.xacro" = ["J001"]\n')
    rules = sorted(f["rule"] for f in _findings(cli, "xacro/arm.urdf.xacro", cwd=tmp_path))
    assert rules == ["I001", "I002"]


def test_parallel_workers_locate_the_same(cli, tmp_path):
    for index in range(3):
        shutil.copytree(DATA, tmp_path / f"copy{index}")
    one = _findings(cli, str(tmp_path), "--jobs", "1")
    three = _findings(cli, str(tmp_path), "--jobs", "3")
    assert one == three and any(f["path"].endswith("macros/arm_segment.xacro") and f["line"] for f in one)


def test_expansion_is_what_xacro_writes_and_carries_no_marks():
    import xacro

    with redirect_stderr(io.StringIO()):
        reference = xacro.process_file(str(TOP)).toprettyxml(indent="  ").encode()
    expanded = expand(TOP, {}, PackageResolver(DATA, {}))
    assert expanded == reference and ORIGIN_ATTRIBUTE.encode() not in expanded
    model = load_model(TOP)  # the Model (fixers, the sim copy) never sees the marks
    assert not any(ORIGIN_ATTRIBUTE in element.attrib for element in model.root.iter() if isinstance(element.tag, str))


def test_origins_follow_macros_blocks_and_includes():
    expanded = expand(TOP, {}, PackageResolver(DATA, {}))
    found = origins(expanded)
    from ar3cli.urdf.xmlsource import parse

    root, _ = parse(expanded, TOP)
    elements = [element for element in root.iter() if isinstance(element.tag, str)]
    assert found is not None and len(found) == len(elements) and None not in found
    where = dict(zip(elements, found))
    shoulder = root.find("joint[@name='shoulder_joint']")
    assert where[shoulder] == Origin(str(MACROS), _line_of(MACROS, '<joint name="${name}_joint"'), 5)
    block = shoulder.find("origin")  # the block passed to the macro: the call site in the top file
    assert where[block] == Origin(str(TOP), _line_of(TOP, '<origin xyz="0 0 0.1"/>'), 5)
    assert where[root.find("link[@name='wrist_link']")].line == _line_of(TOP, '<link name="wrist_link"/>')
    assert origins(b"<robot/>") is None


def test_lint_api_gives_the_macro_file(monkeypatch):
    monkeypatch.chdir(REPO)
    (result,) = lint_paths([TOP.relative_to(REPO)], LintOptions(), use_cache=False, jobs=1)
    assert result.path == "tests/data/xacro/arm.urdf.xacro"  # the file linted, whatever its findings name
    assert [f.path for f in result.findings] == ["tests/data/xacro/arm.urdf.xacro",
                                                 *["tests/data/xacro/macros/arm_segment.xacro"] * 3]
