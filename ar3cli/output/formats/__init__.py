"""The format registry: ``--format NAME`` -> the renderer that turns a command's report into output.

Each format is one module of this package that calls :func:`register` with a :class:`Format`: its
name, a phrase for ``--help``, and one renderer per *kind* of report it can render (what ruff's
``OutputFormat`` and flake8's report plugins are). A command says which kinds its report is; its
``--format`` choices and their help come from here (:func:`choices`, :func:`help_text`), and it hands
its report, its kinds and the chosen name to :func:`finish_as`, which dispatches (a plain Report:
:func:`finish`). Adding a format is one new
module here plus its tests: :func:`load` imports every module of the package.

The kinds:

- :data:`REPORT`: a :class:`~ar3cli.output.report.Report` (tables, lines, a JSON document); every command.
- :data:`MARKDOWN`: a Report whose command can also write it as Markdown (:attr:`Report.markdown`).
- :data:`ANNOTATIONS`: a Report with Markdown and GitHub workflow annotations (:attr:`Report.annotations`).
- :data:`LINT`: lint findings, a :class:`~ar3cli.output.lint_report.LintReport`.

The renderer of a kind returns the :class:`Report` to write; the format's ``stream`` says how
:func:`ar3cli.output.report.finish` writes it: ``json`` (``Report.data`` alone on stdout) or ``text``.
"""

from __future__ import annotations

import enum
import functools
import importlib
import pkgutil
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, NoReturn

from ar3cli.output.report import OutputFormat, Report
from ar3cli.output.report import finish as write_and_end

REPORT = "report"
MARKDOWN = "markdown"
ANNOTATIONS = "annotations"
LINT = "lint"


@dataclass(frozen=True)
class Format:
    """One output format: ``renderers`` maps each kind of report it renders to the function that
    turns such a report into the :class:`Report` to write; ``order`` places it in ``--help`` lists."""

    name: str
    help: str
    renderers: Mapping[str, Callable[[Any], Report]]
    stream: OutputFormat = OutputFormat.text
    order: int = 100

    @property
    def kinds(self) -> frozenset[str]:
        return frozenset(self.renderers)


_FORMATS: dict[str, Format] = {}


def register(fmt: Format) -> Format:
    """Add ``fmt`` to the registry (a format module calls this once); a second format of the same
    name replaces the first (tests register dummies)."""
    OutputFormat(fmt.stream)  # text or json, else ValueError
    _FORMATS[fmt.name] = fmt
    choices.cache_clear()
    return fmt


def unregister(name: str) -> None:
    """Remove a format (for tests that register a dummy)."""
    _FORMATS.pop(name, None)
    choices.cache_clear()


@functools.cache
def load() -> None:
    """Import every format module of this package once (each registers itself)."""
    for module in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{module.name}")


def formats(kinds: Iterable[str] | None = None) -> list[Format]:
    """The registered formats that render any of ``kinds`` (all without), in ``--help`` order."""
    load()
    wanted = None if kinds is None else set(kinds)
    return sorted((fmt for fmt in _FORMATS.values() if wanted is None or fmt.kinds & wanted),
                  key=lambda fmt: (fmt.order, fmt.name))


def names(kinds: Iterable[str] | None = None) -> list[str]:
    """The names of :func:`formats`."""
    return [fmt.name for fmt in formats(kinds)]


@functools.cache
def choices(kinds: tuple[str, ...], enum_name: str = "Format") -> type[enum.Enum]:
    """A ``str`` Enum of the formats that render ``kinds``: the type of a command's ``--format``
    (the same class for the same arguments, so ``format is choices(...).text`` works)."""
    return enum.Enum(enum_name, [(name, name) for name in names(kinds)], type=str, module=__name__)


def help_text(kinds: Iterable[str]) -> str:
    """``--format``'s help: every format of ``kinds`` with its phrase."""
    parts = [f"{fmt.name} ({fmt.help})" for fmt in formats(kinds)]
    listed = parts[0] if len(parts) == 1 else f"{', '.join(parts[:-1])} or {parts[-1]}"
    return f"Output format: {listed}."


def get(name: Any) -> Format:
    """The format called ``name`` (a string or a choices member)."""
    load()
    key = str(getattr(name, "value", name))
    try:
        return _FORMATS[key]
    except KeyError:
        raise ValueError(f"unknown output format {key!r} (known: {', '.join(names())})") from None


def render(payload: Any, kinds: Iterable[str], name: Any) -> tuple[Report, OutputFormat]:
    """``payload``, a report of ``kinds`` (the most specific first), rendered in the format
    ``name`` by its renderer of the first of those kinds it has: the Report to write, and how to
    write it (``json`` or ``text``)."""
    fmt = get(name)
    kinds = tuple(kinds)
    kind = next((kind for kind in kinds if kind in fmt.renderers), None)
    if kind is None:
        raise ValueError(f"format {fmt.name!r} does not render {' or '.join(kinds)} reports")
    return fmt.renderers[kind](payload), OutputFormat(fmt.stream)


def finish(report: Report, name: Any = "text") -> NoReturn:
    """A plain Report in the format ``name`` (a command's ``--format``), and the end of the command."""
    finish_as(report, (REPORT,), name)


def finish_as(payload: Any, kinds: Iterable[str], name: Any) -> NoReturn:
    """Render ``payload`` (see :func:`render`) and end the command: exit 2 when the Report carries
    errors, else 0 when it is ok, else 1 (:func:`ar3cli.output.report.finish`)."""
    report, stream = render(payload, kinds, name)
    write_and_end(report, stream)
