"""Command-line options shared by several commands, typed once with ``Annotated``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.output.report import OutputFormat

FormatOption = Annotated[
    OutputFormat,
    typer.Option("--format", "-f", help="Output format: a table for people, or one JSON document on stdout."),
]
PackagePathOption = Annotated[
    Optional[list[str]],
    typer.Option("--package-path", metavar="NAME=DIR",
                 help="Where package://NAME/... lives (repeatable). Also searched: ROS_PACKAGE_PATH, "
                      "AMENT_PREFIX_PATH and the robot file's ancestor folders."),
]
XacroArgOption = Annotated[
    Optional[list[str]],
    typer.Option("--xacro-arg", metavar="NAME:=VALUE", help="A xacro argument for .xacro inputs (repeatable)."),
]
SeedOption = Annotated[int, typer.Option("--seed", min=0, max=2**32 - 1,
                                         help="Random seed (0 .. 2^32-1); the same seed gives the same output.")]
RobotPathArgument = Annotated[Path, typer.Argument(metavar="PATH", help="A .urdf or .xacro file.", show_default=False)]


def samples_option(help: str, most: int) -> typer.models.OptionInfo:
    """``--samples/-n``: at least 1 and at most ``most`` (memory grows with it; say so up front)."""
    return typer.Option("--samples", "-n", min=1, max=most, help=help)


# Options shared by the fixers (fix-inertia, fix-continuous).
FixPathsArgument = Annotated[list[Path], typer.Argument(metavar="PATH", show_default=False,
                                                        help=".urdf files to fix (xacro is refused).")]
DiffOption = Annotated[bool, typer.Option("--diff", help="Print a unified diff and write nothing.")]
CheckOption = Annotated[bool, typer.Option("--check", help="Write nothing; exit 1 when a change is needed.")]
OutputOption = Annotated[Optional[Path], typer.Option("--output", "-o", show_default=False,
                                                      help="Write the result to FILE instead of in place "
                                                           "(one input only).")]


def _apply_timeout(seconds: float) -> float:
    """Set the child processes' time limit as the option is parsed (every command that has it)."""
    from ar3cli.infra.child_limits import set_timeout

    set_timeout(seconds)
    return seconds


TimeoutOption = Annotated[float, typer.Option(
    "--timeout", metavar="SECONDS", min=0, callback=_apply_timeout,
    help="Wall-clock limit per file for the process that runs pybullet (or a decomposition) on it: one that "
         "takes longer is stopped, and the file gets a one-line error. 0: no limit. Each such process may also "
         "map at most half of the memory (1-4 GB; AR3CLI_CHILD_MEMORY_MB sets it).")]
"""``--timeout``: commands give the default (:data:`~ar3cli.infra.child_limits.DEFAULT_TIMEOUT_S`, or
:data:`~ar3cli.infra.child_limits.LONG_TIMEOUT_S` for sample-collisions and fix-collision)."""
