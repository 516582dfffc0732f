"""``ar3cli scan-report``: counts, worst files and a keep-list from a scan store."""

import enum
from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.output.report import Report, finish


class ReportFormat(str, enum.Enum):
    text = "text"
    json = "json"
    markdown = "markdown"


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
    format: Annotated[ReportFormat, typer.Option("--format", "-f", help="text (tables), json or markdown.")]
    = ReportFormat.text,
) -> None:
    """Sum up a scan store: files by status, findings by rule, the worst files, and the files a
    keep filter keeps (written to --keep-list for a training run).

    Exit codes: 0 ok, 2 usage or I/O error.
    """
    filters = keep if keep else (["no-errors"] if keep_list is not None else [])
    report = store_report(store, top, filters, ReportFormat(format))
    if keep_list is not None:
        from ar3cli.infra.atomic import atomic_write

        paths = report.data["keep"]["paths"]
        atomic_write(keep_list, "".join(f"{path}\n" for path in paths).encode("utf-8", "surrogateescape"))
        report.lines.append(f"wrote {len(paths)} paths to {keep_list}")
    finish(report, "json" if format is ReportFormat.json else "text")


def store_report(store: Path, top: int, filters: list[str] | None = None,
                 fmt: ReportFormat = ReportFormat.text) -> Report:
    """The report of ``store`` in ``fmt`` (the JSON document is ``Report.data`` in every format)."""
    from ar3cli.scan.keep import parse_keep
    from ar3cli.scan.report import keep_line, markdown, summarize, tables
    from ar3cli.scan.store import Store

    parsed = [parse_keep(text) for text in filters or []]
    with Store(store, readonly=True) as opened:
        data = summarize(list(opened.rows()), parsed, top)
    if fmt is ReportFormat.markdown:
        return Report(data=data, text=markdown(data))
    return Report(data=data, tables=tables(data), lines=[keep_line(data)])
