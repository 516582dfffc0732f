"""A progress bar on stderr for long loops, shown only on a terminal (pipes and CI get nothing)."""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any


class progress_bar:
    """``with progress_bar("sampling", total) as advance: advance(n)``; a no-op off a terminal.
    With a ``unit`` (``"files"``) the bar also shows the rate (``12.5 files/s``)."""

    def __init__(self, label: str, total: int, unit: str = "") -> None:
        self.label = label
        self.total = total
        self.unit = unit
        self.bar: Any = None
        if sys.stderr.isatty():
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

            from ar3cli.output.report import console

            rate = [TextColumn("{task.fields[rate]}")] if unit else []
            self.bar = Progress(label, BarColumn(), MofNCompleteColumn(), *rate, TimeRemainingColumn(),
                                console=console(stderr=True), transient=True)

    def __enter__(self) -> Callable[[int], None]:
        if self.bar is None:
            return lambda done: None
        self.bar.start()
        task = self.bar.add_task(self.label, total=self.total, rate="")
        if not self.unit:
            return lambda done: self.bar.advance(task, done)

        def advance(done: int) -> None:
            self.bar.advance(task, done)
            speed = self.bar.tasks[0].speed
            self.bar.update(task, rate=f"{speed:.1f} {self.unit}/s" if speed else "")

        return advance

    def __exit__(self, *exc_info: object) -> None:
        if self.bar is not None:
            self.bar.stop()
