"""A fixer's own options, declared once, as fields of its options dataclass.

A fixer is one module (``fix/NAME_plan.py``, see docs/architecture.md): its options dataclass
marks each field the user sets with :func:`setting` (flags, help, bounds), and the commands layer
(:mod:`ar3cli.commands.fixer_options`) builds the ``fix-NAME`` command's typer options from them,
so no command module repeats them. Nothing here imports typer: the fix layer says *what* can be
set; how a command line is parsed stays in ``commands/``. Fields without :func:`setting` are the
plan's own state (derived values, created files) and never reach the command line.
"""

from __future__ import annotations

import typing
from dataclasses import MISSING, dataclass, field, fields
from typing import Any

SETTING_KEY = "ar3cli.setting"
"""The key of a dataclass field's ``metadata`` that holds its :class:`Setting`."""


@dataclass(frozen=True)
class Setting:
    """How the user sets one field: its flags, help and bounds."""

    flags: tuple[str, ...]
    """``("--samples", "-n")``; a switch with an off form is one ``"--verify/--no-verify"``; empty:
    the shared option of the field's name (``seed``: the ``--seed`` every sampling command takes)."""
    help: str | None = None
    metavar: str | None = None
    minimum: float | None = None
    maximum: float | None = None


@dataclass(frozen=True)
class SettingField:
    """One :func:`setting` field of an options dataclass, with its resolved type."""

    name: str
    annotation: Any
    default: Any
    """The field's default; :data:`dataclasses.MISSING` for a required option."""
    setting: Setting


def setting(*flags: str, help: str | None = None, default: Any = MISSING, metavar: str | None = None,
            minimum: float | None = None, maximum: float | None = None) -> Any:
    """A dataclass field the user sets with ``flags`` (no default: the option is required; no
    flags and no help: the shared option of the field's name)."""
    return field(default=default, metadata={SETTING_KEY: Setting(flags, help, metavar, minimum, maximum)})


def settings_of(options_type: type) -> list[SettingField]:
    """The :func:`setting` fields of ``options_type``, in declaration order (the ``--help`` order)."""
    hints = typing.get_type_hints(options_type)
    return [SettingField(item.name, hints[item.name], item.default, item.metadata[SETTING_KEY])
            for item in fields(options_type) if SETTING_KEY in item.metadata]


def require_positive(**values: float | None) -> None:
    """Refuse any given value that is not > 0, naming its option (``effort=...`` is ``--effort``)."""
    from ar3cli.errors import UserError

    for name, value in values.items():
        if value is not None and not value > 0:
            raise UserError(f"--{name.replace('_', '-')} {value}: must be positive")
