"""``ar3cli lint-urdf``: static (and optionally simulated) checks of URDF / xacro files."""

import enum
from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.commands.options import (
    FollowSymlinksOption,
    PackagePathOption,
    TimeoutOption,
    XacroArgOption,
    XacroEnvOption,
    XacroMode,
    XacroModeOption,
)
from ar3cli.errors import EXIT_USAGE, UserError
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.output.report import Report, Table, finish


class LintFormat(str, enum.Enum):
    """Output formats of lint-urdf (the common text/json plus CI formats)."""

    text = "text"
    json = "json"
    sarif = "sarif"
    github = "github"
    markdown = "markdown"
    junit = "junit"
    html = "html"


class Engine(str, enum.Enum):
    """Simulators ``--sim`` runs."""

    pybullet = "pybullet"
    mujoco = "mujoco"
    all = "all"


class FailOn(str, enum.Enum):
    error = "error"
    warning = "warning"
    info = "info"


def lint_urdf(
    paths: Annotated[Optional[list[Path]], typer.Argument(
        metavar="PATH", help="URDF/xacro files, or folders searched for *.urdf and *.xacro (required, "
                             "except with --explain).", show_default=False)] = None,
    format: Annotated[LintFormat, typer.Option("--format", "-f", help="text (table), json, sarif (SARIF 2.1.0), "
                                                                      "github (workflow annotations), markdown or "
                                                                      "junit (JUnit XML test report).")]
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
    engine: Annotated[Engine, typer.Option("--engine", help="With --sim: the simulator(s) to check in: PyBullet "
                                                           "(P rules), MuJoCo (M rules: compile, unreadable meshes, "
                                                           "contacts at home, 1 s under gravity; needs "
                                                           "pip install 'ar3cli[mujoco]'), or all.")]
    = Engine.pybullet,
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
    fix_hint: Annotated[bool, typer.Option("--fix-hint", help="After the findings, print the ar3cli command "
                                                               "lines that fix them, one per fixer and file "
                                                               "(JSON: fix_commands).")] = False,
    group: Annotated[Optional[bool], typer.Option("--group/--no-group",
                                                  help="Text format: show 5 or more alike findings of one rule in "
                                                       "one file as one row (count, first locations, message); on "
                                                       "by default. JSON, SARIF, github and markdown keep every "
                                                       "finding.", show_default=False)] = None,
    wide: Annotated[bool, typer.Option("--wide", help="Text format: one line per finding, however wide (for grep "
                                                      "and wide log viewers). By default tables fit the terminal "
                                                      "(or COLUMNS) and wrap messages; piped without COLUMNS, they "
                                                      "are one line per row anyway.")] = False,
    baseline: Annotated[Optional[Path], typer.Option("--baseline", metavar="FILE",
                                                     help="Do not report (or fail on) the findings this baseline "
                                                          "file holds; only new ones count.", show_default=False)]
    = None,
    write_baseline: Annotated[Optional[Path], typer.Option("--write-baseline", metavar="FILE",
                                                           help="Write every finding of this run to FILE as the "
                                                                "baseline (for --baseline) and exit 0.",
                                                           show_default=False)] = None,
    follow_symlinks: FollowSymlinksOption = False,
    changed_since: Annotated[Optional[str], typer.Option("--changed-since", metavar="REF",
                                                         help="Only the robot files under PATH changed since this "
                                                              "git ref (and untracked ones), and those using a "
                                                              "changed mesh or included xacro file.",
                                                         show_default=False)] = None,
    explain: Annotated[Optional[str], typer.Option("--explain", metavar="CODE",
                                                   help="Print a rule's documentation (why, fix, examples) and "
                                                        "exit; takes no PATH.", show_default=False)] = None,
    package_path: PackagePathOption = None,
    xacro_arg: XacroArgOption = None,
    xacro: XacroModeOption = XacroMode.safe,
    xacro_env: XacroEnvOption = None,
    srdf: Annotated[Optional[Path], typer.Option(
        "--srdf", metavar="FILE.srdf", dir_okay=False,
        help="With --sim: link pairs this MoveIt SRDF disables are not reported as colliding at home (P002).")]
    = None,
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
    target: Annotated[Optional[list[str]], typer.Option(
        "--target", metavar="ENGINES",
        help="Engines the robot is meant for (comma-separated or repeated: pybullet, ros, mujoco, isaac, drake, "
             "gazebo): adds each one's known traps (T rules). Default: pybullet,ros.", show_default=False)] = None,
) -> None:
    """Check URDF and xacro files for mistakes that break ROS tools or make PyBullet misbehave.

    Every finding has a stable rule code, a severity, a location and a fix; see docs/rules.md.
    Exit codes: 0 clean, 1 findings at or above --fail-on, 2 usage or I/O error.
    """
    if explain is not None:
        if paths:
            raise UserError("--explain takes a rule code and no PATH")
        explain_rule(explain, LintFormat(format))
    if not paths:
        raise UserError("missing PATH: give the URDF/xacro files or folders to check, or --explain CODE "
                        "(see 'ar3cli lint-urdf --help')")
    if write_baseline is not None and changed_since is not None:
        raise UserError("--write-baseline records every file, so it cannot be combined with --changed-since")
    from ar3cli.findings import Severity
    from ar3cli.lint.config import LintConfig, load_config
    from ar3cli.lint.engine import LintOptions, lint_paths, summarize
    from ar3cli.lint.rules import validate_patterns
    from ar3cli.urdf.loading import apply_xacro_options
    from ar3cli.urdf.packages import parse_package_paths
    from ar3cli.urdf.xacro_expand import parse_xacro_args

    if Engine(engine) is not Engine.pybullet and not sim:
        raise UserError("--engine chooses the simulator of --sim: add --sim")
    engines = ("pybullet", "mujoco") if engine is Engine.all else (Engine(engine).value,)
    if sim and "mujoco" in engines:
        from ar3cli.sim.mujoco_session import import_mujoco

        import_mujoco()  # a missing extra: one line naming it, exit 2
    config = LintConfig() if no_config else load_config()
    try:
        options = LintOptions(
            select=(validate_patterns(_split(select), "--select") if select else config.select) or ["ALL"],
            ignore=[*config.ignore, *validate_patterns(_split(ignore), "--ignore")],
            per_file_ignores=config.per_file_ignores, severity=config.severity, sim=sim,
            package_paths=parse_package_paths(package_path), xacro_args=parse_xacro_args(xacro_arg),
            srdf_disabled=_srdf_disabled(srdf, sim), engines=engines, targets=_targets(target))
    except ValueError as exc:
        raise UserError(str(exc)) from None
    apply_xacro_options(xacro is XacroMode.trusted, xacro_env)
    threshold = Severity(fail_on.value) if fail_on else (config.fail_on or Severity.ERROR)
    fmt = LintFormat(format)
    accepted = None
    if baseline is not None and write_baseline is None:
        from ar3cli.lint.baseline import read_baseline

        accepted = read_baseline(baseline)  # before linting: a broken baseline fails at once
    selection = None
    if changed_since is not None:
        from ar3cli.lint.changed import select_changed

        selection = select_changed(paths, changed_since, options.package_paths, options.xacro_args)
        results = lint_paths(selection.files, options, use_cache=not no_cache, jobs=jobs) if selection.files else []
        no_files = not selection.candidates
    else:
        results = lint_paths(paths, options, use_cache=not no_cache, jobs=jobs)
        no_files = not results
    if no_files:
        raise UserError(f"no .urdf or .xacro files found in {', '.join(str(p) for p in paths)}")
    if write_baseline is not None:
        _write_baseline(write_baseline, results, fmt, follow_symlinks)
    held = None
    if accepted is not None:
        from ar3cli.lint.baseline import apply_baseline

        results, baselined, unused = apply_baseline(results, accepted)
        held = {"baselined": baselined, "baseline_unused": unused}
    summary = {**summarize(results, threshold), **(held or {})}
    summary["exit_code"] = EXIT_USAGE if summary["files_not_checked"] else 1 if summary["findings_failing"] and \
        not exit_zero else 0
    grouped = True if group is None else group
    if selection is not None and not results and fmt is LintFormat.text:
        report = Report(data={}, lines=[changed_note(selection)])
    else:
        report = render_lint(results, summary, options, fmt, grouped=grouped)
        if selection is not None:
            report.data["changed_since"] = selection.to_dict()
            if fmt is LintFormat.text:
                report.lines.insert(0, changed_note(selection))
            else:
                from ar3cli.output.report import log

                log(changed_note(selection))
    if fix_hint and fmt in (LintFormat.text, LintFormat.json):
        from ar3cli.lint.fix_hints import fix_commands

        commands = [line for result in results for line in fix_commands(result.path, result.findings)]
        report.data["fix_commands"] = commands
        report.lines += [f"to fix: {line}" for line in commands] or ["to fix: no finding has an ar3cli fixer"]
    report.ok = report.ok or exit_zero
    report.wide = wide
    report.errors = [*report.errors, *(result.error for result in results if result.error)]
    finish(report, "json" if fmt in (LintFormat.json, LintFormat.sarif) else "text")


def _targets(values: list[str] | None) -> tuple[str, ...]:
    """The --target engines, validated (default: pybullet and ros)."""
    from ar3cli.lint.rules.targets import DEFAULT_TARGETS, TARGETS

    if not values:
        return DEFAULT_TARGETS
    names = tuple(dict.fromkeys(name.strip().lower() for value in values for name in value.split(",") if name.strip()))
    unknown = [name for name in names if name not in TARGETS]
    if unknown:
        raise UserError(f"--target: unknown engine {unknown[0]!r} (known: {', '.join(TARGETS)})")
    return names


def _srdf_disabled(srdf: Path | None, sim: bool) -> frozenset[frozenset[str]]:
    """The pairs ``--srdf`` disables; it only matters with ``--sim`` (a one-line error without)."""
    if srdf is None:
        return frozenset()
    if not sim:
        raise UserError("--srdf only changes the --sim checks (P002, contact at the home pose): add --sim")
    from ar3cli.urdf.srdf import disabled_pairs

    return disabled_pairs(srdf)


def _write_baseline(path: Path, results, fmt: LintFormat, follow_symlinks: bool = False) -> None:
    """Write the baseline, say so in one line (or a JSON object), exit 0 (2 if a file's check crashed)."""
    from ar3cli.lint.baseline import write_baseline

    count, files = write_baseline(path, results, follow_symlinks)
    line = (f"wrote {path}: {count} finding{'s' if count != 1 else ''} in {files} file{'s' if files != 1 else ''} "
            f"({len(results)} checked); with --baseline {path} only new findings are reported")
    data = {"baseline": str(path), "findings": count, "files_with_findings": files, "files": len(results)}
    finish(Report(data=data, lines=[line], errors=[r.error for r in results if r.error]),
           "json" if fmt is LintFormat.json else "text")


def changed_note(selection) -> str:
    """What --changed-since picked, in one line."""
    head = f"--changed-since {selection.ref}:"
    if not selection.files:
        return (f"{head} no robot file under PATH changed or uses a changed file "
                f"({selection.candidates} not checked); nothing to check")
    parts = []
    if selection.changed:
        parts.append(f"{len(selection.changed)} changed ({_names(selection.changed)})")
    if selection.dependents:
        count = len(selection.dependents)
        parts.append(f"{count} use{'s' if count == 1 else ''} a changed file ("
                     + _names([f"{robot} uses {', '.join(used)}" for robot, used in selection.dependents.items()])
                     + ")")
    return f"{head} {len(selection.files)} of {selection.candidates} robot files: {'; '.join(parts)}"


def _names(items: list[str], shown: int = 3) -> str:
    return ", ".join(items[:shown]) + (f", and {len(items) - shown} more" if len(items) > shown else "")


def explain_rule(code: str, fmt: LintFormat) -> None:
    """``--explain CODE``: the rule's documentation in the terminal (or as JSON), exit 0."""
    from ar3cli.lint.engine import find_rule, rule_document
    from ar3cli.output.sarif import RULES_URL

    document = rule_document(find_rule(code))
    document["url"] = f"{RULES_URL}#{document['anchor']}"
    if fmt is LintFormat.json:
        finish(Report(data=document), "json")
    finish(Report(data=document, text=explain_text(document)), "text")


_SHOWN_FIRST = ("code", "name", "severity", "title", "why", "fix", "bad", "good", "needs_sim", "family", "anchor",
                "url")
_PARAGRAPHS = {"why": "Why it matters", "fix": "Fix", "fixed_by": "Fixed by", "thresholds": "Thresholds",
               "references": "References"}


def explain_text(document: dict) -> str:
    """The terminal form of :func:`~ar3cli.lint.engine.rule_document`: the heading, then every
    paragraph the rule has (fields added to Rule later included), the examples, the link."""
    import textwrap

    sim = "; runs only with --sim" if document.get("needs_sim") else ""
    out = [f"{document['code']} {document['name']} ({document['severity']}, {document['family']}{sim})", "",
           textwrap.fill(f"{document['title']}.", 100), ""]
    extra = [key for key in document if key not in _SHOWN_FIRST and key not in _PARAGRAPHS]
    for key in ("why", "fix", "fixed_by", "thresholds", "references", *extra):
        value = document.get(key)
        if value in (None, "", (), [], {}, False):
            continue
        label = _PARAGRAPHS.get(key) or key.replace("_", " ").capitalize()
        if key == "fixed_by":
            value = f"ar3cli {value}"
        text = value if isinstance(value, str) else ", ".join(map(str, value)) if isinstance(value, (list, tuple)) \
            else str(value)
        out += [f"{label}:", textwrap.fill(text, 100, initial_indent="  ", subsequent_indent="  "), ""]
    for key, label in (("bad", "Failing example"), ("good", "Passing example")):
        if document.get(key):
            out += [f"{label}:", textwrap.indent(document[key].rstrip("\n"), "  "), ""]
    out.append(f"Docs: {document['url']}")
    return "\n".join(out) + "\n"


def _split(items: list[str] | None) -> list[str]:
    return [part for item in items or [] for part in item.split(",")]


def summary_line(summary: dict, cached: int = 0) -> str:
    """The verdict line; ``cached`` files answered from the result cache are said when there are any."""
    files = summary["files"]
    broken = summary["files_not_checked"]
    clean = summary["files_clean"]
    verdict = "FAILED" if summary["failed"] else "passed"
    unchecked = f"; {broken} not fully checked (pybullet crashed, or ran out of time or memory)" if broken else ""
    remembered = f"; {cached} unchanged since an earlier run (from the cache)" if cached else ""
    held = ""
    if summary.get("baselined") is not None:
        unused = summary.get("baseline_unused") or 0
        held = f"; {summary['baselined']} baselined" + (
            f" ({unused} more in the baseline no longer found: --write-baseline drops them)" if unused else "")
    return (f"{verdict}: {files} file{'s' if files != 1 else ''} checked, {summary['error']} errors, "
            f"{summary['warning']} warnings, {summary['info']} info; {clean} clean{held}{unchecked}{remembered} "
            f"(fail-on: {summary['fail_on']})")


def render_lint(results, summary: dict, options, fmt: LintFormat, grouped: bool = False) -> Report:
    """The lint Report in ``fmt``: text and json tables, SARIF as the JSON document, github
    annotations and markdown as verbatim stdout text (github also appends the Markdown table to
    ``$GITHUB_STEP_SUMMARY`` when set). ``grouped`` folds alike findings into one text row
    (:func:`~ar3cli.lint.engine.group_findings`); every other format keeps every finding."""
    from ar3cli.lint.fix_hints import fixed_by

    findings = [f for result in results for f in result.findings]
    data = {"files": [r.to_dict() for r in results],
            "findings": [{**f.to_dict(), "fixed_by": fixed_by(f.rule)} for f in findings], "summary": summary}
    ok = not summary["findings_failing"]  # a file not checked is exit 2 (Report.errors), not 1
    if fmt is LintFormat.sarif:
        from ar3cli.output.sarif import sarif_document

        return Report(data=sarif_document(findings, options.rules()), ok=ok)
    if fmt is LintFormat.junit:
        from ar3cli.findings import Severity
        from ar3cli.output.junit import junit_document

        document = junit_document([(r.path, r.findings, r.error) for r in results], Severity(summary["fail_on"]))
        return Report(data=data, text=document, lines=[summary_line(summary)], ok=ok)
    if fmt is LintFormat.html:
        from ar3cli.commands.finding_context import finding_context
        from ar3cli.output.html import lint_page

        page = lint_page(data, {"verdict": summary_line(summary), **finding_context(findings)})
        return Report(data=data, text=page, lines=[summary_line(summary)], ok=ok)
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
