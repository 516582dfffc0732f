"""Command-line options shared by several commands, typed once with ``Annotated``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.errors import UserError
from ar3cli.output import OutputFormat

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
SeedOption = Annotated[int, typer.Option("--seed", help="Random seed; the same seed gives the same output.")]
RobotPathArgument = Annotated[Path, typer.Argument(help="A .urdf or .xacro file.", show_default=False)]


def load_from_options(path: Path, package_path: list[str] | None, xacro_arg: list[str] | None):
    """Parse the shared loading options and load the model; malformed options raise UserError."""
    from ar3cli.model import load_model
    from ar3cli.packages import parse_package_paths
    from ar3cli.xacro_expand import parse_xacro_args

    try:
        packages = parse_package_paths(package_path)
        xacro_args = parse_xacro_args(xacro_arg)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    return load_model(path, packages, xacro_args)
