"""The one output layer: every command hands it a :class:`Report` and a format.

Text goes to a rich console on a terminal (tables with colour, without it when ``NO_COLOR`` is
set). Off a terminal (pipes, CI logs, pre-commit) tables are plain ASCII, one line per row, and
rich is not even imported unless the report holds rich renderables. JSON goes to stdout alone, so
``ar3cli ... --format json | jq`` always works; progress and logs go to stderr. Failing to write
the output (a full disk) is a one-line :class:`~ar3cli.errors.UserError`.
Lint's extra formats (sarif, github, markdown) live in their own modules and use the same Report.
"""

from __future__ import annotations

import enum
import json
import math
import os
import sys
from dataclasses import dataclass, field
from typing import Any, NoReturn, TextIO

from ar3cli.errors import EXIT_USAGE, UserError


class OutputFormat(str, enum.Enum):
    """Formats every command supports."""

    text = "text"
    json = "json"


STATUS_STYLES = {
    "ok": "green", "pass": "green", "passed": "green", "success": "green",
    "info": "blue", "warn": "yellow", "warning": "yellow",
    "fail": "red", "failed": "red", "error": "bold red",
}


@dataclass
class Table:
    """A titled table: ``rows`` hold plain values; cells in a ``status_column`` get coloured."""

    title: str
    columns: list[str]
    rows: list[list[Any]] = field(default_factory=list)
    caption: str = ""
    status_column: str | None = None
    numeric_columns: tuple[str, ...] = ()
    nowrap_columns: tuple[str, ...] = ()
    """Columns a terminal table must not fold (e.g. ``path:line:col``, which editors make clickable)."""


@dataclass
class Report:
    """What a command found: ``data`` is the JSON document, ``tables``/``lines`` its text form."""

    data: dict[str, Any]
    tables: list[Table] = field(default_factory=list)
    lines: list[str] = field(default_factory=list)
    ok: bool = True
    renderables: list[Any] = field(default_factory=list)
    """Extra rich renderables (e.g. a heat map), printed after the tables in text mode."""
    text: str = ""
    """A verbatim payload for stdout (a unified diff, workflow annotations, Markdown). When set, text
    mode writes it to stdout alone and moves tables and lines to stderr, so the payload can be piped."""
    errors: list[str] = field(default_factory=list)
    """One-line errors about part of the work (a file whose pybullet run crashed) while the rest was
    reported: written to stderr as ``ar3cli: error: ...`` in every format, and the exit code is 2."""


def console(stderr: bool = False):
    """A rich Console for stdout (or stderr): no colour and ASCII boxes when not a terminal."""
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    plain = bool(os.environ.get("NO_COLOR")) or not stream.isatty()
    return Console(file=stream, no_color=plain, highlight=False, soft_wrap=not stream.isatty(),
                   width=None if stream.isatty() else 160, safe_box=True,
                   force_terminal=False if plain else None)


def format_cell(value: Any) -> str:
    """Numbers compactly (4 significant digits, scientific when tiny/huge); None as a dash."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        if value == 0 or not math.isfinite(value):
            return str(value)
        magnitude = abs(value)
        return f"{value:.4g}" if 1e-3 <= magnitude < 1e5 else f"{value:.3e}"
    return str(value)


def plain_table(table: Table) -> str:
    """An ASCII table, one line per row and no wrapping: what pipes, CI logs and grep want.

    Rich's layout engine takes ~0.6 ms per row (0.4 s for pybullet_data's 659 lint findings);
    off a terminal nobody sees its wrapping, so this is a plain, fast formatter.
    """
    rows = [[format_cell(value).replace("\n", " ") for value in row] for row in table.rows]
    widths = [max([len(column), *(len(row[index]) for row in rows)]) for index, column in enumerate(table.columns)]
    numeric = [column in table.numeric_columns for column in table.columns]

    def line(cells: list[str]) -> str:
        return "| " + " | ".join(cell.rjust(width) if right else cell.ljust(width)
                                 for cell, width, right in zip(cells, widths, numeric)) + " |"

    rule = "+" + "+".join("-" * (width + 2) for width in widths) + "+"
    out = [table.title] if table.title else []
    out += [rule, line(list(table.columns)), rule, *(line(row) for row in rows), rule]
    if table.caption:
        out.append(table.caption)
    return "\n".join(out) + "\n"


NARROW_TERMINAL = 100
"""Below this many columns a wide table would split words and numbers: rows are printed as blocks."""


def render_rows_as_blocks(table: Table, out) -> None:
    """One block per row for narrow terminals: the short cells on one line, each long cell indented
    below it and wrapped by the terminal (as ruff prints diagnostics)."""
    from rich.padding import Padding
    from rich.text import Text

    rows = [[format_cell(value) for value in row] for row in table.rows]
    short = [index for index, column in enumerate(table.columns)
             if column in table.nowrap_columns or column in table.numeric_columns or column == table.status_column
             or max((len(row[index]) for row in rows), default=0) <= 16]
    if table.title:
        out.print(Text(table.title, style="bold"))
    for row in rows:
        out.print(Text("  ".join(row[index] for index in short if row[index])))
        for index, column in enumerate(table.columns):
            if index not in short and row[index]:
                out.print(Padding(Text(f"{column}: {row[index]}"), (0, 0, 0, 4)))


def render_table(table: Table, out=None) -> None:
    """Print one :class:`Table`: through rich on a terminal (as blocks when it is narrow), as
    :func:`plain_table` elsewhere."""
    out = out or console()
    if not out.is_terminal:
        out.file.write(plain_table(table))
        out.file.flush()
        return
    if out.width < NARROW_TERMINAL and len(table.columns) > 3:
        render_rows_as_blocks(table, out)
        return
    from rich import box
    from rich.table import Table as RichTable
    from rich.text import Text

    plain = out.no_color
    rich_table = RichTable(title=table.title or None, caption=table.caption or None,
                           box=box.ASCII2 if plain else box.ROUNDED, title_justify="left",
                           caption_justify="left", header_style="" if plain else "bold")
    for column in table.columns:
        keep_whole = column in table.nowrap_columns or column in table.numeric_columns or column == table.status_column
        rich_table.add_column(column, justify="right" if column in table.numeric_columns else "left",
                              overflow="fold", no_wrap=keep_whole, min_width=max(len(word) for word in column.split()))
    status_index = table.columns.index(table.status_column) if table.status_column in table.columns else -1
    for row in table.rows:
        cells = []
        for index, value in enumerate(row):
            text = format_cell(value)
            style = STATUS_STYLES.get(text.lower(), "") if index == status_index and not plain else ""
            cells.append(Text(text, style=style))
        rich_table.add_row(*cells)
    out.print(rich_table)


def emit_json(data: Any) -> None:
    """Write one JSON document to stdout, and nothing else."""
    write(sys.stdout, json.dumps(data, indent=2, default=_json_default, allow_nan=False) + "\n")


def write(stream: TextIO, text: str) -> None:
    """Write and flush ``text``; a full disk or an I/O error becomes a one-line UserError (and
    the descriptor is pointed at /dev/null, so the text still buffered is dropped quietly at exit).
    A reader that went away (``| head``) is left to the CLI's usual quiet exit."""
    try:
        stream.write(text)
        stream.flush()
    except BrokenPipeError:
        raise
    except OSError as exc:
        try:
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, stream.fileno())
            os.close(null)
        except (OSError, ValueError):
            pass
        raise UserError(f"cannot write the output: {exc.strerror or exc}") from None


def _json_default(value: Any) -> Any:
    if hasattr(value, "tolist"):
        return value.tolist()
    if hasattr(value, "item"):
        return value.item()
    if isinstance(value, enum.Enum):
        return value.value
    if hasattr(value, "__fspath__"):
        return os.fspath(value)
    raise TypeError(f"cannot serialise {type(value).__name__}")


def render_report(report: Report, fmt: OutputFormat | str) -> None:
    """Render ``report``: the JSON document for ``json``; otherwise the verbatim text (if any) on
    stdout, then all tables, renderables and summary lines (on stderr when there was verbatim text)."""
    if str(getattr(fmt, "value", fmt)) == OutputFormat.json.value:
        emit_json(report.data)
        return
    if report.text:
        write(sys.stdout, report.text)
    stream = sys.stderr if report.text else sys.stdout
    if not report.renderables and not stream.isatty():
        # What render_table would print off a terminal, without creating a console: importing rich
        # costs ~25 ms of every piped run.
        write(stream, "".join([*map(plain_table, report.tables), *(line + "\n" for line in report.lines)]))
        return
    out = console(stderr=bool(report.text))
    for table in report.tables:
        render_table(table, out)
    for renderable in report.renderables:
        out.print()
        out.print(renderable)
    if report.renderables:
        out.print()
    for line in report.lines:
        out.print(line, markup=False)


def finish(report: Report, fmt: OutputFormat | str) -> NoReturn:
    """Render ``report`` and end the command: exit 2 when it carries :attr:`Report.errors`, else 0
    when ``report.ok``, else 1 (problems found)."""
    import typer

    render_report(report, fmt)
    for error in report.errors:
        write(sys.stderr, f"ar3cli: error: {error}\n")
    raise typer.Exit(EXIT_USAGE if report.errors else 0 if report.ok else 1)


def log(message: str) -> None:
    """A progress/log line on stderr (never on stdout, which may carry JSON)."""
    print(message, file=sys.stderr, flush=True)
