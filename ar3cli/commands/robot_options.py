"""The options of every command that loads one robot file, declared once: :func:`robot_input` adds
``--package-path``, ``--xacro-arg``, ``--xacro`` and ``--xacro-env`` and hands the command one
:class:`RobotSource` that loads the file with them.

The command's function takes ``source: RobotSource`` and its own options; the decorator gives typer
a signature with the robot options placed before ``--format`` (or last), so ``--help`` lists them in
the same place for info, render, report, fk-verify, sample-collisions and cross-check.
"""

from __future__ import annotations

import functools
import inspect
import typing
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ar3cli.commands.options import (
    PackagePathOption,
    XacroArgOption,
    XacroEnvOption,
    XacroMode,
    XacroModeOption,
    keyword_parameter,
)

if TYPE_CHECKING:
    from ar3cli.urdf.model import Model

SOURCE = "source"
"""The parameter of a command that receives the robot options as a :class:`RobotSource`."""
ROBOT_OPTIONS = (keyword_parameter("package_path", PackagePathOption, None),
                 keyword_parameter("xacro_arg", XacroArgOption, None),
                 keyword_parameter("xacro", XacroModeOption, XacroMode.safe),
                 keyword_parameter("xacro_env", XacroEnvOption, None))


@dataclass(frozen=True)
class RobotSource:
    """How to read the robot file: ``--package-path`` and ``--xacro-arg`` specs, the xacro mode and
    the environment names ``--xacro-env`` lets a trusted xacro read."""

    package_path: list[str] | None = None
    xacro_arg: list[str] | None = None
    xacro: XacroMode = XacroMode.safe
    xacro_env: list[str] | None = None

    def load(self, path: Path) -> Model:
        """The Model of ``path`` (xacro expanded); malformed specs and bad files raise UserError."""
        from ar3cli.urdf.model import load_model

        return load_model(path, *self.specs())

    def specs(self) -> tuple[dict, dict]:
        """(packages, xacro arguments) parsed, with the xacro mode and environment names made this
        run's policy (:func:`~ar3cli.urdf.loading.read_specs`): for readers other than :meth:`load`."""
        from ar3cli.urdf.loading import read_specs

        return read_specs(self.package_path, self.xacro_arg, self.xacro is XacroMode.trusted, self.xacro_env)


def robot_input(function: Callable[..., None]) -> Callable[..., None]:
    """Give a one-robot command the robot options; its function takes ``source: RobotSource``."""
    hints = typing.get_type_hints(function, include_extras=True)  # the module may postpone annotations
    own = [parameter.replace(kind=inspect.Parameter.KEYWORD_ONLY, annotation=hints.get(name, parameter.annotation))
           for name, parameter in inspect.signature(function).parameters.items() if name != SOURCE]
    at = next((index for index, parameter in enumerate(own) if parameter.name == "format"), len(own))
    parameters = [*own[:at], *ROBOT_OPTIONS, *own[at:]]

    @functools.wraps(function)
    def command(**values: Any) -> None:
        source = RobotSource(**{parameter.name: values.pop(parameter.name) for parameter in ROBOT_OPTIONS})
        function(**values, **{SOURCE: source})

    command.__signature__ = inspect.Signature(parameters, return_annotation=None)  # type: ignore[attr-defined]
    command.__annotations__ = {parameter.name: parameter.annotation for parameter in parameters}
    return command
