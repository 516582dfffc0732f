"""One install-check row: what was checked, how it went, and what to run when it did not go well.

Its own module so that both the environment checks (:mod:`ar3cli.install_check.checks`) and the capability
checks (:mod:`ar3cli.install_check.capabilities`) build rows without importing each other.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass


@dataclass(frozen=True)
class Check:
    """``status`` is ``ok``, ``warn``, ``fail`` or ``info``; ``hint`` the exact command to run when not ok."""

    name: str
    status: str
    detail: str
    hint: str = ""

    def to_dict(self) -> dict[str, str]:
        return asdict(self)
