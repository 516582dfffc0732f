"""The options every fixer command takes, declared once: :func:`fixer_command` adds them.

A fixer command (``fix-*``) is a function of its own options and ``args: FixerArgs``; the
decorator gives typer a signature with the file argument first, the command's own options, then
``--diff``, ``--check``, ``-o``, ``--follow-symlinks``, ``--package-path``, ``--format`` and
(for the fixers that start a child process) ``--timeout``, and hands the function those values
as one :class:`~ar3cli.fix.driver.FixerArgs`. :func:`run_fix` runs the fixer and exits with its code.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, NoReturn, Optional

import typer

from ar3cli.commands.options import (
    FollowSymlinksOption,
    FormatOption,
    PackagePathOption,
    TimeoutOption,
    keyword_parameter,
)

if TYPE_CHECKING:
    from ar3cli.fix.driver import Fixer, FixerArgs

FixPathsArgument = Annotated[list[Path], typer.Argument(metavar="PATH", show_default=False,
                                                        help=".urdf files to fix (xacro is refused).")]
DiffOption = Annotated[bool, typer.Option("--diff", help="Print a unified diff and write nothing.")]
CheckOption = Annotated[bool, typer.Option("--check", help="Write nothing; exit 1 when a change is needed.")]
OutputOption = Annotated[Optional[Path], typer.Option("--output", "-o", show_default=False,
                                                      help="Write the result to FILE instead of in place "
                                                           "(one input only).")]


ARGS = "args"
"""The parameter of a fixer command that receives the shared options as a ``FixerArgs``."""
PATHS = keyword_parameter("paths", FixPathsArgument)
SHARED = (keyword_parameter("diff", DiffOption, False), keyword_parameter("check", CheckOption, False),
          keyword_parameter("output", OutputOption, None), keyword_parameter("follow_symlinks", FollowSymlinksOption, False),
          keyword_parameter("package_path", PackagePathOption, None),
          keyword_parameter("format", FormatOption, "text"))
"""After the command's own options, in this order (``--help`` lists them so)."""


def fixer_command(timeout: float | None) -> Callable[[Callable[..., None]], Callable[..., None]]:
    """Give a fixer command the shared options; ``timeout`` is its ``--timeout`` default (None: the
    fixer starts no child process and has no ``--timeout``). The command's function takes
    ``args: FixerArgs`` and its own options; its docstring is its help."""

    def decorate(function: Callable[..., None]) -> Callable[..., None]:
        own = [parameter.replace(kind=inspect.Parameter.KEYWORD_ONLY)
               for name, parameter in inspect.signature(function).parameters.items() if name != ARGS]
        tail = [] if timeout is None else [keyword_parameter("timeout", TimeoutOption, timeout)]
        parameters = [PATHS, *own, *SHARED, *tail]

        @functools.wraps(function)
        def command(**values: Any) -> None:
            from ar3cli.fix.driver import FixerArgs

            shared = {parameter.name: values.pop(parameter.name) for parameter in (PATHS, *SHARED)}
            values.pop("timeout", None)  # set for the child processes by the option's callback
            function(**values, **{ARGS: FixerArgs(**shared)})

        command.__signature__ = inspect.Signature(parameters, return_annotation=None)  # type: ignore[attr-defined]
        command.__annotations__ = {parameter.name: parameter.annotation for parameter in parameters}
        return command

    return decorate


def run_fix(fixer: Fixer, options: Any, args: FixerArgs, verify: bool = False) -> NoReturn:
    """Run ``fixer`` (a ``fix/*_plan.py``'s ``FIXER``) and exit with its code."""
    from ar3cli.fix.driver import run_fixer

    raise typer.Exit(run_fixer(fixer, options, args, verify=verify))
