"""Load a model from what a command line says: the path, ``NAME=DIR`` package paths and
``NAME:=VALUE`` xacro arguments."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

from ar3cli.errors import UserError

if TYPE_CHECKING:
    from ar3cli.urdf.model import Model


def apply_xacro_options(trusted: bool, env_names: list[str] | None) -> None:
    """Make ``--xacro trusted`` and ``--xacro-env NAME`` the policy of this run's expansions
    (:func:`~ar3cli.urdf.xacro_expand.set_policy`); a malformed name raises UserError.

    The default policy (safe mode, no variable) is what xacro_expand starts with: while that module
    is not imported yet there is nothing to set, and a run over plain ``.urdf`` files never imports
    xacro's machinery (~5 ms of start-up)."""
    names = [name.strip() for name in env_names or []]
    for name in names:
        if not name or "=" in name or "$" in name or " " in name:
            raise UserError(f"--xacro-env expects an environment variable name, got {name!r}")
    if not trusted and not names and "ar3cli.urdf.xacro_expand" not in sys.modules:
        return
    from ar3cli.urdf.xacro_expand import set_policy
    from ar3cli.urdf.xacro_safe import XacroPolicy

    set_policy(XacroPolicy(trusted=trusted, env=frozenset(names)))


def load_with_specs(path: Path, package_specs: list[str] | None, xacro_specs: list[str] | None,
                    xacro_trusted: bool = False, xacro_env: list[str] | None = None) -> Model:
    """Parse the package-path and xacro-argument specs and load the model (:func:`read_specs`).
    The loaders are imported here, not at start-up: every command module imports this one."""
    from ar3cli.urdf.model import load_model

    return load_model(path, *read_specs(package_specs, xacro_specs, xacro_trusted, xacro_env))


def read_specs(package_specs: list[str] | None, xacro_specs: list[str] | None, xacro_trusted: bool = False,
               xacro_env: list[str] | None = None) -> tuple[dict, dict]:
    """``--package-path`` and ``--xacro-arg`` specs parsed (package -> folder, name -> value), with
    ``--xacro trusted`` / ``--xacro-env`` made this run's xacro policy; malformed specs raise
    UserError (exit 2). Every reader of a robot file goes through it: a model, or a lint of it."""
    from ar3cli.urdf.packages import parse_package_paths
    from ar3cli.urdf.xacro_args import parse_xacro_args

    try:
        packages = parse_package_paths(package_specs)
        xacro_args = parse_xacro_args(xacro_specs)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    apply_xacro_options(xacro_trusted, xacro_env)
    return packages, xacro_args
