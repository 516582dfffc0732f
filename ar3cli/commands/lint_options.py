"""lint-urdf's own options, typed once with ``Annotated``, and the functions that turn their values
into the linter's settings (the shared ones are in ``options.py``)."""

from __future__ import annotations

import enum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Optional

import typer

from ar3cli.commands.options import format_option
from ar3cli.errors import UserError
from ar3cli.output.formats import LINT

if TYPE_CHECKING:
    from ar3cli.urdf.srdf_read import DisabledPairs


class Engine(str, enum.Enum):
    """Simulators ``--sim`` runs."""

    pybullet = "pybullet"
    mujoco = "mujoco"
    all = "all"


class FailOn(str, enum.Enum):
    error = "error"
    warning = "warning"
    info = "info"


SIM_PANEL = "Simulation"
"""lint-urdf's ``--help`` panels: its options grouped, so that each panel's columns fit 80 characters."""
CI_PANEL = "Baselines, changes and output"
KINDS = (LINT,)
"""lint-urdf's report: lint findings (every format that renders them)."""
LintFormatOption = format_option(KINDS, "LintFormat")
PathsArgument = Annotated[Optional[list[Path]], typer.Argument(
    metavar="PATH", help="URDF/xacro files, or folders searched for *.urdf and *.xacro (required, "
                         "except with --explain).", show_default=False)]
SelectOption = Annotated[Optional[list[str]], typer.Option(
    "--select", metavar="CODES",
    help="Only these rule codes or prefixes (comma-separated, repeatable; overrides the config's select).")]
IgnoreOption = Annotated[Optional[list[str]], typer.Option(
    "--ignore", metavar="CODES", help="Skip these rule codes or prefixes (added to the config's ignore).")]
FailOnOption = Annotated[Optional[FailOn], typer.Option(
    "--fail-on", help="Exit 1 when a finding is at least this severe (default: error, or the config's fail-on).",
    show_default=False)]
ExitZeroOption = Annotated[bool, typer.Option("--exit-zero", help="Exit 0 even when there are findings.")]
SimOption = Annotated[bool, typer.Option(
    "--sim", help="Also load each model in PyBullet (P rules): load errors, self-collision at home, inertia "
                  "PyBullet really uses, stability.", rich_help_panel=SIM_PANEL)]
EngineOption = Annotated[Engine, typer.Option(
    "--engine", help="The simulator(s) --sim checks in: PyBullet (P rules), MuJoCo (M rules: compile, "
                     "unreadable meshes, contacts at home, 1 s under gravity; needs pip install 'ar3cli[mujoco]'), "
                     "or all; mujoco and all imply --sim.", rich_help_panel=SIM_PANEL)]
NoConfigOption = Annotated[bool, typer.Option("--no-config", help="Ignore \\[tool.ar3cli.lint] in pyproject.toml.")]
IsolatedOption = Annotated[bool, typer.Option(
    "--isolated", help="Judge the files by the command line alone: ignore \\[tool.ar3cli.lint] in pyproject.toml "
                       "and the files' own suppression comments (ar3cli: ignore, ar3cli: ignore-file); a baseline only "
                       "when --baseline names one. For pull requests whose author may have written those.")]
JobsOption = Annotated[Optional[int], typer.Option(
    "--jobs", "-j", min=1, show_default=False,
    help="Processes that share the files, at most one per CPU. Default on Linux: one per 24 files or per 256 KB "
         "of them, whichever is more (per 2 files with --sim), at most 8; elsewhere 1. The output is the same for "
         "any value.")]
NoCacheOption = Annotated[bool, typer.Option(
    "--no-cache", help="Check every file again instead of reusing the findings of unchanged files from earlier "
                       "runs (also AR3CLI_NO_CACHE=1).")]
FixHintOption = Annotated[bool, typer.Option(
    "--fix-hint", help="After the findings, print the ar3cli command lines that fix them, one per fixer and file "
                       "(JSON: fix_commands).", rich_help_panel=CI_PANEL)]
GroupOption = Annotated[Optional[bool], typer.Option(
    "--group/--no-group", help="Text format: show 5 or more alike findings of one rule in one file as one row "
                               "(count, first locations, message); github, markdown, sarif and junit: one "
                               "annotation, row, result or test case per rule and file. On by default; JSON keeps "
                               "every finding.", show_default=False, rich_help_panel=CI_PANEL)]
WideOption = Annotated[bool, typer.Option(
    "--wide", help="Text format: the table, a row a line however wide. By default tables fit the terminal "
                   "(or COLUMNS); piped (pre-commit, CI logs), each finding is one line: path:line:col: CODE "
                   "[severity] message.", rich_help_panel=CI_PANEL)]
BaselineOption = Annotated[Optional[Path], typer.Option(
    "--baseline", metavar="FILE", help="Do not report (or fail on) the findings this baseline file holds; only new "
                                       "ones count.", show_default=False, rich_help_panel=CI_PANEL)]
WriteBaselineOption = Annotated[Optional[Path], typer.Option(
    "--write-baseline", metavar="FILE", help="Write every finding of this run to FILE as the baseline (for "
                                             "--baseline) and exit 0.", show_default=False, rich_help_panel=CI_PANEL)]
ChangedSinceOption = Annotated[Optional[str], typer.Option(
    "--changed-since", metavar="REF", help="Only the robot files under PATH changed since this git ref (and "
                                           "untracked ones), and those using a changed mesh or included xacro file.",
    show_default=False, rich_help_panel=CI_PANEL)]
ExplainOption = Annotated[Optional[str], typer.Option(
    "--explain", metavar="CODE", help="Print a rule's documentation (why, fix, examples) and exit; takes no PATH.",
    show_default=False)]
SrdfOption = Annotated[Optional[Path], typer.Option(
    "--srdf", metavar="FILE.srdf", dir_okay=False, rich_help_panel=SIM_PANEL,
    help="With --sim: link pairs this MoveIt SRDF disables are not reported as colliding at home (P002).")]
TargetOption = Annotated[Optional[list[str]], typer.Option(
    "--target", metavar="ENGINES",
    help="Engines the robot is meant for (comma-separated or repeated: pybullet, ros, mujoco, isaac, drake, "
         "gazebo): adds each one's known traps (T rules). Default: pybullet,ros.", show_default=False)]


def linter_options(config: Any, select: list[str] | None = None, ignore: list[str] | None = None,
                   isolated: bool = False, **settings: Any) -> Any:
    """The linter's :class:`~ar3cli.lint.engine.LintOptions` for the command line's ``--select`` and
    ``--ignore`` (their CODES strings, comma-separated) and the project's ``config``
    (:meth:`LintOptions.configured <ar3cli.lint.engine.LintOptions.configured>`)."""
    from ar3cli.lint.engine import LintOptions

    return LintOptions.configured(config, split_codes(select) if select else None, split_codes(ignore),
                                  isolated, **settings)


def skipped_links_note(skipped: list[str]) -> str:
    """The note for the symbolic links a folder's search left out (they lead out of the folder)."""
    shown = ", ".join(skipped[:3]) + (f" and {len(skipped) - 3} more" if len(skipped) > 3 else "")
    return (f"ar3cli: note: skipped {len(skipped)} symbolic link{'s' if len(skipped) != 1 else ''} to a file outside "
            f"the folder searched ({shown}); name a file as PATH to lint it")


def split_codes(items: list[str] | None) -> list[str]:
    """``--select``/``--ignore`` values, each comma-separated, as one list."""
    return [part for item in items or [] for part in item.split(",")]


def parse_targets(values: list[str] | None) -> tuple[str, ...]:
    """The --target engines, validated (default: pybullet and ros)."""
    from ar3cli.lint.rules.targets import DEFAULT_TARGETS, TARGETS

    if not values:
        return DEFAULT_TARGETS
    names = tuple(dict.fromkeys(name.strip().lower() for value in values for name in value.split(",") if name.strip()))
    unknown = [name for name in names if name not in TARGETS]
    if unknown:
        raise UserError(f"--target: unknown engine {unknown[0]!r} (known: {', '.join(TARGETS)})")
    return names


def srdf_disabled(srdf: Path | None, sim: bool) -> DisabledPairs | None:
    """The pairs ``--srdf`` disables (None: no ``--srdf``); it only matters with ``--sim`` (a one-line error
    without)."""
    if srdf is None:
        return None
    if not sim:
        raise UserError("--srdf only changes the --sim checks (P002, contact at the home pose): add --sim")
    from ar3cli.urdf.srdf_read import disabled_pairs

    return disabled_pairs(srdf)
