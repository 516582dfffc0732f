"""Read a YAML input (DH tables, MoveIt's joint_limits.yaml): every problem is one plain line."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ar3cli.errors import UserError


def load_yaml(path: Path, what: str) -> Any:
    """The parsed document of ``path``; ``what`` names the file in messages ("DH file", ...).

    Missing file, folder, unreadable or non-UTF-8 bytes and YAML syntax errors (with the line)
    become a :class:`UserError`; ``yaml.safe_load`` never builds Python objects from tags.
    """
    import yaml

    path = Path(path)
    if path.is_dir():
        raise UserError(f"{path}: is a directory, expected a {what}")
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UserError(f"{path}: {what} not found") from None
    except UnicodeDecodeError:
        raise UserError(f"{path}: {what} is not UTF-8 text") from None
    except OSError as exc:
        raise UserError(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark is not None else str(path)
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise UserError(f"{where}: {what} is not valid YAML: {problem}") from None
