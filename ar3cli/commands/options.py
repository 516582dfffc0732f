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
FollowSymlinksOption = Annotated[bool, typer.Option(
    "--follow-symlinks", help="Write through an output path (or an in-place fix's file) that is a symbolic link, "
                              "replacing the link's target. Without it such a path is refused: a link planted "
                              "in a repository must not redirect a write.")]
