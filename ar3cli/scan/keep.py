"""Keep-list filters: which scanned files a training run should keep, in a small vocabulary.

Each ``--keep`` names one filter; several must all hold. Spaces and underscores count as hyphens
and case does not matter (``'no errors'`` is ``no-errors``):

========================  =======================================================================
``loads``                 the file loaded and its check finished (status clean or findings)
``clean``                 loads, and no finding at or above ``error`` (as lint-urdf's summary counts clean files)
``no-errors``             loads, and no error finding
``no-warnings``           loads, and no error or warning finding
``max-severity=LEVEL``    loads, and no finding above LEVEL (``info``, ``warning`` or ``error``)
``no-rule=CODES``         no finding of these codes or prefixes (comma-separated: ``P,J006``)
``max-findings=N``        at most N findings
``min-dof=N``             at least N degrees of freedom (``max-dof=N``: at most N)
========================  =======================================================================
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ar3cli.errors import UserError
from ar3cli.scan.record import LOADED, SEVERITIES, Row

VOCABULARY = ("loads", "clean", "no-errors", "no-warnings", "max-severity=LEVEL", "no-rule=CODES",
              "max-findings=N", "min-dof=N", "max-dof=N")


@dataclass(frozen=True)
class Keep:
    """One parsed filter: its normalised text and the test a row must pass."""

    text: str
    test: Callable[[Row], bool]


def _below(level: str) -> Callable[[Row], bool]:
    allowed = SEVERITIES[:SEVERITIES.index(level) + 1]
    return lambda row: row.status in LOADED and all(f["severity"] in allowed for f in row.findings)


def _number(name: str, value: str) -> int:
    try:
        number = int(value)
    except ValueError:
        raise UserError(f"--keep {name}=N expects a whole number, got {value!r}") from None
    if number < 0:
        raise UserError(f"--keep {name}=N expects a number >= 0, got {number}")
    return number


def parse_keep(text: str) -> Keep:
    """The filter ``text`` names; an unknown or malformed one is a one-line UserError (exit 2)."""
    normal = "-".join(text.strip().lower().replace("_", " ").split())
    name, _, value = (part.strip() for part in normal.partition("="))
    name = name.rstrip("-")
    value = value.lstrip("-")
    fixed = {"loads": lambda row: row.status in LOADED, "clean": lambda row: row.status == "clean",
             "no-errors": _below("warning"), "no-warnings": _below("info")}
    if name in fixed and not value:
        return Keep(name, fixed[name])
    if name == "max-severity" and value in SEVERITIES:
        return Keep(f"{name}={value}", _below(value))
    if name == "no-rule" and value:
        codes = tuple(code.strip().upper() for code in value.split(",") if code.strip())
        return Keep(f"{name}={','.join(codes)}", lambda row: not any(f["rule"].startswith(codes) for f in row.findings))
    if name in ("max-findings", "min-dof", "max-dof") and value:
        limit = _number(name, value)
        tests = {"max-findings": lambda row: len(row.findings) <= limit,
                 "min-dof": lambda row: row.dof is not None and row.dof >= limit,
                 "max-dof": lambda row: row.dof is not None and row.dof <= limit}
        return Keep(f"{name}={limit}", tests[name])
    raise UserError(f"unknown --keep filter {text!r}; use one of: {', '.join(VOCABULARY)}")


def kept(rows: list[Row], filters: list[Keep]) -> list[Row]:
    """The rows every filter keeps."""
    return [row for row in rows if all(keep.test(row) for keep in filters)]
