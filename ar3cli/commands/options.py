"""Command-line options shared by several commands, typed once with ``Annotated`` (the fixers' own:
``fixer_options.py``)."""

from __future__ import annotations

import inspect
import math
from enum import Enum
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ar3cli.output.formats import REPORT, choices, help_text


def keyword_parameter(name: str, annotation: Any, default: Any = inspect.Parameter.empty) -> inspect.Parameter:
    """A keyword-only parameter for a signature the option decorators build (``robot_input``,
    ``fixer_command``): typer reads the options from it."""
    return inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=annotation)


def format_option(kinds: tuple[str, ...], enum_name: str) -> Any:
    """``--format/-f`` of a command whose report is of ``kinds`` (most specific first): its choices
    and their help are the formats of :mod:`ar3cli.output.formats` that render those kinds."""
    return Annotated[choices(kinds, enum_name), typer.Option("--format", "-f", help=help_text(kinds))]


FormatOption = format_option((REPORT,), "ReportFormat")
SHARED_PANEL = "Robot files, writes and limits (the same in every command)"
"""The ``--help`` panel of the options many commands share: in their own box, with their own column
widths, they no longer squeeze each command's options into a narrow help column."""
PackagePathOption = Annotated[
    Optional[list[str]],
    typer.Option("--package-path", metavar="NAME=DIR", rich_help_panel=SHARED_PANEL,
                 help="Where package://NAME/... lives (repeatable). Also searched: ROS_PACKAGE_PATH, "
                      "AMENT_PREFIX_PATH and the robot file's ancestor folders."),
]
XacroArgOption = Annotated[
    Optional[list[str]],
    typer.Option("--xacro-arg", metavar="NAME:=VALUE", rich_help_panel=SHARED_PANEL,
                 help="A xacro argument for .xacro inputs (repeatable)."),
]


class XacroMode(str, Enum):
    """How ``.xacro`` inputs are expanded (``docs/security.md``)."""

    safe = "safe"
    trusted = "trusted"


XacroModeOption = Annotated[
    XacroMode,
    typer.Option("--xacro", rich_help_panel=SHARED_PANEL,
                 help="How .xacro inputs are expanded. safe: expressions without Python eval, files only "
                      "from the robot's folder and packages, no environment variables, time and memory "
                      "limits. trusted: xacro as it is, which runs any Python the file holds; only for "
                      "your own files on your own machine."),
]
XacroEnvOption = Annotated[
    Optional[list[str]],
    typer.Option("--xacro-env", metavar="NAME", rich_help_panel=SHARED_PANEL,
                 help="An environment variable .xacro inputs may read with $(env NAME) / $(optenv NAME) in safe "
                      "mode (repeatable; without it they are refused)."),
]
SeedOption = Annotated[int, typer.Option("--seed", min=0, max=2**32 - 1,
                                         help="Random seed (0 .. 2^32-1); the same seed gives the same output.")]


def _float_range_type() -> type:
    """click's FloatRange from whichever click typer uses (recent typer vendors its own)."""
    try:
        from typer._click.types import FloatRange
    except ImportError:  # pragma: no cover - typer before it vendored click
        from click.types import FloatRange
    return FloatRange


class FiniteFloat(_float_range_type()):
    """A float option that refuses ``nan``, ``inf`` and ``-inf`` (one line, exit 2).

    click's FLOAT and FloatRange take them: ``nan`` even passes ``min``/``max``, because every
    comparison with NaN is false, and then reaches the maths and the JSON (``--always-threshold nan``
    was exit 3 with ``--format json``). Every float option of every command uses this type through
    :func:`finite_float`; ``tests/test_output_edge_cases.py`` walks the app to check that none is missed.
    """

    name = "float"

    def convert(self, value: Any, param: Any, ctx: Any) -> Any:
        try:
            number = float(value)
        except (TypeError, ValueError):
            number = None  # not a number at all: click's own message
        if number is not None and not math.isfinite(number):
            self.fail(f"{value}: must be a finite number", param, ctx)
        return super().convert(value, param, ctx)

    def _describe_range(self) -> str:
        """No bounds, no range in ``--help`` (click's FloatRange printed ``[x<=None]``)."""
        return "" if self.min is None and self.max is None else super()._describe_range()


def finite_float(min: float | None = None, max: float | None = None) -> FiniteFloat:
    """The click type of a float option: finite, and within ``min`` .. ``max`` when given. Pass it
    as ``typer.Option(..., click_type=finite_float(...))`` (typer's own ``min``/``max`` are ignored
    once a click type is given)."""
    return FiniteFloat(min=min, max=max)


RobotPathArgument = Annotated[Path, typer.Argument(metavar="PATH", help="A .urdf or .xacro file.", show_default=False)]


def samples_option(help: str, most: int) -> typer.models.OptionInfo:
    """``--samples/-n``: at least 1 and at most ``most`` (memory grows with it; say so up front)."""
    return typer.Option("--samples", "-n", min=1, max=most, help=help)


FollowSymlinksOption = Annotated[bool, typer.Option(
    "--follow-symlinks", rich_help_panel=SHARED_PANEL,
    help="Write through an output path (or an in-place fix's file) that is a symbolic link, "
         "replacing the link's target. Without it such a path is refused: a link planted "
         "in a repository must not redirect a write.")]


def _apply_timeout(seconds: float) -> float:
    """Set the child processes' time limit as the option is parsed (every command that has it)."""
    from ar3cli.infra.child_limits import set_timeout

    set_timeout(seconds)
    return seconds


TimeoutOption = Annotated[float, typer.Option(
    "--timeout", metavar="SECONDS", click_type=finite_float(min=0), callback=_apply_timeout,
    rich_help_panel=SHARED_PANEL,
    help="Wall-clock limit per file for each process that works on it (its checks, pybullet, a decomposition, "
         "a diff): one that takes longer is stopped, and the file gets a one-line error. 0: no limit. Each such "
         "process may also map at most half of the memory (1-4 GB; AR3CLI_CHILD_MEMORY_MB sets it).")]
"""``--timeout``: commands give the default (:data:`~ar3cli.infra.child_limits.DEFAULT_TIMEOUT_S`, or
:data:`~ar3cli.infra.child_limits.LONG_TIMEOUT_S` for sample-collisions and fix-collision)."""
