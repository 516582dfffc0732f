"""``ar3cli server``: the language server editors start (LSP over stdin/stdout).

A thin adapter: the options lint-urdf would take become :class:`~ar3cli.server.options.ServerOptions`,
and :func:`ar3cli.server.launch.serve` runs until the editor ends it. docs/editors.md shows how each
editor starts it.
"""

from __future__ import annotations

from typing import Annotated

import typer

from ar3cli.commands.lint_options import NoConfigOption, TargetOption, parse_targets
from ar3cli.commands.options import (
    PackagePathOption,
    TimeoutOption,
    XacroArgOption,
    XacroEnvOption,
    XacroMode,
    XacroModeOption,
)
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.server.options import DEFAULT_DEBOUNCE_MS, MAX_DEBOUNCE_MS

SimOnSaveOption = Annotated[bool, typer.Option(
    "--sim", help="Also run the PyBullet rules (lint-urdf --sim) each time a file is saved, in a child process; "
                  "never while typing. The editor's setting `sim` overrides it.")]
DebounceOption = Annotated[int, typer.Option(
    "--debounce-ms", min=0, max=MAX_DEBOUNCE_MS, metavar="MS",
    help="How long typing must pause before a changed buffer is checked. The editor's setting `debounceMs` "
         "overrides it.")]
StdioOption = Annotated[bool, typer.Option(
    "--stdio", help="Speak LSP on stdin/stdout: what the server always does (accepted because editors pass it).")]


def server(
    package_path: PackagePathOption = None,
    xacro_arg: XacroArgOption = None,
    xacro: XacroModeOption = XacroMode.safe,
    xacro_env: XacroEnvOption = None,
    target: TargetOption = None,
    sim: SimOnSaveOption = False,
    debounce_ms: DebounceOption = DEFAULT_DEBOUNCE_MS,
    no_config: NoConfigOption = False,
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
    stdio: StdioOption = False,
) -> None:
    """Run the language server: lint-urdf's findings in your editor as you type, with hovers, quick fixes,
    an outline of the kinematic tree, go to definition and completion for .urdf and .xacro files.

    Editors start it and talk to it on stdin/stdout (LSP); docs/editors.md has the configuration for
    VS Code, Neovim, Helix and Emacs. It reads [tool.ar3cli.lint] of the workspace's pyproject.toml
    and takes lint-urdf's robot options. Needs the server extra: pip install 'ar3cli[server]'.
    """
    from ar3cli.server.launch import require_extra, serve
    from ar3cli.server.options import ServerOptions
    from ar3cli.urdf.loading import read_specs

    require_extra()  # before anything else: without the extra, one line and exit 2
    packages, xacro_args = read_specs(package_path, xacro_arg, xacro is XacroMode.trusted, xacro_env)
    serve(ServerOptions(packages=packages, xacro_args=xacro_args, targets=parse_targets(target) if target else None,
                        sim=sim, debounce_ms=debounce_ms, use_config=not no_config))
