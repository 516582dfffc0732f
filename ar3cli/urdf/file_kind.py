"""What a robot file is, by its name: the one test every layer shares, kept apart from the xacro
machinery so that loading a plain ``.urdf`` does not import it (``urdf.xacro_expand`` and its safe
evaluator cost a start-up that a one-file lint or a 1,000-sample collision check feels)."""

from __future__ import annotations

from pathlib import Path


def is_xacro(path: Path) -> bool:
    """True for ``robot.xacro`` and ``robot.urdf.xacro``."""
    return path.suffix.lower() == ".xacro"
