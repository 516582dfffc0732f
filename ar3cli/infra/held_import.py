"""Import a library that swallows interrupts, with SIGINT and SIGTERM held back until it is done.

trimesh wraps its optional imports in ``except BaseException`` (144 places in 4.x). A Ctrl-C, or a
SIGTERM (which ar3cli turns into KeyboardInterrupt, see :mod:`ar3cli.infra.shutdown`), that arrives
while trimesh is being imported is raised inside one of those blocks and swallowed: the run went on
and wrote its result (review of 2026-11-26: ``fix-collision`` got SIGTERM 0.5-0.8 s in and ended
with exit 0, its URDF and part files written). Held back, the signal is delivered once the import
is done, where it stops the run as it should.
"""

from __future__ import annotations

import importlib
import sys
from types import ModuleType

from ar3cli.infra.process_pool import interrupts_deferred


def import_holding_interrupts(name: str) -> ModuleType:
    """``import name``; a SIGINT or SIGTERM during the import takes effect when it is done."""
    module = sys.modules.get(name)
    if module is not None:
        return module
    with interrupts_deferred():
        return importlib.import_module(name)
