"""Bounded tables: a table, a tree or a list of details shows at most a few thousand rows and counts
the rest (``--format json`` keeps them all). A robot file decides how many links, joints and
meshes it has, so whatever lists them grows with the file; a message lists its names with
:func:`ar3cli.findings.listed` (at most :data:`~ar3cli.findings.LIST_ITEMS`), a table its rows
with :func:`capped`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeVar

TABLE_ROWS = 1_000
"""Rows a table shows at most (text and Markdown); the caption counts the rest."""

T = TypeVar("T")


def capped(rows: Sequence[T], most: int = TABLE_ROWS) -> tuple[Sequence[T], int]:
    """The first ``most`` of ``rows``, and how many were left out."""
    return (rows, 0) if len(rows) <= most else (rows[:most], len(rows) - most)


def left_out(count: int, noun: str = "rows") -> str:
    """The line that says a list was cut: ``(and 4,000 more rows: --format json lists them all)``."""
    return f"(and {count:,} more {noun}: --format json lists them all)"
