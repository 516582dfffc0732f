"""``ar3cli lint-urdf``: static (and optionally simulated) checks of URDF / xacro files."""

import enum
from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.commands.options import PackagePathOption, XacroArgOption
from ar3cli.errors import UserError
from ar3cli.output.report import Report, Table, finish


class LintFormat(str, enum.Enum):
    """Output formats of lint-urdf (the common text/json plus CI formats)."""

    text = "text"
    json = "json"
    sarif = "sarif"
    github = "github"
    markdown = "markdown"


class FailOn(str, enum.Enum):
    error = "error"
    warning = "warning"
    info = "info"


def lint_urdf(
    paths: Annotated[list[Path], typer.Argument(
        metavar="PATH", help="URDF/xacro files, or folders searched for *.urdf and *.xacro.", show_default=False)],
    format: Annotated[LintFormat, typer.Option("--format", "-f", help="text (table), json, sarif (SARIF 2.1.0), "
                                                                      "github (workflow annotations) or markdown.")]
    = LintFormat.text,
    select: Annotated[Optional[list[str]], typer.Option("--select", metavar="CODES",
                                                        help="Only these rule codes or prefixes (comma-separated, "
                                                             "repeatable; overrides the config's select).")] = None,
    ignore: Annotated[Optional[list[str]], typer.Option("--ignore", metavar="CODES",
                                                        help="Skip these rule codes or prefixes (added to the "
                                                             "config's ignore).")] = None,
    fail_on: Annotated[Optional[FailOn], typer.Option("--fail-on", help="Exit 1 when a finding is at least this "
                                                                        "severe (default: error, or the config's fail-on).",
                                                      show_default=False)] = None,
    exit_zero: Annotated[bool, typer.Option("--exit-zero", help="Exit 0 even when there are findings.")] = False,
    sim: Annotated[bool, typer.Option("--sim", help="Also load each model in PyBullet (P rules): load errors, "
                                                    "self-collision at home, inertia PyBullet really uses, stability.")]
    = False,
    no_config: Annotated[bool, typer.Option("--no-config", help="Ignore \\[tool.ar3cli.lint] in pyproject.toml.")]
    = False,
    jobs: Annotated[Optional[int], typer.Option("--jobs", "-j", min=1, show_default=False,
                                                help="Processes that share the files, at most one per CPU. "
                                                     "Default on Linux: one per 24 files (per 2 with --sim), "
                                                     "at most 8; elsewhere 1. The output is the same for any "
                                                     "value.")]
    = None,
    no_cache: Annotated[bool, typer.Option("--no-cache", help="Check every file again instead of reusing the "
                                                              "findings of unchanged files from earlier runs "
                                                              "(also AR3CLI_NO_CACHE=1).")] = False,
    group: Annotated[Optional[bool], typer.Option("--group/--no-group",
                                                  help="Text format: show 5 or more alike findings of one rule in "
                                                       "one file as one row (count, first locations, message); on "
                                                       "by default. JSON, SARIF, github and markdown keep every "
                                                       "finding.", show_default=False)] = None,
    package_path: PackagePathOption = None,
    xacro_arg: XacroArgOption = None,
) -> None:
    """Check URDF and xacro files for mistakes that break ROS tools or make PyBullet misbehave.

    Every finding has a stable rule code, a severity, a location and a fix; see docs/rules.md.
    Exit codes: 0 clean, 1 findings at or above --fail-on, 2 usage or I/O error.
    """
    from ar3cli.findings import Severity
    from ar3cli.lint.config import LintConfig, load_config
    from ar3cli.lint.engine import LintOptions, lint_paths, summarize
    from ar3cli.lint.rules import validate_patterns
    from ar3cli.urdf.packages import parse_package_paths
    from ar3cli.urdf.xacro_expand import parse_xacro_args

    config = LintConfig() if no_config else load_config()
    try:
        options = LintOptions(
            select=(validate_patterns(_split(select), "--select") if select else config.select) or ["ALL"],
            ignore=[*config.ignore, *validate_patterns(_split(ignore), "--ignore")],
            per_file_ignores=config.per_file_ignores, severity=config.severity, sim=sim,
            package_paths=parse_package_paths(package_path), xacro_args=parse_xacro_args(xacro_arg))
    except ValueError as exc:
        raise UserError(str(exc)) from None
    threshold = Severity(fail_on.value) if fail_on else (config.fail_on or Severity.ERROR)
    results = lint_paths(paths, options, use_cache=not no_cache, jobs=jobs)
    if not results:
        raise UserError(f"no .urdf or .xacro files found in {', '.join(str(p) for p in paths)}")
    summary = summarize(results, threshold)
    grouped = True if group is None else group
    report = render_lint(results, summary, options, LintFormat(format), grouped=grouped)
    report.ok = report.ok or exit_zero
    report.errors = [*report.errors, *(result.error for result in results if result.error)]
    finish(report, "json" if LintFormat(format) in (LintFormat.json, LintFormat.sarif) else "text")


def _split(items: list[str] | None) -> list[str]:
    return [part for item in items or [] for part in item.split(",")]


def summary_line(summary: dict, cached: int = 0) -> str:
    """The verdict line; ``cached`` files answered from the result cache are said when there are any."""
    files = summary["files"]
    broken = summary["files_with_errors"]
    clean = summary["files_clean"]
    verdict = "FAILED" if summary["failed"] or broken else "passed"
    unchecked = f"; {broken} not fully checked (pybullet crashed)" if broken else ""
    remembered = f"; {cached} unchanged since an earlier run (from the cache)" if cached else ""
    return (f"{verdict}: {files} file{'s' if files != 1 else ''} checked, {summary['error']} errors, "
            f"{summary['warning']} warnings, {summary['info']} info; {clean} clean{unchecked}{remembered} "
            f"(fail-on: {summary['fail_on']})")


def render_lint(results, summary: dict, options, fmt: LintFormat, grouped: bool = False) -> Report:
    """The lint Report in ``fmt``: text and json tables, SARIF as the JSON document, github
    annotations and markdown as verbatim stdout text (github also appends the Markdown table to
    ``$GITHUB_STEP_SUMMARY`` when set). ``grouped`` folds alike findings into one text row
    (:func:`~ar3cli.lint.engine.group_findings`); every other format keeps every finding."""
    findings = [f for result in results for f in result.findings]
    data = {"files": [r.to_dict() for r in results], "findings": [f.to_dict() for f in findings], "summary": summary}
    ok = not summary["failed"]
    if fmt is LintFormat.sarif:
        from ar3cli.output.sarif import sarif_document

        return Report(data=sarif_document(findings, options.rules()), ok=ok)
    if fmt in (LintFormat.github, LintFormat.markdown):
        from ar3cli.output.github import annotation, append_step_summary, markdown_table

        table = markdown_table(findings, summary_line(summary))
        if fmt is LintFormat.markdown:
            return Report(data=data, text=table, ok=ok)
        error = append_step_summary(table)  # GitHub Actions: the reviewer sees it on the run's summary page
        annotations = "".join(annotation(finding) + "\n" for finding in findings)
        return Report(data=data, text=annotations + summary_line(summary) + "\n", ok=ok, errors=[error] if error else [])
    tables = [Table(title=result.path, columns=["location", "code", "severity", "message", "hint"],
                    rows=_rows(result.findings, grouped), status_column="severity", nowrap_columns=("location",))
              for result in results if result.findings]
    return Report(data=data, tables=tables, lines=[summary_line(summary, sum(r.cached for r in results))], ok=ok)


def _rows(findings, grouped: bool) -> list[list]:
    """Table rows: one per finding, or per group of alike findings when ``grouped``."""
    if not grouped:
        return [[f.location, f.rule, f.severity.value, f.message, f.hint] for f in findings]
    from ar3cli.lint.engine import FindingGroup, group_findings

    rows = []
    for row in group_findings(findings):
        if isinstance(row, FindingGroup):
            first = row.first
            rows.append([first.location, first.rule, first.severity.value, row.message, first.hint])
        else:
            rows.append([row.location, row.rule, row.severity.value, row.message, row.hint])
    return rows
