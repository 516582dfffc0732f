"""``ar3cli server`` end to end: pytest-lsp drives one real server process over stdio, as an editor does.

The workspace (a temporary folder) holds the fixture arm of tests/data/server (an absolute mesh path,
inverted limits, a continuous joint with fake limits, a package.xml), the xacro arm of tests/data/xacro
(a macro file it includes), and a pyproject.toml whose configuration the server must apply. What the
server says is compared with what the command line says on the same files: lint-urdf's findings,
``--explain``'s text, and the bytes the fixers write.
"""

from __future__ import annotations

import asyncio
import json
import os
import shutil
import sys
from pathlib import Path

import pytest

pytest.importorskip("pygls", reason="the server extra is not installed (pip install 'ar3cli[server]')")
pytest_lsp = pytest.importorskip("pytest_lsp", reason="pytest-lsp is not installed (pip install 'ar3cli[test]')")

from lsprotocol import types  # noqa: E402
from pytest_lsp import ClientServerConfig, LanguageClient, client_capabilities  # noqa: E402

from tests.conftest import REPO, run_cli  # noqa: E402

DATA = REPO / "tests" / "data"
PYPROJECT = """[tool.ar3cli.lint]
ignore = ["P003"]
[tool.ar3cli.lint.severity]
J006 = "info"
"""
"""The workspace's configuration: J006 reported as info, P003 (mass properties, with --sim) ignored."""
TIMEOUT = 60


@pytest.fixture(scope="module")
def workspace(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("server-workspace")
    shutil.copytree(DATA / "server", root / "arm")
    urdf = root / "arm" / "arm.urdf"
    urdf.write_text(urdf.read_text().replace("ABSOLUTE/", (root / "arm").as_posix() + "/"))
    shutil.copytree(DATA / "xacro", root / "xacro")
    (root / "pyproject.toml").write_text(PYPROJECT)
    return root


@pytest_lsp.fixture(scope="module", config=ClientServerConfig(
    server_command=[sys.executable, "-m", "ar3cli", "server"],
    server_env={**os.environ, "PYTHONPATH": str(REPO)}))
async def client(lsp_client: LanguageClient, workspace: Path):
    @lsp_client.feature(types.CLIENT_REGISTER_CAPABILITY)
    def register(params: types.RegistrationParams) -> None:  # VS Code accepts the server's file watchers
        lsp_client.registrations = [*getattr(lsp_client, "registrations", []), *params.registrations]

    await lsp_client.initialize_session(types.InitializeParams(
        capabilities=client_capabilities("visual-studio-code"), root_uri=workspace.as_uri(),
        workspace_folders=[types.WorkspaceFolder(workspace.as_uri(), "workspace")]))
    yield
    await lsp_client.shutdown_session()


# ---- helpers ---------------------------------------------------------------------------------------
def open_file(client: LanguageClient, path: Path, text: str | None = None) -> str:
    uri = path.as_uri()
    client.text_document_did_open(types.DidOpenTextDocumentParams(types.TextDocumentItem(
        uri, "xml", 1, path.read_text() if text is None else text)))
    return uri


def replace_all(client: LanguageClient, uri: str, text: str, version: int) -> None:
    client.text_document_did_change(types.DidChangeTextDocumentParams(
        types.VersionedTextDocumentIdentifier(version, uri), [types.TextDocumentContentChangeWholeDocument(text)]))


async def diagnostics(client: LanguageClient, uri: str, until=lambda found: True) -> list[types.Diagnostic]:
    """The diagnostics published for ``uri`` once ``until(them)`` holds (polled: notifications may come first)."""
    deadline = asyncio.get_running_loop().time() + TIMEOUT
    while True:
        found = client.diagnostics.get(uri)
        if found is not None and until(found):
            return list(found)
        if asyncio.get_running_loop().time() > deadline:
            raise AssertionError(f"no diagnostics as expected for {uri} after {TIMEOUT} s: {found}")
        await asyncio.sleep(0.05)


def codes(found: list[types.Diagnostic]) -> set[str]:
    return {str(item.code) for item in found}


def text_in(text: str, item: types.Range) -> str:
    lines = text.splitlines(keepends=True)
    start = sum(len(line) for line in lines[:item.start.line]) + item.start.character
    end = sum(len(line) for line in lines[:item.end.line]) + item.end.character
    return text[start:end]


def apply_edits(text: str, edits: list[types.TextEdit]) -> str:
    """What an editor does with a WorkspaceEdit's text edits (ASCII text: characters are UTF-16 units)."""
    lines = text.splitlines(keepends=True)

    def offset(position: types.Position) -> int:
        return sum(len(line) for line in lines[:position.line]) + position.character

    for edit in sorted(edits, key=lambda edit: offset(edit.range.start), reverse=True):
        text = text[:offset(edit.range.start)] + edit.new_text + text[offset(edit.range.end):]
    return text


async def actions_for(client: LanguageClient, uri: str, item: types.Diagnostic) -> list[types.CodeAction]:
    found = await client.text_document_code_action_async(types.CodeActionParams(
        types.TextDocumentIdentifier(uri), item.range, types.CodeActionContext([item])))
    return [action for action in found or [] if isinstance(action, types.CodeAction)]


# ---- a URDF ----------------------------------------------------------------------------------------
@pytest.mark.asyncio(loop_scope="module")
async def test_open_publishes_lint_urdfs_findings_with_the_workspace_configuration(client: LanguageClient,
                                                                                   workspace: Path):
    path = workspace / "arm" / "arm.urdf"
    found = await diagnostics(client, open_file(client, path), lambda found: len(found) >= 3)
    cli = run_cli("lint-urdf", "arm/arm.urdf", "--format", "json", "--no-cache", cwd=workspace)
    expected = {(finding["rule"], finding["line"] - 1, finding["severity"]) for finding in json.loads(cli.stdout)["findings"]}
    severity = {types.DiagnosticSeverity.Error: "error", types.DiagnosticSeverity.Warning: "warning",
                types.DiagnosticSeverity.Information: "info"}
    assert {(str(item.code), item.range.start.line, severity[item.severity]) for item in found} == expected
    assert ("J006", 47, "info") in expected  # [tool.ar3cli.lint.severity] applied by both
    by_code = {str(item.code): item for item in found}
    text = path.read_text()
    assert text_in(text, by_code["J003"].range) == 'lower="1.5" upper="-1.5"'  # the attributes the message names
    assert text_in(text, by_code["G003"].range).startswith('filename="/') and by_code["G003"].range.start.line == 9
    assert by_code["J003"].code_description.href.endswith("docs/rules.md#j003-limit-inverted")
    assert by_code["J003"].source == "ar3cli" and "Swap lower and upper." in by_code["J003"].message


@pytest.mark.asyncio(loop_scope="module")
async def test_hover_shows_the_rules_explanation_and_a_links_facts(client: LanguageClient, workspace: Path):
    uri = (workspace / "arm" / "arm.urdf").as_uri()
    j003 = next(item for item in await diagnostics(client, uri, lambda found: "J003" in codes(found))
                if item.code == "J003")
    shown = await client.text_document_hover_async(types.HoverParams(types.TextDocumentIdentifier(uri),
                                                                      j003.range.start))
    assert shown.contents.value == run_cli("lint-urdf", "--explain", "J003").stdout.rstrip("\n")
    line = next(number for number, text in enumerate((workspace / "arm" / "arm.urdf").read_text().splitlines())
                if '<child link="upper_arm"/>' in text)
    facts = await client.text_document_hover_async(types.HoverParams(types.TextDocumentIdentifier(uri),
                                                                     types.Position(line, 22)))
    assert facts.contents.value.splitlines()[:2] == ["link upper_arm: 1 kg", "parent: base_link via shoulder: revolute, "
                                                     "axis 0 0 1, 1.5 .. -1.5 rad"]


@pytest.mark.asyncio(loop_scope="module")
async def test_code_actions_write_what_the_fixers_write(client: LanguageClient, workspace: Path, tmp_path: Path):
    path = workspace / "arm" / "arm.urdf"
    uri, text = path.as_uri(), path.read_text()
    found = {str(item.code): item for item in await diagnostics(client, uri, lambda found: len(found) >= 3)}
    for code, command in (("J003", ["fix-joints"]), ("J006", ["fix-continuous"]),
                          ("G003", ["fix-mesh-paths", "--package", f"server_arm={path.parent}"])):
        action = next(action for action in await actions_for(client, uri, found[code])
                      if action.title.startswith(command[0]))
        copy = tmp_path / code / "arm.urdf"
        shutil.copytree(path.parent, copy.parent)
        result = run_cli(*command, str(copy), "--no-verify")
        assert result.code == 0, result.stderr
        assert apply_edits(text, action.edit.changes[uri]) == copy.read_text(), code
    ignore = next(action for action in await actions_for(client, uri, found["J003"])
                  if action.title.startswith("Ignore J003"))
    ignored = apply_edits(text, ignore.edit.changes[uri])
    assert "<!-- ar3cli: ignore[J003] -->" in ignored.splitlines()[26]  # the first child of <joint name="shoulder">
    replace_all(client, uri, ignored, 2)
    assert "J003" not in codes(await diagnostics(client, uri, lambda found: "J003" not in codes(found)))
    replace_all(client, uri, text, 3)
    await diagnostics(client, uri, lambda found: "J003" in codes(found))


@pytest.mark.asyncio(loop_scope="module")
async def test_editing_changes_the_diagnostics_and_a_broken_buffer_is_one_finding(client: LanguageClient,
                                                                                  workspace: Path):
    path = workspace / "arm" / "arm.urdf"
    uri, text = path.as_uri(), path.read_text()
    limit = '    <limit lower="1.5" upper="-1.5" effort="10" velocity="1"/>'
    line, start = text.splitlines().index(limit), limit.index("lower")
    client.text_document_did_change(types.DidChangeTextDocumentParams(  # an incremental change, as editors send
        types.VersionedTextDocumentIdentifier(10, uri), [types.TextDocumentContentChangePartial(
            types.Range(types.Position(line, start), types.Position(line, start + 24)), 'lower="-1.5" upper="1.5"')]))
    assert codes(await diagnostics(client, uri, lambda found: "J003" not in codes(found))) == {"G003", "J006"}
    replace_all(client, uri, text.replace("</robot>", "</robt>"), 11)
    broken = await diagnostics(client, uri, lambda found: codes(found) & {"F002"})
    assert [str(item.code) for item in broken] == ["F002"]
    symbols = await client.text_document_document_symbol_async(types.DocumentSymbolParams(
        types.TextDocumentIdentifier(uri)))
    assert symbols is not None  # the server still answers (from the last buffer that loaded)
    replace_all(client, uri, text, 12)
    await diagnostics(client, uri, lambda found: "J003" in codes(found))


@pytest.mark.asyncio(loop_scope="module")
async def test_outline_and_completion(client: LanguageClient, workspace: Path):
    path = workspace / "arm" / "arm.urdf"
    uri, text = path.as_uri(), path.read_text()
    await diagnostics(client, uri, lambda found: "J003" in codes(found))
    outline = await client.text_document_document_symbol_async(types.DocumentSymbolParams(
        types.TextDocumentIdentifier(uri)))

    def tree(symbol) -> list:
        return [symbol.name, [tree(child) for child in symbol.children or []]]

    assert [tree(symbol) for symbol in outline] == [
        ["base_link", [["shoulder", [["upper_arm", [["elbow", [["forearm", []]]]]]]]]]]
    line = text.splitlines().index('    <child link="upper_arm"/>')
    links = await client.text_document_completion_async(types.CompletionParams(
        types.TextDocumentIdentifier(uri), types.Position(line, 18)))
    assert [item.label for item in links.items] == ["base_link", "upper_arm", "forearm"]
    line = text.splitlines().index("    <inertial>")
    children = await client.text_document_completion_async(types.CompletionParams(
        types.TextDocumentIdentifier(uri), types.Position(line, 5)))
    assert [item.label for item in children.items] == ["collision", "inertial", "visual"]


# ---- xacro -----------------------------------------------------------------------------------------
@pytest.mark.asyncio(loop_scope="module")
async def test_xacro_findings_land_on_the_included_file_and_its_change_rechecks_the_includer(
        client: LanguageClient, workspace: Path):
    top, macros = workspace / "xacro" / "arm.urdf.xacro", workspace / "xacro" / "macros" / "arm_segment.xacro"
    top_uri = open_file(client, top)
    own = await diagnostics(client, top_uri, lambda found: "I001" in codes(found))
    assert [(str(item.code), item.range.start.line) for item in own] == [("I001", 19)]  # the top file's line 20
    included = await diagnostics(client, macros.as_uri(), lambda found: "J001" in codes(found))
    assert sorted((str(item.code), item.range.start.line) for item in included) == [
        ("I002", 19), ("J001", 10), ("J001", 10)]  # J001 twice: the macro made shoulder_joint and elbow_joint
    macros_uri = open_file(client, macros)  # a macro file, opened: checked through the file including it
    await asyncio.sleep(0.5)
    assert sorted(str(item.code) for item in client.diagnostics[macros_uri]) == ["I002", "J001", "J001"]
    fixed = macros.read_text().replace('      <axis xyz="0 0 1"/>\n',
                                       '      <axis xyz="0 0 1"/>\n      <limit lower="-1" upper="1" effort="1" '
                                       'velocity="1"/>\n')
    replace_all(client, macros_uri, fixed, 2)
    macros.write_text(fixed)
    client.text_document_did_save(types.DidSaveTextDocumentParams(types.TextDocumentIdentifier(macros_uri)))
    assert codes(await diagnostics(client, macros_uri, lambda found: "J001" not in codes(found))) == {"I002"}


@pytest.mark.asyncio(loop_scope="module")
async def test_go_to_definition_in_xacro(client: LanguageClient, workspace: Path):
    top, macros = workspace / "xacro" / "arm.urdf.xacro", workspace / "xacro" / "macros" / "arm_segment.xacro"
    uri, lines = top.as_uri(), top.read_text().splitlines()

    async def go(line_text: str, column: int) -> tuple[str, int]:
        line = next(number for number, text in enumerate(lines) if line_text in text)
        found = await client.text_document_definition_async(types.DefinitionParams(
            types.TextDocumentIdentifier(uri), types.Position(line, column)))
        return found[0].uri, found[0].range.start.line

    assert await go('<xacro:arm_segment name="shoulder"', 10) == (macros.as_uri(), 3)  # the macro
    assert await go('<xacro:include filename=', 30) == (macros.as_uri(), 0)  # the included file
    assert await go('<parent link="elbow_link"/>', 20) == (macros.as_uri(), 4)  # a link the macro wrote
    assert await go('<child link="wrist_link"/>', 19) == (uri, 19)  # a link written in the file itself


# ---- the PyBullet rules on save --------------------------------------------------------------------
@pytest.mark.asyncio(loop_scope="module")
async def test_sim_setting_adds_the_pybullet_rules_on_save(client: LanguageClient, workspace: Path):
    path = workspace / "arm" / "arm.urdf"
    uri = path.as_uri()
    await diagnostics(client, uri, lambda found: "J003" in codes(found))
    assert not {code for code in codes(client.diagnostics[uri]) if code.startswith("P")}
    client.workspace_did_change_configuration(types.DidChangeConfigurationParams({"ar3cli": {"sim": True}}))
    client.text_document_did_save(types.DidSaveTextDocumentParams(types.TextDocumentIdentifier(uri)))
    found = await diagnostics(client, uri, lambda found: "P005" in codes(found))
    assert "P003" not in codes(found)  # ignored by the workspace's configuration, as lint-urdf --sim does
    client.workspace_did_change_configuration(types.DidChangeConfigurationParams({"ar3cli": {"sim": False}}))


@pytest.mark.asyncio(loop_scope="module")
async def test_hostile_names_reach_the_editor_as_plain_text(client: LanguageClient, workspace: Path):
    """The output boundary (issue 34) for the editor: a robot whose link and joint names hold a newline
    with a workflow command, ESC, C1, a bidi override and Markdown gets diagnostics, hovers and an
    outline that carry none of those characters raw, and hovers are plain text (no Markdown to render)."""
    from tests.test_output_boundary import RAW, robot

    path = workspace / "hostile.urdf"
    path.write_text(robot())
    uri = open_file(client, path)
    found = await diagnostics(client, uri, lambda found: "J008" in codes(found))
    outline = await client.text_document_document_symbol_async(types.DocumentSymbolParams(
        types.TextDocumentIdentifier(uri)))
    names = []
    stack = list(outline or [])
    while stack:
        symbol = stack.pop()
        names.append(symbol.name)
        stack += symbol.children or []
    line = next(number for number, text in enumerate(path.read_text().splitlines()) if "<child link=" in text)
    hover = await client.text_document_hover_async(types.HoverParams(types.TextDocumentIdentifier(uri),
                                                                     types.Position(line, 60)))
    shown = [item.message for item in found] + names + ([hover.contents.value] if hover else [])
    assert hover is None or hover.contents.kind == types.MarkupKind.PlainText
    assert len(names) >= 3 and any("::error file=x::" in name for name in names)  # the names are there, escaped
    for text in shown:
        assert not any(character in text for character in RAW), repr(text)


@pytest.mark.asyncio(loop_scope="module")
async def test_keystrokes_in_a_value_give_what_lint_urdf_and_the_fixers_give_on_the_typed_text(
        client: LanguageClient, workspace: Path):
    """One character at a time, as an editor sends them: the server checks each as an edit of the last
    buffer (the model patched, the earlier check's work reused) and must say what a fresh lint-urdf says."""
    path = workspace / "arm" / "arm.urdf"
    uri, text = path.as_uri(), path.read_text()
    await diagnostics(client, uri, lambda found: "J003" in codes(found))
    line = text.splitlines().index('    <limit lower="1.5" upper="-1.5" effort="10" velocity="1"/>')
    column = text.splitlines()[line].index('"-1.5"') + 1
    typed = text
    for version, (start, end, new) in enumerate([(column, column + 1, ""), (column + 3, column + 3, "9")], 20):
        client.text_document_did_change(types.DidChangeTextDocumentParams(
            types.VersionedTextDocumentIdentifier(version, uri), [types.TextDocumentContentChangePartial(
                types.Range(types.Position(line, start), types.Position(line, end)), new)]))
        lines = typed.splitlines(keepends=True)
        lines[line] = lines[line][:start] + new + lines[line][end:]
        typed = "".join(lines)
    assert 'upper="1.59"' in typed
    found = await diagnostics(client, uri, lambda found: not codes(found) & {"J003", "J004"})
    copy = path.parent / "typed.urdf"
    copy.write_text(typed)
    try:
        cli = json.loads(run_cli("lint-urdf", "arm/typed.urdf", "--format", "json", "--no-cache", cwd=workspace).stdout)
        assert {(str(item.code), item.range.start.line, item.message.split("\n")[0]) for item in found} == \
            {(finding["rule"], finding["line"] - 1, finding["message"]) for finding in cli["findings"]}
        action = next(action for action in await actions_for(client, uri, next(item for item in found if item.code == "J006"))
                      if action.title.startswith("fix-continuous"))
        assert run_cli("fix-continuous", str(copy), "--no-verify").code == 0
        assert apply_edits(typed, action.edit.changes[uri]) == copy.read_text()
    finally:
        copy.unlink()
    replace_all(client, uri, text, 30)
    await diagnostics(client, uri, lambda found: "J003" in codes(found))
