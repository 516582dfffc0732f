"""``ar3cli lint-urdf``: static (and optionally simulated) checks of URDF / xacro files.

The options are declared in ``lint_options.py``; the findings are rendered by the format registry
(:mod:`ar3cli.output.formats`, the ``lint`` kind).
"""

from pathlib import Path

from ar3cli.commands.lint_options import (
    KINDS,
    BaselineOption,
    ChangedSinceOption,
    Engine,
    EngineOption,
    ExitZeroOption,
    ExplainOption,
    FailOnOption,
    FixHintOption,
    GroupOption,
    IgnoreOption,
    IsolatedOption,
    JobsOption,
    LintFormatOption,
    NoCacheOption,
    NoConfigOption,
    PathsArgument,
    SelectOption,
    SimOption,
    SrdfOption,
    TargetOption,
    WideOption,
    WriteBaselineOption,
    linter_options,
    parse_targets,
    skipped_links_note,
    srdf_disabled,
)
from ar3cli.commands.options import (
    FollowSymlinksOption,
    PackagePathOption,
    TimeoutOption,
    XacroArgOption,
    XacroEnvOption,
    XacroMode,
    XacroModeOption,
)
from ar3cli.errors import UserError
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.output.formats import finish, finish_as
from ar3cli.output.report import Report


def lint_urdf(
    paths: PathsArgument = None,
    format: LintFormatOption = "text",
    select: SelectOption = None,
    ignore: IgnoreOption = None,
    fail_on: FailOnOption = None,
    exit_zero: ExitZeroOption = False,
    sim: SimOption = False,
    engine: EngineOption = Engine.pybullet,
    no_config: NoConfigOption = False,
    isolated: IsolatedOption = False,
    jobs: JobsOption = None,
    no_cache: NoCacheOption = False,
    fix_hint: FixHintOption = False,
    group: GroupOption = None,
    wide: WideOption = False,
    baseline: BaselineOption = None,
    write_baseline: WriteBaselineOption = None,
    follow_symlinks: FollowSymlinksOption = False,
    changed_since: ChangedSinceOption = None,
    explain: ExplainOption = None,
    package_path: PackagePathOption = None,
    xacro_arg: XacroArgOption = None,
    xacro: XacroModeOption = XacroMode.safe,
    xacro_env: XacroEnvOption = None,
    srdf: SrdfOption = None,
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
    target: TargetOption = None,
) -> None:
    """Check URDF and xacro files for mistakes that break ROS tools or make PyBullet misbehave.

    Every finding has a stable rule code, a severity, a location and a fix; see docs/rules.md.
    Exit codes: 0 clean, 1 findings at or above --fail-on, 2 usage or I/O error.
    """
    if explain is not None:
        if paths:
            raise UserError("--explain takes a rule code and no PATH")
        explain_rule(explain, format)
    if not paths:
        raise UserError("missing PATH: give the URDF/xacro files or folders to check, or --explain CODE "
                        "(see 'ar3cli lint-urdf --help')")
    if write_baseline is not None and changed_since is not None:
        raise UserError("--write-baseline records every file, so it cannot be combined with --changed-since")
    from ar3cli.commands.lint_report import exit_code, lint_report
    from ar3cli.findings import Severity
    from ar3cli.lint.config import LintConfig, load_config
    from ar3cli.lint.engine import lint_paths, summarize
    from ar3cli.urdf.loading import apply_xacro_options
    from ar3cli.urdf.packages import parse_package_paths
    from ar3cli.urdf.xacro_args import parse_xacro_args

    sim = sim or Engine(engine) is not Engine.pybullet  # --engine mujoco|all asks for a simulation
    from ar3cli.infra.isolation import announce_slow_work
    from ar3cli.output.report import log

    announce_slow_work(lambda line: log(f"lint-urdf: {line}"))  # a humanoid's --sim takes ~7 s: say so on stderr
    engines = ("pybullet", "mujoco") if engine is Engine.all else (Engine(engine).value,)
    if sim and "mujoco" in engines:
        from ar3cli.sim.mujoco_session import import_mujoco

        import_mujoco()  # a missing extra: one line naming it, exit 2
    config = LintConfig() if no_config or isolated else load_config()
    try:
        package_paths, xacro_args = parse_package_paths(package_path), parse_xacro_args(xacro_arg)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    options = linter_options(config, select, ignore, isolated, sim=sim, package_paths=package_paths,
                             xacro_args=xacro_args, srdf_disabled=srdf_disabled(srdf, sim), engines=engines,
                             targets=parse_targets(target), sources=str(getattr(format, "value", format)) == "html")
    apply_xacro_options(xacro is XacroMode.trusted, xacro_env)
    threshold = Severity(fail_on.value) if fail_on else (config.fail_on or Severity.ERROR)
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
        skipped: list[str] = []
        results = lint_paths(paths, options, use_cache=not no_cache, jobs=jobs, skipped=skipped)
        no_files = not results
        if skipped:
            from ar3cli.output.report import log

            log(skipped_links_note(skipped))
    if no_files:
        raise UserError(f"no .urdf or .xacro files found in {', '.join(str(p) for p in paths)}")
    if write_baseline is not None:
        _write_baseline(write_baseline, results, format, follow_symlinks)
    held = None
    if accepted is not None:
        from ar3cli.lint.baseline import apply_baseline

        results, baselined, unused = apply_baseline(results, accepted)
        held = {"baselined": baselined, "baseline_unused": unused, "baseline": str(baseline)}
    summary = {**summarize(results, threshold), **(held or {}), "config_file": options.config_file,
               "isolated": isolated}
    summary["exit_code"] = exit_code(summary, exit_zero)
    fixes = None
    if fix_hint:
        from ar3cli.lint.fix_hints import fix_commands

        fixes = [line for result in results for line in fix_commands(result.path, result.findings)]
    report = lint_report(results, summary, options, grouped=True if group is None else group,
                         note=selection.note() if selection else None,
                         changed=selection.to_dict() if selection else None,
                         fix_commands=fixes, exit_zero=exit_zero, wide=wide)
    finish_as(report, KINDS, format)


def _write_baseline(path: Path, results, fmt, follow_symlinks: bool = False) -> None:
    """Write the baseline, say so in one line (or a JSON object), exit 0 (2 if a file's check crashed)."""
    from ar3cli.lint.baseline import write_baseline

    count, files = write_baseline(path, results, follow_symlinks)
    line = (f"wrote {path}: {count} finding{'s' if count != 1 else ''} in {files} file{'s' if files != 1 else ''} "
            f"({len(results)} checked); with --baseline {path} only new findings are reported")
    data = {"baseline": str(path), "findings": count, "files_with_findings": files, "files": len(results)}
    finish(Report(data=data, lines=[line], errors=[r.error for r in results if r.error]),
           "json" if fmt == "json" else "text")


def explain_rule(code: str, fmt) -> None:
    """``--explain CODE``: the rule's documentation in the terminal (or as JSON), exit 0."""
    from ar3cli.lint.engine import find_rule, rule_document
    from ar3cli.output.explain import explain_text

    document = rule_document(find_rule(code))
    if fmt == "json":
        finish(Report(data=document), "json")
    finish(Report(data=document, text=explain_text(document)), "text")
