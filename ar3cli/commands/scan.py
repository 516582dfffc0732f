"""``ar3cli scan``: lint every robot file under some folders into a resumable SQLite store.

This module is also the bridge between two features: the scan (:mod:`ar3cli.scan`) runs
:func:`lint_for_scan`, which calls the linter (:mod:`ar3cli.lint.engine`), without either feature
importing the other.
"""

import enum
from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.commands.options import FormatOption, PackagePathOption, XacroArgOption, finite_float
from ar3cli.output.formats import finish
from ar3cli.output.report import Report


class BackendName(str, enum.Enum):
    local = "local"
    ray = "ray"


def scan(
    roots: Annotated[list[Path], typer.Argument(metavar="ROOT", show_default=False,
                                                help="Folders searched for *.urdf and *.xacro (or single files).")],
    store: Annotated[Path, typer.Option("--store", metavar="FILE.sqlite", dir_okay=False,
                                        help="The SQLite store: one row per file, kept between runs.")]
    = Path("scan.sqlite"),
    sim: Annotated[bool, typer.Option("--sim", help="Also run the simulation checks (P rules) in PyBullet.")] = False,
    select: Annotated[Optional[list[str]], typer.Option("--select", metavar="CODES",
                                                        help="Only these rule codes or prefixes (comma-separated).")]
    = None,
    ignore: Annotated[Optional[list[str]], typer.Option("--ignore", metavar="CODES",
                                                        help="Skip these rule codes or prefixes.")] = None,
    rescan: Annotated[bool, typer.Option("--rescan", help="Check every file again, even those already stored.")]
    = False,
    jobs: Annotated[Optional[int], typer.Option("--jobs", "-j", min=1, show_default=False,
                                                help="Worker processes (local: at most one per CPU; default one "
                                                     "per CPU), or the CPUs of the local Ray it starts.")] = None,
    timeout: Annotated[float, typer.Option("--timeout", metavar="SECONDS", click_type=finite_float(min=0.1),
                                           help="Stop a file's check after this long: its row says timeout.")]
    = 120.0,
    backend: Annotated[BackendName, typer.Option("--backend", help="local: forked workers on this machine; "
                                                                   "ray: Ray tasks (pip install 'ar3cli[ray]').")]
    = BackendName.local,
    address: Annotated[Optional[str], typer.Option("--address", metavar="HOST:PORT", show_default=False,
                                                   help="With --backend ray: join this running cluster instead of "
                                                        "starting a local one.")] = None,
    report: Annotated[bool, typer.Option("--report", help="Print the scan-report of the store after the scan.")]
    = False,
    package_path: PackagePathOption = None,
    xacro_arg: XacroArgOption = None,
    format: FormatOption = "text",
) -> None:
    """Lint every robot file under ROOT into a SQLite store, one row per file; a second run checks
    only new or changed files. Interrupt it at any time: the next run goes on from there.

    Exit codes: 0 scan finished (whatever it found), 2 usage or I/O error, 130 interrupted.
    """
    import functools
    import os

    from ar3cli.errors import UserError
    from ar3cli.lint.engine import LintOptions, collect_files
    from ar3cli.lint.rules import validate_patterns
    from ar3cli.scan.run import Backend, run_scan
    from ar3cli.scan.worker import ScanSettings
    from ar3cli.urdf.packages import parse_package_paths
    from ar3cli.urdf.xacro_args import parse_xacro_args

    if address is not None and backend is not BackendName.ray:
        raise UserError("--address joins a Ray cluster: add --backend ray")
    if backend is BackendName.ray:
        from ar3cli.scan.ray_backend import require_ray

        require_ray()
    try:
        options = LintOptions(select=validate_patterns(_split(select), "--select") or ["ALL"],
                              ignore=validate_patterns(_split(ignore), "--ignore"), sim=sim,
                              package_paths=parse_package_paths(package_path), xacro_args=parse_xacro_args(xacro_arg))
    except ValueError as exc:
        raise UserError(str(exc)) from None
    skipped: list[str] = []
    files = collect_files(roots, skipped)
    if skipped:
        from ar3cli.commands.lint_options import skipped_links_note
        from ar3cli.output.report import log

        log(skipped_links_note(skipped))
    if not files:
        raise UserError(f"no .urdf or .xacro files found in {', '.join(str(p) for p in roots)}")
    settings = ScanSettings(functools.partial(lint_for_scan, options=options), settings_key(options),
                            options.package_paths, options.xacro_args, os.getcwd())
    summary = run_scan(files, store, settings, Backend(backend.value, jobs, timeout, address), rescan)
    if report and format == "text":
        from ar3cli.commands.scan_report import store_report

        finish(store_report(store, top=10), "text")
    data = summary.to_dict()
    counts = ", ".join(f"{count} {status}" for status, count in summary.statuses.items() if count) or "none"
    line = (f"scanned {summary.files} files into {store}: {summary.checked} checked ({counts}), "
            f"{summary.skipped} already stored; {data['seconds']} s, {data['files_per_second']} files/s "
            f"({summary.backend})")
    finish(Report(data=data, lines=[line]), format)


def lint_for_scan(path: Path, model, options):
    """The scan's per-file check: lint the Model the scan loaded, or, when it did not load, let
    the linter load the file to report why (an F001-F004 finding)."""
    from ar3cli.lint.engine import display_path, lint_file, lint_model

    rules = options.rules()
    if model is None:
        return lint_file(path, rules, options)
    return lint_model(model, display_path(path), rules, options)


def settings_key(options) -> str:
    """What a stored row was checked with: the version, --sim, and a digest of the rules and load options."""
    import hashlib

    from ar3cli import __version__

    described = repr(([rule.code for rule in options.rules()], sorted(options.package_paths.items()),
                      sorted(options.xacro_args.items())))
    digest = hashlib.sha256(described.encode()).hexdigest()[:12]
    return f"ar3cli {__version__} {'sim' if options.sim else 'static'} {digest}"


def _split(items: list[str] | None) -> list[str]:
    return [part for item in items or [] for part in item.split(",")]
