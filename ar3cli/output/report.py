"""The one output layer: every command hands it a :class:`Report` and a format.

Text goes to a rich console on a terminal (tables with colour, without it when ``NO_COLOR`` is
set), fitted to its width (``COLUMNS`` wins): long cells wrap inside their column. Off a terminal
(pipes, CI logs, pre-commit) tables are plain ASCII fitted to ``COLUMNS``, or to
:data:`PIPED_WIDTH` (100) when it is not set, and lint findings are one line each
(:mod:`ar3cli.output.formats.text`); rich is not even imported unless the report holds rich
renderables. ``Report.wide`` (lint-urdf's ``--wide``) asks for one line per row everywhere. Names
from robot files, file names and the environment reach text output through :func:`printable`
(:func:`ar3cli.output.escape.terminal`), so a control character in them (a newline, a terminal
escape sequence, ``\\r``, a bidi override) is shown as ``\\x1b``, never obeyed; JSON keeps the exact
strings. Tables show at most :data:`~ar3cli.output.lists.TABLE_ROWS` rows. JSON goes to stdout
alone, so ``ar3cli ... --format json | jq`` always works; progress and logs go to stderr. Failing
to write the output (a full disk) is a one-line :class:`~ar3cli.errors.UserError`.
Which formats a user can choose, and which reports each renders, is the registry of
:mod:`ar3cli.output.formats`; every format ends here, writing the Report it made as text or JSON.
"""

from __future__ import annotations

import enum
import json
import math
import os
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, NoReturn, TextIO

from ar3cli.errors import EXIT_USAGE, UserError
from ar3cli.output.escape import terminal


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
class Tree:
    """A tree of labels (``info``'s kinematic tree), drawn by the output layer: with rich's guides on
    a terminal, indented ASCII elsewhere; labels through :func:`printable`. At most
    :data:`~ar3cli.output.lists.TABLE_ROWS` nodes are drawn, and no deeper than :data:`TREE_DEPTH`
    levels of indentation (a chain of 4,000 links would otherwise print 32 MB of guides)."""

    label: str
    children: list[Tree] = field(default_factory=list)
    style: str = ""


TREE_DEPTH = 32
"""Levels a tree is indented at most; deeper nodes are drawn at that level with ``[depth N]``."""


def tree_lines(tree: Tree) -> list[tuple[int, str, str]]:
    """(indentation level, label, style) of each node drawn, depth first, iteratively (a chain of
    thousands of links is fine); the last line counts the nodes left out."""
    from ar3cli.output.lists import TABLE_ROWS, left_out

    out: list[tuple[int, str, str]] = []
    stack = [(tree, 0)]
    left = 0
    while stack:
        node, depth = stack.pop()
        if len(out) >= TABLE_ROWS:
            left += 1
        else:
            label = printable(node.label) if depth <= TREE_DEPTH else f"[depth {depth}] {printable(node.label)}"
            out.append((min(depth, TREE_DEPTH), label, node.style))
        stack += [(child, depth + 1) for child in reversed(node.children)]
    if left:
        out.append((1, left_out(left, "nodes"), ""))
    return out


def plain_tree(tree: Tree) -> str:
    """:func:`tree_lines` as indented ASCII (two spaces a level, ``- `` before each node but the root)."""
    return "".join(("  " * (depth - 1) + "- " if depth else "") + label + "\n" for depth, label, _ in tree_lines(tree))


def rich_tree(tree: Tree) -> Any:
    """:func:`tree_lines` as a rich Tree (guides on a terminal)."""
    from rich.text import Text
    from rich.tree import Tree as RichTree

    lines = tree_lines(tree)
    top = RichTree(Text(lines[0][1], style=lines[0][2]), guide_style="dim")
    parents = [top]
    for depth, label, style in lines[1:]:
        del parents[depth:]
        parents.append(parents[-1].add(Text(label, style=style)))
    return top


@dataclass
class Report:
    """What a command found: ``data`` is the JSON document, ``tables``/``lines`` its text form."""

    data: dict[str, Any]
    tables: list[Table] = field(default_factory=list)
    lines: list[str] = field(default_factory=list)
    ok: bool = True
    renderables: list[Any] = field(default_factory=list)
    """Extra renderables, printed after the tables in text mode: a :class:`Tree`, or a rich
    renderable (the collision heat map) whose command escaped its names with :func:`printable`."""
    text: str = ""
    """A verbatim payload for stdout (a unified diff, workflow annotations, Markdown). When set, text
    mode writes it to stdout alone and moves tables and lines to stderr, so the payload can be piped."""
    quoted: bool = False
    """``text`` quotes a robot file (a fixer's unified diff): written through
    :func:`~ar3cli.output.escape.terminal_lines`, and inside GitHub Actions between
    ``::stop-commands::`` and its end, so a line of the file cannot be read as a workflow command."""
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


printable = terminal
"""What every text output does with names, paths and messages: :func:`ar3cli.output.escape.terminal`
(one line, control characters shown as ``\\xNN``)."""


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


PIPED_WIDTH = 100
"""Columns a table takes off a terminal (a pipe, a CI log, pre-commit) when ``COLUMNS`` is not set:
rows of 200-330 characters are hard to read in a log viewer; wider cells wrap inside their column."""


def _columns_set() -> int | None:
    columns = os.environ.get("COLUMNS", "").strip()
    return int(columns) if columns.isdigit() and int(columns) >= 20 else None


def table_width(stream: TextIO, wide: bool = False) -> int | None:
    """How many columns a text table on ``stream`` may take; None for no limit (one line per row).

    ``wide`` (``--wide``): no limit. Else ``COLUMNS`` when set (at least 20, so a stray tiny value
    cannot fold every word), else the terminal's width, else (a pipe, a file, a CI log) :data:`PIPED_WIDTH`.
    """
    if wide:
        return None
    columns = _columns_set()
    if columns is not None:
        return columns
    if stream.isatty():
        import shutil

        return shutil.get_terminal_size().columns
    return PIPED_WIDTH


def piped(stream: TextIO) -> bool:
    """``stream`` is not a terminal and ``COLUMNS`` does not say how wide its reader is: pre-commit,
    a CI log, ``| grep``. Lint findings are then one line each (:mod:`ar3cli.output.formats.text`)."""
    return _columns_set() is None and not stream.isatty()


MIN_WRAPPED_WIDTH = 12
"""A wrapped column narrower than this reads as a word list: the table is printed as blocks."""


def plain_table(table: Table, width: int | None = None, blocks: bool = True) -> str:
    """An ASCII table: one line per row when ``width`` is None, else fitted into ``width`` columns.

    Fitting keeps the short columns whole (location, code, severity, numbers: what grep looks for,
    on each row's first line) and wraps the long ones (message, hint) inside their cells; when the
    table cannot fit without splitting words and numbers, each row is a block instead
    (:func:`plain_blocks`: the short cells on one line, the long ones below), or, with ``blocks``
    False (a pipe's default width, which is no reader's limit), the table as narrow as it goes
    without splitting them. Rich's layout engine takes ~0.6 ms per row (0.4 s for pybullet_data's
    659 lint findings); this plain formatter is what pipes, CI logs and ``--wide`` get.
    """
    rows = [[format_cell(value) for value in row] for row in table.rows]
    natural = [max([len(column), *(len(row[index]) for row in rows)]) for index, column in enumerate(table.columns)]
    room = None if width is None else width - 3 * len(natural) - 1
    widths = natural if room is None else _fitted_widths(table, natural, rows, room, narrowest=not blocks)
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


def piped_table(table: Table, stream: TextIO, wide: bool = False) -> str:
    """:func:`plain_table` as ``stream`` takes it off a terminal: the width of :func:`table_width`;
    blocks only for a width someone chose (``COLUMNS``), not for a pipe's default."""
    return plain_table(table, table_width(stream, wide), blocks=not piped(stream))


def _wrap(text: str, size: int) -> list[str]:
    import textwrap

    return textwrap.wrap(text, size, break_on_hyphens=False) or [""]


def _fitted_widths(table: Table, natural: list[int], rows: list[list[str]], room: int,
                   narrowest: bool = False) -> list[int] | None:
    """Column widths that fit ``room`` characters of cells: the long text columns capped at one
    common width (the widest shrink first), never below their longest word (up to
    :data:`LONGEST_WORD`: a joint name is not split) nor :data:`MIN_WRAPPED_WIDTH`; the others
    whole, their headers wrapped when that is still too wide. None when even that does not fit,
    or with ``narrowest`` those smallest widths."""
    if sum(natural) <= room:
        return natural
    flexible = [index for index, column in enumerate(table.columns)
                if column not in table.nowrap_columns and column not in table.numeric_columns
                and column != table.status_column and natural[index] > 16]
    floors = {index: min(natural[index], max(MIN_WRAPPED_WIDTH, min(LONGEST_WORD, max(
        len(word) for text in [table.columns[index], *(row[index] for row in rows)] for word in [*text.split(), ""]))))
        for index in flexible}
    whole = list(natural)
    if sum(natural[index] if index not in flexible else floors[index] for index in range(len(natural))) > room:
        # still too wide: the headers of the other columns may wrap too ("declared effort" over "20 N m")
        whole = [max([len(row[index]) for row in rows] + [len(word) for word in column.split()])
                 if index not in flexible else size for index, (column, size) in enumerate(zip(table.columns, natural))]
    fixed = sum(size for index, size in enumerate(whole) if index not in flexible)

    def width(cap: int, index: int) -> int:
        return max(floors[index], min(natural[index], cap))

    def total(cap: int) -> int:
        return fixed + sum(width(cap, index) for index in flexible)

    if total(0) > room:
        return [width(0, index) if index in flexible else size for index, size in enumerate(whole)] if narrowest else None
    low, high = 0, max((natural[index] for index in flexible), default=0)
    while low < high:  # the largest common cap that fits
        middle = (low + high + 1) // 2
        low, high = (middle, high) if total(middle) <= room else (low, middle - 1)
    return [width(low, index) if index in flexible else size for index, size in enumerate(whole)]


LONGEST_WORD = 30
"""A word up to this long keeps its column wide enough to stay whole; longer ones (paths) may break."""


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


def bounded(table: Table) -> Table:
    """``table`` with at most :data:`~ar3cli.output.lists.TABLE_ROWS` rows, its caption counting the
    rows left out (the JSON document keeps them)."""
    from dataclasses import replace

    from ar3cli.output.lists import capped, left_out

    rows, left = capped(table.rows)
    if not left:
        return table
    return replace(table, rows=list(rows), caption=" ".join(filter(None, [table.caption, left_out(left)])))


def render_table(table: Table, out=None, wide: bool = False) -> None:
    """Print one :class:`Table`: through rich on a terminal (as blocks when it is narrow), as
    :func:`plain_table` elsewhere and with ``wide``; at most
    :data:`~ar3cli.output.lists.TABLE_ROWS` rows (:func:`bounded`)."""
    out = out or console()
    table = bounded(table)
    if wide or not out.is_terminal:
        out.file.write(piped_table(table, out.file, wide))
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
        write(sys.stdout, quoted(report.text) if report.quoted else report.text)
    stream = sys.stderr if report.text else sys.stdout
    trees = all(isinstance(renderable, Tree) for renderable in report.renderables)
    if trees and (report.wide or not stream.isatty()):
        # What render_table would print off a terminal, without creating a console: importing rich
        # costs ~25 ms of every piped run.
        write(stream, "".join([*(piped_table(bounded(table), stream, report.wide) for table in report.tables),
                               *("\n" + plain_tree(tree) for tree in report.renderables),
                               "\n" if report.renderables else "",
                               *(printable(line) + "\n" for line in report.lines)]))
        return
    out = console(stderr=bool(report.text))
    for table in report.tables:
        render_table(table, out, report.wide)
    for renderable in report.renderables:
        out.print()
        out.print(rich_tree(renderable) if isinstance(renderable, Tree) else renderable)
    if report.renderables:
        out.print()
    for line in report.lines:
        out.print(printable(line), markup=False)


def quoted(text: str) -> str:
    """A robot file's lines for stdout (:attr:`Report.quoted`): each line escaped; inside GitHub
    Actions (``GITHUB_ACTIONS=true``) between ``::stop-commands::TOKEN`` and ``::TOKEN::`` with a
    random token, GitHub's own way to print text that must not run workflow commands (a file line
    `` ::error::x`` would otherwise be one: the runner ignores leading spaces)."""
    from ar3cli.output.escape import terminal_lines

    text = terminal_lines(text)
    if os.environ.get("GITHUB_ACTIONS") != "true" or "::" not in text:
        return text
    import secrets

    token = secrets.token_hex(16)
    return f"::stop-commands::{token}\n{text}{'' if text.endswith(chr(10)) else chr(10)}::{token}::\n"


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
