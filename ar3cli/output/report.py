"""The one output layer: every command hands it a :class:`Report` and a format.

Text goes to a rich console on a terminal (tables with colour, without it when ``NO_COLOR`` is
set), fitted to its width (``COLUMNS`` wins): long cells wrap inside their column. Off a terminal
(pipes, CI logs, pre-commit) tables are plain ASCII, one line per row (what grep and log viewers
want), unless ``COLUMNS`` is set: then they fit that width the same way; rich is not even imported
unless the report holds rich renderables. ``Report.wide`` (lint-urdf's ``--wide``) asks for one
line per row everywhere. Names from robot files (paths, links, joints) reach text output through
:func:`printable`, so a control character in them (a terminal escape sequence, ``\\r``, a bidi
override) is shown as ``\\x1b``, never obeyed by the terminal; JSON keeps the exact strings. JSON goes to stdout alone, so
``ar3cli ... --format json | jq`` always works; progress and logs go to stderr. Failing to write
the output (a full disk) is a one-line :class:`~ar3cli.errors.UserError`.
Which formats a user can choose, and which reports each renders, is the registry of
:mod:`ar3cli.output.formats`; every format ends here, writing the Report it made as text or JSON.
"""

from __future__ import annotations

import enum
import json
import math
import os
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, NoReturn, TextIO

from ar3cli.errors import EXIT_USAGE, UserError


class OutputFormat(str, enum.Enum):
    """How a Report is written (:func:`finish`): text (tables and lines, or the verbatim text) or
    json (``Report.data`` alone on stdout). The ``--format`` a user chooses is a format of the
    registry (:mod:`ar3cli.output.formats`), and each writes its Report in one of these two ways."""

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
    wide: bool = False
    """Text tables one line per row whatever the width (``--wide``): for grep and wide log viewers."""
    markdown: Callable[[], str] | None = None
    """The report as Markdown (``--format markdown``), for a command whose report has that form."""
    annotations: Callable[[], str] | None = None
    """GitHub workflow annotations (``--format github``), for a command whose report has them."""


def console(stderr: bool = False):
    """A rich Console for stdout (or stderr): no colour and ASCII boxes when not a terminal."""
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    plain = bool(os.environ.get("NO_COLOR")) or not stream.isatty()
    return Console(file=stream, no_color=plain, highlight=False, soft_wrap=not stream.isatty(),
                   width=None if stream.isatty() else 160, safe_box=True,
                   force_terminal=False if plain else None)


_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069]")
"""Characters a terminal or a log viewer obeys instead of showing: C0 controls but tab and
newline (ESC starts escape sequences, CR rewrites the line, BS erases), DEL, C1 controls (CSI
0x9b), and the bidirectional marks, embeddings, overrides and isolates (the "Trojan Source" ones)."""


def printable(text: str) -> str:
    """``text`` with every :data:`_CONTROL` character written as ``\\xNN`` (``\\uNNNN`` above
    0xff): what every text, github and markdown output does with names that come from robot files."""
    if text.isprintable():  # the usual case, one C-level scan
        return text
    return _CONTROL.sub(lambda match: f"\\x{ord(match.group()):02x}" if ord(match.group()) < 0x100
                        else f"\\u{ord(match.group()):04x}", text)


def format_cell(value: Any) -> str:
    """Numbers compactly (4 significant digits, scientific when tiny/huge); None as a dash; text
    through :func:`printable`."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        if value == 0 or not math.isfinite(value):
            return str(value)
        magnitude = abs(value)
        return f"{value:.4g}" if 1e-3 <= magnitude < 1e5 else f"{value:.3e}"
    return printable(str(value))


def table_width(stream: TextIO, wide: bool = False) -> int | None:
    """How many columns a text table on ``stream`` may take; None for no limit (one line per row).

    ``wide`` (``--wide``): no limit. Else ``COLUMNS`` when set (at least 20, so a stray tiny value
    cannot fold every word), else the terminal's width, else (a pipe, a file, a CI log) no limit.
    """
    if wide:
        return None
    columns = os.environ.get("COLUMNS", "").strip()
    if columns.isdigit() and int(columns) >= 20:
        return int(columns)
    if stream.isatty():
        import shutil

        return shutil.get_terminal_size().columns
    return None


MIN_WRAPPED_WIDTH = 12
"""A wrapped column narrower than this reads as a word list: the table is printed as blocks."""


def plain_table(table: Table, width: int | None = None) -> str:
    """An ASCII table: one line per row when ``width`` is None, else fitted into ``width`` columns.

    Fitting keeps the short columns whole (location, code, severity, numbers: what grep looks for,
    on each row's first line) and wraps the long ones (message, hint) inside their cells; when the
    long ones would get fewer than :data:`MIN_WRAPPED_WIDTH` columns, each row is a block instead
    (:func:`plain_blocks`). Rich's layout engine takes ~0.6 ms per row (0.4 s for pybullet_data's
    659 lint findings); this plain formatter is what pipes, CI logs and ``--wide`` get.
    """
    rows = [[format_cell(value).replace("\n", " ") for value in row] for row in table.rows]
    natural = [max([len(column), *(len(row[index]) for row in rows)]) for index, column in enumerate(table.columns)]
    widths = natural if width is None else _fitted_widths(table, natural, rows, width - 3 * len(natural) - 1)
    if widths is None:
        return plain_blocks(table, rows, width or 80)
    numeric = [column in table.numeric_columns for column in table.columns]

    def lines(cells: list[str]) -> list[str]:
        if widths is natural:
            parts = [[cell] for cell in cells]
        else:
            parts = [_wrap(cell, size) for cell, size in zip(cells, widths)]
        height = max(len(part) for part in parts)
        return ["| " + " | ".join((part[at] if at < len(part) else "").rjust(size) if right
                                  else (part[at] if at < len(part) else "").ljust(size)
                                  for part, size, right in zip(parts, widths, numeric)) + " |"
                for at in range(height)]

    rule = "+" + "+".join("-" * (size + 2) for size in widths) + "+"
    out = [printable(table.title)] if table.title else []
    out += [rule, *lines(list(table.columns)), rule, *(line for row in rows for line in lines(row)), rule]
    if table.caption:
        out.append(printable(table.caption))
    return "\n".join(out) + "\n"


def _wrap(text: str, size: int) -> list[str]:
    import textwrap

    return textwrap.wrap(text, size, break_on_hyphens=False) or [""]


def _fitted_widths(table: Table, natural: list[int], rows: list[list[str]], room: int) -> list[int] | None:
    """Column widths that fit ``room`` characters of cells: the long text columns capped at one
    common width (the widest shrink first), the others whole; None when that cap is too small."""
    if sum(natural) <= room:
        return natural
    flexible = [index for index, column in enumerate(table.columns)
                if column not in table.nowrap_columns and column not in table.numeric_columns
                and column != table.status_column and natural[index] > 16]
    left = room - sum(size for index, size in enumerate(natural) if index not in flexible)
    count = len(flexible)
    for size in sorted(natural[index] for index in flexible):
        if size * count > left:
            break
        left -= size
        count -= 1
    if not count or left // count < MIN_WRAPPED_WIDTH:
        return None
    cap = left // count
    return [min(size, cap) if index in flexible else size for index, size in enumerate(natural)]


def plain_blocks(table: Table, rows: list[list[str]], width: int) -> str:
    """One block per row for a narrow width: the short cells on one line, each long cell below it,
    indented and wrapped (as :func:`render_rows_as_blocks` does on a terminal)."""
    short = _short_columns(table, rows)
    out = [printable(table.title)] if table.title else []
    for row in rows:
        out.append("  ".join(row[index] for index in short if row[index]))
        for index, column in enumerate(table.columns):
            if index not in short and row[index]:
                out += ["    " + line for line in _wrap(f"{column}: {row[index]}", max(width - 4, MIN_WRAPPED_WIDTH))]
    if table.caption:
        out.append(printable(table.caption))
    return "\n".join(out) + "\n"


def _short_columns(table: Table, rows: list[list[str]]) -> list[int]:
    """The columns a block puts on its first line: never wrapped, or at most 16 characters."""
    return [index for index, column in enumerate(table.columns)
            if column in table.nowrap_columns or column in table.numeric_columns or column == table.status_column
            or max((len(row[index]) for row in rows), default=0) <= 16]


NARROW_TERMINAL = 100
"""Below this many columns a wide table would split words and numbers: rows are printed as blocks."""


def render_rows_as_blocks(table: Table, out) -> None:
    """One block per row for narrow terminals: the short cells on one line, each long cell indented
    below it and wrapped by the terminal (as ruff prints diagnostics)."""
    from rich.padding import Padding
    from rich.text import Text

    rows = [[format_cell(value) for value in row] for row in table.rows]
    short = _short_columns(table, rows)
    if table.title:
        out.print(Text(printable(table.title), style="bold"))
    for row in rows:
        out.print(Text("  ".join(row[index] for index in short if row[index])))
        for index, column in enumerate(table.columns):
            if index not in short and row[index]:
                out.print(Padding(Text(f"{column}: {row[index]}"), (0, 0, 0, 4)))


def render_table(table: Table, out=None, wide: bool = False) -> None:
    """Print one :class:`Table`: through rich on a terminal (as blocks when it is narrow), as
    :func:`plain_table` elsewhere and with ``wide``."""
    out = out or console()
    if wide or not out.is_terminal:
        out.file.write(plain_table(table, table_width(out.file, wide)))
        out.file.flush()
        return
    if out.width < NARROW_TERMINAL and len(table.columns) > 3:
        render_rows_as_blocks(table, out)
        return
    from rich import box
    from rich.table import Table as RichTable
    from rich.text import Text

    plain = out.no_color
    rich_table = RichTable(title=printable(table.title) or None, caption=printable(table.caption) or None,
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
    if not report.renderables and (report.wide or not stream.isatty()):
        # What render_table would print off a terminal, without creating a console: importing rich
        # costs ~25 ms of every piped run.
        width = table_width(stream, report.wide)
        write(stream, "".join([*(plain_table(table, width) for table in report.tables),
                               *(printable(line) + "\n" for line in report.lines)]))
        return
    out = console(stderr=bool(report.text))
    for table in report.tables:
        render_table(table, out, report.wide)
    for renderable in report.renderables:
        out.print()
        out.print(renderable)
    if report.renderables:
        out.print()
    for line in report.lines:
        out.print(printable(line), markup=False)


def finish(report: Report, fmt: OutputFormat | str) -> NoReturn:
    """Write ``report`` as text or json (``fmt``) and end the command: exit 2 when it carries :attr:`Report.errors`, else 0
    when ``report.ok``, else 1 (problems found)."""
    import typer

    render_report(report, fmt)
    for error in report.errors:
        write(sys.stderr, f"ar3cli: error: {printable(error)}\n")
    raise typer.Exit(EXIT_USAGE if report.errors else 0 if report.ok else 1)


def log(message: str) -> None:
    """A progress/log line on stderr (never on stdout, which may carry JSON)."""
    print(printable(message), file=sys.stderr, flush=True)
