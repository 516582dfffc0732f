"""A progress bar on stderr for long loops, shown only on a terminal (pipes and CI get nothing)."""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any


class progress_bar:
    """``with progress_bar("sampling", total) as advance: advance(n)``; a no-op off a terminal."""

    def __init__(self, label: str, total: int) -> None:
        self.label = label
        self.total = total
        self.bar: Any = None
        if sys.stderr.isatty():
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeRemainingColumn

            from ar3cli.output.report import console

            self.bar = Progress(label, BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                                console=console(stderr=True), transient=True)

    def __enter__(self) -> Callable[[int], None]:
        if self.bar is None:
            return lambda done: None
        self.bar.start()
        task = self.bar.add_task(self.label, total=self.total)
        return lambda done: self.bar.advance(task, done)

    def __exit__(self, *exc_info: object) -> None:
        if self.bar is not None:
            self.bar.stop()
