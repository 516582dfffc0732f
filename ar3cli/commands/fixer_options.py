"""Every ``fix-*`` command, built from its fixer: :func:`fixer_command`.

A fixer is one module, ``fix/NAME_plan.py``, exporting ``FIXER`` (a :class:`~ar3cli.fix.driver.Fixer`);
there is no command module per fixer. The command's signature is the file argument first, the
fixer's own options (declared on its options dataclass with :func:`~ar3cli.fix.settings.setting`),
then the options every fixer takes, declared here once: ``--diff``, ``--check``, ``-o``,
``--follow-symlinks``, ``--package-path``, the xacro options (``--xacro-arg``, ``--xacro``,
``--xacro-env``: a fixer that edits xacro sources reads them as every command does), ``--format``
and (for the fixers that start a child process) ``--timeout``. The shared values reach the fixer
as one :class:`~ar3cli.fix.driver.FixerArgs`.
"""

from __future__ import annotations

import inspect
import types
import typing
from collections.abc import Callable
from dataclasses import MISSING
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Optional

import typer

from ar3cli.commands.options import (
    FollowSymlinksOption,
    FormatOption,
    PackagePathOption,
    SeedOption,
    TimeoutOption,
    XacroArgOption,
    XacroEnvOption,
    XacroMode,
    XacroModeOption,
    finite_float,
    keyword_parameter,
)

if TYPE_CHECKING:
    from ar3cli.fix.driver import Fixer
    from ar3cli.fix.settings import SettingField

FixPathsArgument = Annotated[list[Path], typer.Argument(metavar="PATH", show_default=False,
                                                        help=".urdf files to fix (xacro is refused).")]
XacroFixPathsArgument = Annotated[list[Path], typer.Argument(
    metavar="PATH", show_default=False,
    help=".urdf or .xacro files to fix (a xacro source where the value is literal text in it; each element "
         "that is not is listed with the reason).")]
DiffOption = Annotated[bool, typer.Option("--diff", help="Print a unified diff and write nothing.")]
CheckOption = Annotated[bool, typer.Option("--check", help="Write nothing; exit 1 when a change is needed.")]
OutputOption = Annotated[Optional[Path], typer.Option("--output", "-o", show_default=False,
                                                      help="Write the result to FILE instead of in place "
                                                           "(one input only).")]


PATHS = keyword_parameter("paths", FixPathsArgument)
XACRO_PATHS = keyword_parameter("paths", XacroFixPathsArgument)
SHARED = (keyword_parameter("diff", DiffOption, False), keyword_parameter("check", CheckOption, False),
          keyword_parameter("output", OutputOption, None), keyword_parameter("follow_symlinks", FollowSymlinksOption, False),
          keyword_parameter("package_path", PackagePathOption, None),
          keyword_parameter("xacro_arg", XacroArgOption, None),
          keyword_parameter("xacro", XacroModeOption, XacroMode.safe),
          keyword_parameter("xacro_env", XacroEnvOption, None),
          keyword_parameter("format", FormatOption, "text"))
"""After the command's own options, in this order (``--help`` lists them so)."""


SHARED_BY_NAME = {"seed": SeedOption}
"""Options a fixer names without flags (``seed: int = setting(default=0)``): the same ``--seed`` as
every sampling command."""


def fixer_command(fixer: Fixer) -> Callable[..., None]:
    """The ``fix-*`` command of ``fixer`` (a ``fix/*_plan.py``'s ``FIXER``): the file argument, the
    fixer's own options (the :func:`~ar3cli.fix.settings.setting` fields of ``fixer.options``), the
    shared ones, and ``--timeout`` when ``fixer.timeout`` is set. It builds ``fixer.options`` from
    its values, runs the fixer and exits with its code; ``fixer.help`` is its ``--help``."""
    from ar3cli.fix.settings import settings_of

    own = [_own_option(item) for item in settings_of(fixer.options)] if fixer.options is not None else []
    tail = [] if fixer.timeout is None else [keyword_parameter("timeout", TimeoutOption, fixer.timeout)]
    parameters = [XACRO_PATHS if fixer.edits_xacro else PATHS, *own, *SHARED, *tail]

    def command(**values: Any) -> None:
        from ar3cli.fix.driver import FixerArgs

        shared = {parameter.name: values.pop(parameter.name) for parameter in (PATHS, *SHARED)}
        shared["xacro_trusted"] = XacroMode(shared.pop("xacro")) is XacroMode.trusted
        values.pop("timeout", None)  # set for the child processes by the option's callback
        options = fixer.options(**values) if fixer.options is not None else None
        raise typer.Exit(fixer.run(options, FixerArgs(**shared)))

    command.__name__ = command.__qualname__ = fixer.name.replace("-", "_")
    command.__doc__ = fixer.help
    command.__signature__ = inspect.Signature(parameters, return_annotation=None)  # type: ignore[attr-defined]
    command.__annotations__ = {parameter.name: parameter.annotation for parameter in parameters}
    return command


def _own_option(item: SettingField) -> inspect.Parameter:
    """The typer option of one fixer setting: a float is finite (and within its bounds), an int within
    its bounds; no default means required."""
    setting = item.setting
    default = inspect.Parameter.empty if item.default is MISSING else item.default
    if not setting.flags:
        return keyword_parameter(item.name, SHARED_BY_NAME[item.name], default)
    extra: dict[str, Any] = {}
    if float in _types(item.annotation):
        extra["click_type"] = finite_float(setting.minimum, setting.maximum)
    elif setting.minimum is not None or setting.maximum is not None:
        extra.update(min=setting.minimum, max=setting.maximum)
    if setting.metavar is not None:
        extra["metavar"] = setting.metavar
    if item.default is MISSING:
        extra["show_default"] = False
    option = typer.Option(*setting.flags, help=setting.help, **extra)
    return keyword_parameter(item.name, Annotated[item.annotation, option], default)


def _types(annotation: Any) -> tuple[Any, ...]:
    """``float | None`` (or ``Optional[float]``, a ``typing.Union``) -> ``(float, NoneType)``; a plain
    type -> ``(type,)``."""
    union = typing.get_origin(annotation) in (typing.Union, types.UnionType)
    return typing.get_args(annotation) if union else (annotation,)
