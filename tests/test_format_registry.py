"""The output format registry (ar3cli/output/formats/): it lists every format, each command's
``--format`` choices and help come from it, and a format registered later (one module, or a test's
dummy) is offered by every command whose report it renders, with no edit to a command."""

from __future__ import annotations

import os
import pkgutil
import subprocess
import sys
import textwrap

import pytest

from ar3cli.output import formats
from ar3cli.output.formats import ANNOTATIONS, LINT, MARKDOWN, REPORT, Format
from ar3cli.output.report import OutputFormat, Report
from tests.conftest import REPO

BUILT_IN = ["text", "json", "sarif", "github", "markdown", "junit", "html"]
COMMAND_KINDS = {"lint-urdf": (LINT,), "diff": (ANNOTATIONS, MARKDOWN, REPORT), "scan-report": (MARKDOWN, REPORT)}
"""The kinds of each command's report; every other command's is a plain Report."""
ROBOT = REPO / "tests" / "data" / "joints" / "floating_hand.urdf"


def format_parameters():
    """(command name, its --format click parameter) of every command that has one."""
    import typer

    from ar3cli.cli import application

    group = typer.main.get_command(application([]))
    for name, command in group.commands.items():  # type: ignore[attr-defined]
        for parameter in command.params:
            if "--format" in getattr(parameter, "opts", ()):
                yield name, parameter


def test_the_registry_lists_every_format_module_in_help_order():
    modules = {module.name for module in pkgutil.iter_modules(formats.__path__)}
    assert formats.names() == BUILT_IN
    assert modules == set(BUILT_IN)  # one module per format
    assert formats.names((REPORT,)) == ["text", "json"]
    assert formats.names((LINT,)) == BUILT_IN
    for fmt in formats.formats():
        assert fmt.help and fmt.kinds and OutputFormat(fmt.stream)


def test_every_command_offers_the_formats_that_render_its_report():
    seen = set()
    for name, parameter in format_parameters():
        kinds = COMMAND_KINDS.get(name, (REPORT,))
        assert list(parameter.type.choices) == formats.names(kinds), name
        assert parameter.help == formats.help_text(kinds), name
        assert str(getattr(parameter.default, "value", parameter.default)) == "text", name
        seen.add(name)
    assert {"lint-urdf", "diff", "scan-report", "info", "fix-inertia", "report"} <= seen
    assert formats.names(COMMAND_KINDS["diff"]) == ["text", "json", "github", "markdown"]


@pytest.fixture
def dummy():
    """A format registered for the test only: plain reports and lint findings, one line each."""
    def plain(report: Report) -> Report:
        return Report(data={}, text=f"dummy: {sorted(report.data)}\n")

    def lint(report) -> Report:
        return Report(data={}, text=f"dummy: {len(report.findings)} findings\n", ok=report.ok)

    yield formats.register(Format("dummy", "a test's format", {REPORT: plain, LINT: lint}, order=1000))
    formats.unregister("dummy")


def test_a_registered_format_is_listed_and_dispatched_to(dummy):
    assert formats.names((REPORT,)) == ["text", "json", "dummy"]
    assert formats.names((LINT,))[-1] == "dummy"
    assert "dummy (a test's format)" in formats.help_text((REPORT,))
    assert [member.value for member in formats.choices((REPORT,), "Test")] == ["text", "json", "dummy"]
    report, stream = formats.render(Report(data={"b": 1, "a": 2}), (REPORT,), "dummy")
    assert (report.text, stream) == ("dummy: ['a', 'b']\n", OutputFormat.text)
    with pytest.raises(ValueError, match="does not render"):
        formats.render(Report(data={}), (REPORT,), "sarif")
    with pytest.raises(ValueError, match="unknown output format"):
        formats.get("nope")
    with pytest.raises(ValueError):
        formats.register(Format("bad", "no such stream", {REPORT: lambda report: report}, stream="yaml"))  # type: ignore[arg-type]
    assert "bad" not in formats.names()


DUMMY_RUN = textwrap.dedent("""
    import sys
    from ar3cli.output.formats import LINT, REPORT, Format, register
    from ar3cli.output.report import Report
    register(Format("dummy", "a test's format",
                    {REPORT: lambda r: Report(data={}, text="dummy report\\n"),
                     LINT: lambda r: Report(data={}, text=f"dummy lint: {len(r.findings)}\\n", ok=r.ok)}))
    from ar3cli.cli import main
    main(sys.argv[1:])
""")


def run_with_dummy(*args: str) -> subprocess.CompletedProcess:
    """The CLI in a fresh process that registered a dummy format before any command was imported."""
    return subprocess.run([sys.executable, "-c", DUMMY_RUN, *args], cwd=REPO, capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(REPO), "NO_COLOR": "1", "AR3CLI_NO_CACHE": "1"},
                          timeout=300, stdin=subprocess.DEVNULL)


def test_commands_offer_and_use_a_format_registered_before_they_load():
    info = run_with_dummy("info", str(ROBOT), "--format", "dummy")
    assert (info.returncode, info.stdout) == (0, "dummy report\n"), info.stderr
    lint = run_with_dummy("lint-urdf", str(ROBOT), "-f", "dummy")
    assert lint.stdout.startswith("dummy lint: ") and lint.returncode in (0, 1), lint.stderr
    helped = run_with_dummy("lint-urdf", "--help")
    assert "dummy" in helped.stdout and "test's format" in helped.stdout
