"""The two models being compared, how their elements correspond, and what counts as a change:
what every section comparer (structure, joints, dynamics, limits, geometry) reads."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ar3cli.robot_diff.locate import Locator
from ar3cli.robot_diff.match import Matching
from ar3cli.robot_diff.records import Change
from ar3cli.robot_diff.tolerance import Tolerance
from ar3cli.urdf.model import Model


@dataclass
class Pair:
    old: Model
    new: Model
    matching: Matching
    tolerance: Tolerance
    new_locator: Locator
    old_locator: Locator

    def change(self, section: str, element: str, what: str, old: Any = "", new: Any = "",
               amount: float | None = None, unit: str = "", at: Any = None, old_at: Any = None) -> Change:
        """A :class:`Change` located at NEW's element ``at`` (or, for what only OLD has, at OLD's ``old_at``)."""
        from ar3cli.robot_diff.records import show

        if at is not None or old_at is None:
            file, line = self.new_locator.locate(at)
        else:
            file, line = self.old_locator.locate(old_at)
        return Change(section, element, what, old if isinstance(old, str) else show(old),
                      new if isinstance(new, str) else show(new), amount, unit, file, line)
