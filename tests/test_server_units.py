"""The language server's parts without a client: positions and ranges, the cursor, the open-file store,
a rule that raises, a macro library, and the command without its extra (tests/test_server.py drives
the whole server over stdio)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from tests.conftest import REPO, run_cli

pytest.importorskip("lsprotocol", reason="the server extra is not installed (pip install 'ar3cli[server]')")

from ar3cli.server.cursor import cursor_at, open_elements  # noqa: E402
from ar3cli.server.ranges import LineIndex, finding_span  # noqa: E402

ARM = (REPO / "tests" / "data" / "server" / "arm.urdf").read_text()


def test_positions_count_utf16_units_as_lsp_does_by_default():
    text = 'a\n<link name="é😀x"/>\n'
    utf16, utf8, utf32 = (LineIndex(text, encoding) for encoding in ("utf-16", "utf-8", "utf-32"))
    x = text.index("x")
    assert utf16.position(x) == (1, 15)  # é is one unit, the emoji two
    assert utf8.position(x) == (1, 18)  # é two bytes, the emoji four
    assert utf32.position(x) == (1, 14)
    for index in (utf16, utf8, utf32):
        assert index.offset(*index.position(x)) == x
    assert utf16.offset(5, 0) == len(text) and utf16.offset(1, 999) == text.index("\n", 2)


def test_a_findings_range_is_the_attributes_its_message_names_else_the_start_tag():
    index = LineIndex(ARM)
    line = ARM.splitlines().index('    <limit lower="1.5" upper="-1.5" effort="10" velocity="1"/>') + 1
    start, end = finding_span(index, line, 5, "joint 'shoulder' lower 1.5 > upper -1.5")
    assert ARM[start:end] == 'lower="1.5" upper="-1.5"'
    start, end = finding_span(index, line, 5, "joint 'shoulder' <limit> is a second one")
    assert ARM[start:end] == '<limit lower="1.5" upper="-1.5" effort="10" velocity="1"/>'
    mesh = ARM.splitlines().index('      <geometry><mesh filename="ABSOLUTE/meshes/base.obj"/></geometry>') + 1
    start, end = finding_span(index, mesh, 17, "link 'base_link' mesh ABSOLUTE/meshes/base.obj: file not found")
    assert ARM[start:end] == 'filename="ABSOLUTE/meshes/base.obj"'  # the value quoted, not the attribute named
    start, end = finding_span(index, 2, 0, "a finding on a line")  # no column: the line's text
    assert ARM[start:end] == ARM.splitlines()[1]
    assert finding_span(index, 0, 0, "no line") == (0, len(ARM.splitlines()[0]))


def test_the_cursor_is_read_from_the_buffer_even_half_typed():
    text = '<robot name="r">\n  <joint name="j1" type="rev">\n    <parent link="base"/>\n    <chi'
    at = cursor_at(text, text.index("base") + 2)
    assert (at.kind, at.tag, at.attribute, at.value, at.word) == ("value", "parent", "link", "base", "ba")
    at = cursor_at(text, len(text))
    assert (at.kind, at.tag, at.word) == ("tag", "chi", "chi")
    at = cursor_at(text, text.index('type="rev"'))
    assert at.kind == "attribute" and at.present == {"name", "type"}
    assert cursor_at(text, text.index("\n  <joint")).kind == "text"
    assert open_elements(text, len(text)) == ["robot", "joint"]
    assert open_elements("<robot><link/><!-- <joint> --><joint></joint>", 45) == ["robot"]


def _analysis(tmp_path: Path, name: str, text: str):
    from ar3cli.analysis.robot import RobotAnalysis

    path = tmp_path / name
    path.write_text(text)
    return RobotAnalysis.load(path)


def test_a_rule_that_raises_costs_its_own_findings_only(tmp_path, monkeypatch):
    from ar3cli.lint import engine
    from ar3cli.lint.rules import REGISTRY
    from ar3cli.server.checks import lint_findings

    def broken(context):
        raise ZeroDivisionError("a bug in a rule")
        yield  # a generator, as rules are

    analysis = _analysis(tmp_path, "arm.urdf", ARM)
    expected = {finding.rule for finding in lint_findings(analysis, sim=False)[0]}
    assert {"J003", "J006"} <= expected
    monkeypatch.setattr(engine, "RULES", [dataclasses.replace(rule, check=broken) if rule.code == "J003" else rule
                                          for rule in engine.RULES])
    found, notes = lint_findings(_analysis(tmp_path, "again.urdf", ARM), sim=False)
    assert {finding.rule for finding in found} == expected - {"J003"}
    assert any("internal error in rule J003 (ZeroDivisionError: a bug in a rule)" in note for note in notes), notes
    assert REGISTRY["J003"].check is not broken


def test_a_macro_library_says_nothing_of_its_own(tmp_path):
    from ar3cli.server.checks import Snapshot, check

    text = (REPO / "tests" / "data" / "xacro" / "macros" / "arm_segment.xacro").read_text()
    path = tmp_path / "arm_segment.xacro"
    path.write_text(text)
    checked = check(Snapshot(path.as_uri(), path, 1, text), _analysis(tmp_path, "x.urdf", ARM).settings)
    assert checked.diagnostics == {str(path): []}  # alone it would be S001 and S011: a robot without links
    assert any("macro library" in note for note in checked.notes)


def test_open_files_keep_bounded_analyses_and_closed_ones_are_forgotten(tmp_path):
    from ar3cli.server.checks import Snapshot, check
    from ar3cli.server.documents import KEPT_ANALYSES, Documents

    documents = Documents()
    settings = _analysis(tmp_path, "settings.urdf", ARM).settings
    paths = []
    for number in range(KEPT_ANALYSES + 3):
        path = tmp_path / f"arm{number}.urdf"
        path.write_text(ARM)
        paths.append(path)
        documents.add(path.as_uri(), path)
        for version in range(3):  # a few edits each
            documents.record(check(Snapshot(path.as_uri(), path, version, ARM), settings))
    held = [document for document in documents.open.values() if document.loaded is not None]
    assert len(held) == KEPT_ANALYSES
    assert sum(document.released for document in documents.open.values()) == 3  # made again when a feature asks
    assert all(document.checked.diagnostics for document in documents.open.values())  # diagnostics all stay
    for path in paths:
        changed, _ = documents.remove(path.as_uri())
        assert str(path) in changed  # its diagnostics are withdrawn
    assert not documents.open


def test_enclosing_package_is_the_package_xml_above_the_file(tmp_path):
    from ar3cli.urdf.packages import enclosing_package

    folder = tmp_path / "pkg" / "urdf"
    folder.mkdir(parents=True)
    assert enclosing_package(folder) is None
    (folder.parent / "package.xml").write_text("<package><name>my_robot</name></package>")
    assert enclosing_package(folder) == ("my_robot", folder.parent)


def test_document_splices_are_the_pending_edits_in_file_order():
    from ar3cli.urdf.edits import Document

    document = Document(b'<robot name="r"><link name="a"/><link name="b"/></robot>')
    second, first = document.spans[2], document.spans[1]
    document.set_attribute(second, "name", "c")
    document.set_attribute(first, "name", "d")
    assert [new for _, _, new in document.splices] == [b"d", b"c"]
    assert document.apply() == b'<robot name="r"><link name="d"/><link name="c"/></robot>'


def test_without_the_extra_the_command_says_the_pip_command_in_one_line(tmp_path):
    blocked = tmp_path / "blocked" / "pygls"
    blocked.mkdir(parents=True)
    (blocked / "__init__.py").write_text("raise ModuleNotFoundError(\"No module named 'pygls'\", name='pygls')\n")
    result = run_cli("server", env={"PYTHONPATH": f"{tmp_path / 'blocked'}:{REPO}"})
    assert result.code == 2 and result.stdout == ""
    assert result.stderr.splitlines() == ["ar3cli: error: the language server needs the 'server' extra (pygls is not "
                                          "installed); run: pip install 'ar3cli[server]'"]
