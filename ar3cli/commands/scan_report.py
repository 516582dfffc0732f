"""``ar3cli scan-report``: counts, worst files and a keep-list from a scan store."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.commands.options import format_option
from ar3cli.output.formats import MARKDOWN, REPORT, finish_as
from ar3cli.output.report import Report, log

KINDS = (MARKDOWN, REPORT)
"""A scan summary is a table report with a Markdown form."""
FormatOption = format_option(KINDS, "ScanReportFormat")


def scan_report(
    store: Annotated[Path, typer.Argument(metavar="STORE", show_default=False,
                                          help="The SQLite store an 'ar3cli scan' wrote.")],
    keep: Annotated[Optional[list[str]], typer.Option(
        "--keep", metavar="FILTER",
        help="Which files to keep (repeatable, all must hold): loads, clean, no-errors, no-warnings, "
             "max-severity=LEVEL, no-rule=CODES, max-findings=N, min-dof=N, max-dof=N. Default with "
             "--keep-list: no-errors.", show_default=False)] = None,
    keep_list: Annotated[Optional[Path], typer.Option("--keep-list", metavar="FILE", dir_okay=False,
                                                      help="Write the kept files' paths to FILE, one a line.",
                                                      show_default=False)] = None,
    top: Annotated[int, typer.Option("--top", min=0, max=10_000, help="How many of the worst files to list.")] = 10,
    format: FormatOption = "text",
) -> None:
    """Sum up a scan store: files by status, findings by rule, the worst files, and the files a
    keep filter keeps (written to --keep-list for a training run).

    Exit codes: 0 ok, 2 usage or I/O error.
    """
    filters = keep if keep else (["no-errors"] if keep_list is not None else [])
    report = store_report(store, top, filters)
    if keep_list is not None:
        from ar3cli.infra.atomic import atomic_write

        paths = report.data["keep"]["paths"]
        # one path a line: a name holding a line break would write a second, forged path into the list
        lines = [path for path in paths if "\n" not in path and "\r" not in path]
        atomic_write(keep_list, "".join(f"{path}\n" for path in lines).encode("utf-8", "surrogateescape"))
        wrote = f"wrote {len(lines)} paths to {keep_list}" + (
            f"; left out {len(paths) - len(lines)} whose name holds a line break" if len(lines) < len(paths) else "")
        if format == "markdown":
            log(wrote)  # the Markdown alone on stdout, this line on stderr
        else:
            report.lines.append(wrote)
    finish_as(report, KINDS, format)


def store_report(store: Path, top: int, filters: list[str] | None = None) -> Report:
    """The report of ``store``: its JSON document, tables and keep line, and its Markdown form."""
    from ar3cli.scan.keep import parse_keep
    from ar3cli.scan.report import keep_line, markdown, summarize, tables
    from ar3cli.scan.store import Store

    parsed = [parse_keep(text) for text in filters or []]
    with Store(store, readonly=True) as opened:
        data = summarize(list(opened.rows()), parsed, top)
    return Report(data=data, tables=tables(data), lines=[keep_line(data)], markdown=lambda: markdown(data))
