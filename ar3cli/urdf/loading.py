"""Load a model from what a command line says: the path, ``NAME=DIR`` package paths and
``NAME:=VALUE`` xacro arguments."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ar3cli.errors import UserError

if TYPE_CHECKING:
    from ar3cli.urdf.model import Model


def load_with_specs(path: Path, package_specs: list[str] | None, xacro_specs: list[str] | None) -> Model:
    """Parse the package-path and xacro-argument specs and load the model; malformed specs raise
    UserError (exit 2). The loaders are imported here, not at start-up: every command module
    imports this one."""
    from ar3cli.urdf.model import load_model
    from ar3cli.urdf.packages import parse_package_paths
    from ar3cli.urdf.xacro_expand import parse_xacro_args

    try:
        packages = parse_package_paths(package_specs)
        xacro_args = parse_xacro_args(xacro_specs)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    return load_model(path, packages, xacro_args)
