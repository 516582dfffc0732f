"""Progress on stderr for long loops: a bar on a terminal, a plain line every few seconds elsewhere.

Off a terminal (pre-commit, a CI log, ``2> log``) a live bar would be control characters, and no
output at all leaves a 170 s scan looking hung: there a line such as ``scanning: 120/1,095 files,
12.5 files/s, 10 s`` is printed every :data:`PLAIN_EVERY_S` seconds while the loop advances (a loop
done sooner prints nothing).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import Any

PLAIN_EVERY_S = 5.0
"""Seconds between two plain progress lines off a terminal (the first after as long)."""


class progress_bar:
    """``with progress_bar("sampling", total) as advance: advance(n)``; a plain line every few seconds
    off a terminal. With a ``unit`` (``"files"``) the bar also shows the rate (``12.5 files/s``)."""

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
            return self._plain()
        self.bar.start()
        task = self.bar.add_task(self.label, total=self.total, rate="")
        if not self.unit:
            return lambda done: self.bar.advance(task, done)

        def advance(done: int) -> None:
            self.bar.advance(task, done)
            speed = self.bar.tasks[0].speed
            self.bar.update(task, rate=f"{speed:.1f} {self.unit}/s" if speed else "")

        return advance

    def _plain(self) -> Callable[[int], None]:
        """``advance`` off a terminal: count, and print a line when :data:`PLAIN_EVERY_S` have passed."""
        from ar3cli.output.report import log

        started = time.monotonic()
        state = {"done": 0, "due": started + PLAIN_EVERY_S}
        unit = f" {self.unit}" if self.unit else ""

        def advance(done: int) -> None:
            state["done"] += done
            now = time.monotonic()
            if now < state["due"]:
                return
            state["due"] = now + PLAIN_EVERY_S
            elapsed = now - started
            rate = f", {state['done'] / elapsed:.1f}{unit}/s" if unit else ""
            log(f"{self.label}: {state['done']:,}/{self.total:,}{unit}{rate}, {elapsed:.0f} s")

        return advance

    def __exit__(self, *exc_info: object) -> None:
        if self.bar is not None:
            self.bar.stop()
