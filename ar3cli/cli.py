"""The Typer application: thin commands that parse options, call the core, render, and exit.

Exit codes: 0 ok, 1 problems found / check failed, 2 usage or I/O error (bad input gets a one-line
``ar3cli: error: ...`` on stderr, never a traceback), 3 a bug in ar3cli (one line too; set
``AR3CLI_DEBUG=1`` to see the traceback), 130 Ctrl-C, 143 SIGTERM (both stop the children and remove
the temporary folders first, see :mod:`ar3cli.infra.shutdown`).
"""

import os
import sys
from collections.abc import Sequence

import typer

from ar3cli import __version__
from ar3cli.errors import EXIT_INTERNAL, EXIT_USAGE, UserError

app = typer.Typer(
    name="ar3cli",
    help="Diagnose, fix and sim-check robot description files (URDF and xacro) with PyBullet.",
    no_args_is_help=True,
    rich_markup_mode="markdown",
    pretty_exceptions_enable=False,
    add_completion=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)
"""The Typer app with its callback only: :func:`application` registers the commands (all of them, or
the one a command line runs). Use ``application([])`` for the complete app (CliRunner, docs)."""


def _version_callback(value: bool) -> None:
    if value:
        print(f"ar3cli {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(False, "--version", callback=_version_callback, is_eager=True,
                                 help="Print the version and exit."),
) -> None:
    """Diagnose, fix and sim-check robot description files (URDF and xacro) with PyBullet."""


def _fixer_commands() -> dict[str, str]:
    """``fix-NAME`` -> its ``FIXER`` for every ``fix/NAME_plan.py``, alphabetically: a fixer is one
    module, found by its file name (the folder is listed, nothing imported)."""
    folder = os.path.join(os.path.dirname(__file__), "fix")
    plans = sorted(name[:-3] for name in os.listdir(folder) if name.endswith("_plan.py"))
    return {"fix-" + plan.removesuffix("_plan").replace("_", "-"): f"ar3cli.fix.{plan}:{FIXER}" for plan in plans}


FIXER = "FIXER"
"""What a ``fix/*_plan.py`` exports; :func:`ar3cli.commands.fixer_options.fixer_command` makes it a command."""
COMMANDS: dict[str, str] = {
    "install-check": "ar3cli.commands.install_check:install_check",
    "info": "ar3cli.commands.info:info",
    "render": "ar3cli.commands.render:render_command",
    "fk-verify": "ar3cli.commands.fk_verify:fk_verify",
    "lint-urdf": "ar3cli.commands.lint_urdf:lint_urdf",
    "expand": "ar3cli.commands.expand:expand",
    "grasp-demo": "ar3cli.commands.grasp_demo:grasp_demo",
    **_fixer_commands(),
    "sample-collisions": "ar3cli.commands.sample_collisions:sample_collisions",
    "cross-check": "ar3cli.commands.cross_check:cross_check",
    "diff": "ar3cli.commands.diff:diff",
    "scan": "ar3cli.commands.scan:scan",
    "scan-report": "ar3cli.commands.scan_report:scan_report",
    "report": "ar3cli.commands.report:report",
    "server": "ar3cli.commands.server:server",
    "view": "ar3cli.commands.view:view",
}
"""Every command, in the order ``--help`` lists them, and where its function (or its fixer) is. A
run imports only the module of the command it runs (see :func:`application`)."""


def application(argv: Sequence[str] | None = None) -> typer.Typer:
    """The app, with the command ``argv`` (default ``sys.argv[1:]``) starts with registered, or
    every command when it starts with none (``--help``, a typo: click then lists or suggests them
    all); none for ``--version``, which its eager callback answers first (0.09 s instead of 0.24 s,
    ``/usr/bin/time ar3cli --version``, 5 runs each)."""
    import importlib

    args = sys.argv[1:] if argv is None else list(argv)
    if args[:1] == ["--version"]:
        names: list[str] = []  # answered by the eager --version callback before any command is looked up
    else:
        names = [args[0]] if args and args[0] in COMMANDS else list(COMMANDS)
    registered = {info.name for info in app.registered_commands}
    for name in names:
        if name not in registered:
            module, _, attribute = COMMANDS[name].partition(":")
            function = getattr(importlib.import_module(module), attribute)
            if attribute == FIXER:
                from ar3cli.commands.fixer_options import fixer_command

                function = fixer_command(function)
            app.command(name)(function)
    order = {name: index for index, name in enumerate(COMMANDS)}
    app.registered_commands.sort(key=lambda info: order.get(info.name or "", len(order)))
    return app


def _click_exceptions() -> tuple[type, type]:
    """(UsageError, NoArgsIsHelpError) of whichever click typer uses (recent typer vendors its own)."""
    import importlib

    for name in ("typer._click.exceptions", "click.exceptions"):
        try:
            module = importlib.import_module(name)
        except ImportError:
            continue
        no_args = getattr(module, "NoArgsIsHelpError", None) or type("NoArgsIsHelpError", (Exception,), {})
        return module.UsageError, no_args
    raise ImportError("neither typer's vendored click nor click is installed")  # pragma: no cover


def main(argv: list[str] | None = None) -> None:
    """Console entry point: run the app; errors become one line on stderr and an exit code.

    Usage errors (a bad option value, a missing argument) are shortened from click's multi-line
    box to ``ar3cli: error: <what> (see 'ar3cli COMMAND --help')`` with exit code 2, like every
    other input error. SIGTERM is handled as Ctrl-C is, with exit code 143.
    """
    from ar3cli.infra import shutdown

    _reopen_closed_standard_streams()
    with shutdown.terminate_like_interrupt():
        _main(argv)


def _interrupted() -> None:
    """Exit after Ctrl-C (130) or SIGTERM (143), with one line saying which."""
    from ar3cli.infra import shutdown

    if shutdown.received():
        print("ar3cli: terminated", file=sys.stderr)
        sys.exit(shutdown.EXIT_TERMINATED)
    print("ar3cli: interrupted", file=sys.stderr)
    sys.exit(130)


def _main(argv: list[str] | None) -> None:
    usage_error, no_args = _click_exceptions()
    try:
        code = application(argv)(args=argv, prog_name="ar3cli", standalone_mode=False)
        if code == 130:  # typer turns Ctrl-C into Exit(130)
            _interrupted()
        sys.exit(code if isinstance(code, int) else 0)
    except no_args as exc:  # `ar3cli` alone, or a group without a command: show the help
        exc.show()
        sys.exit(EXIT_USAGE)
    except usage_error as exc:
        command = exc.ctx.command_path if getattr(exc, "ctx", None) is not None else _command_path(argv)
        message = " ".join(exc.format_message().replace("Value error, ", "").split())
        _say(f"ar3cli: error: {message} (see '{command} --help')")
        sys.exit(EXIT_USAGE)
    except typer.Abort:
        _interrupted()
    except UserError as exc:
        _say(f"ar3cli: error: {exc.message}")
        sys.exit(exc.exit_code)
    except KeyboardInterrupt:
        _interrupted()
    except Exception as exc:  # a bug in ar3cli: one line unless debugging
        if os.environ.get("AR3CLI_DEBUG"):
            raise
        _say(f"ar3cli: internal error: {type(exc).__name__}: {exc} (rerun with AR3CLI_DEBUG=1 for a traceback "
             "and report it)")
        sys.exit(EXIT_INTERNAL)


def _command_path(argv: list[str] | None) -> str:
    """``ar3cli COMMAND`` for the command ``argv`` names, ``ar3cli`` when none: click raises some usage
    errors (an option missing its value, ``render --output``) before it makes the command's context."""
    args = sys.argv[1:] if argv is None else argv
    return f"ar3cli {args[0]}" if args and args[0] in COMMANDS else "ar3cli"


def _say(line: str) -> None:
    """Print one error line on stderr, control characters shown, not obeyed (a file name is the
    attacker's text: an escape sequence in it must not rewrite the terminal or a CI log)."""
    from ar3cli.output.report import printable

    print(printable(line), file=sys.stderr)


SINGLE_THREADED_BLAS = {"OPENBLAS_NUM_THREADS": "1"}
"""Set for a command-line run (and so its child processes) unless the user set it. ar3cli's numpy
work is small arrays (boxes, 3x3 tensors, joint samples): no matrix is large enough for OpenBLAS's
threads to help, but starting them made ``import numpy`` cost 0.17 s of CPU instead of 0.08 s
(``/usr/bin/time python -c "import numpy"``, 3 runs each, 2 cores), CPU that a second lint process
or the pybullet child then lacks."""
GC_ALLOCATIONS = 100_000
"""Allocations between two young-generation garbage collections in a command-line run (Python's
default is 700). A cold lint of pybullet_data's 95 robots allocates a few hundred thousand
short-lived objects (lxml proxies, dataclasses, tuples) that are freed by reference counting,
not by the collector: with the default, 73 collections and 7 of the older generation (which
scans every object the imports made) took 10-15 ms of a ~450 ms run, with this none. Cyclic
garbage is still collected, only in larger batches."""


def run() -> None:
    """The ``ar3cli`` console script and ``python -m ar3cli``: :func:`main`, then a quick exit.

    Python's teardown frees every module and object one by one, which does nothing for a process
    about to end and took ~20 ms after a 95-file lint (measured with benchmarks/bench_lint.py's
    files). So the exit handlers run (caches are saved, temporary folders removed), the streams
    are flushed, and the process ends with ``os._exit``. In-process callers use :func:`main`,
    which raises SystemExit as usual. A SIGTERM once the command is done is ignored: the exit
    handlers finish in milliseconds, and one cut short would leave a temporary file.
    """
    import atexit
    import contextlib
    import gc
    import signal

    gc.set_threshold(GC_ALLOCATIONS, *gc.get_threshold()[1:])
    for name, value in SINGLE_THREADED_BLAS.items():
        os.environ.setdefault(name, value)
    try:
        main()
        code: int | str | None = 0
    except SystemExit as exc:
        code = exc.code
    if isinstance(code, str):  # what sys.exit("message") would print
        print(code, file=sys.stderr)
        code = 1
    if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
    atexit._run_exitfuncs()  # noqa: SLF001 - atexit's own runner: the handlers run now, not at teardown
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):  # closed or full: the output layer has said so
            stream.flush()
    os._exit(code or 0)


def _reopen_closed_standard_streams() -> None:
    """Closed stdin, stdout or stderr (``>&-``, ``2>&-``) become /dev/null. Otherwise the next file
    opened takes their number, and capturing pybullet's C output (which duplicates descriptors 1
    and 2) mixes them up; Python also leaves ``sys.stdout`` as None."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            os.open(os.devnull, os.O_RDWR)  # the lowest free number: this one
    if sys.stdout is None:
        sys.stdout = open(os.devnull, "w", encoding="utf-8")  # noqa: SIM115 - lives as long as the process
    if sys.stderr is None:
        sys.stderr = open(os.devnull, "w", encoding="utf-8")  # noqa: SIM115 - lives as long as the process

