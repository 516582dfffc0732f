"""Read a YAML input (DH tables, MoveIt's joint_limits.yaml): every problem is one plain line.

The file is read by the capped, non-blocking reader (:func:`ar3cli.infra.safe_read.read_bytes`: a
FIFO or ``/dev/zero`` is refused, not waited on or read forever), and the document's nesting is
capped before it is parsed, so 100,000 opening brackets are a one-line error rather than a
RecursionError deep inside the YAML parser.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ar3cli.errors import UserError

MAX_YAML_BYTES = 4 * 1024 * 1024
"""Largest YAML input read: MoveIt's joint_limits.yaml and DH tables are a few KB (the largest in
example-robot-data's neighbours, a 60-joint limits file, is ~6 KB)."""
MAX_YAML_DEPTH = 64
"""Deepest nesting accepted (collections inside collections); the inputs ar3cli reads nest 2 to 4 deep."""


def load_yaml(path: Path, what: str) -> Any:
    """The parsed document of ``path``; ``what`` names the file in messages ("DH file", ...).

    Missing file, folder, FIFO or device, a file over :data:`MAX_YAML_BYTES`, unreadable or
    non-UTF-8 bytes, nesting deeper than :data:`MAX_YAML_DEPTH` and YAML syntax errors (with the
    line) become a :class:`UserError`; ``yaml.safe_load`` never builds Python objects from tags.
    """
    import yaml

    from ar3cli.infra.safe_read import read_bytes

    path = Path(path)
    try:
        data = read_bytes(path, limit=MAX_YAML_BYTES, what=f"a {what}")
    except UserError as exc:
        if exc.message.endswith(": no such file"):
            raise UserError(f"{path}: {what} not found") from None
        raise
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise UserError(f"{path}: {what} is not UTF-8 text") from None
    try:
        _check_depth(yaml, text, path, what)
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark is not None else str(path)
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise UserError(f"{where}: {what} is not valid YAML: {problem}") from None
    except RecursionError:  # a construct deep in a way the event scan does not count: still bad input
        raise UserError(f"{path}: {what} is nested too deeply") from None


def _check_depth(yaml, text: str, path: Path, what: str) -> None:
    """Refuse a document nested deeper than :data:`MAX_YAML_DEPTH`, scanning its events (no recursion)."""
    depth = 0
    for event in yaml.parse(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
        if isinstance(event, yaml.CollectionStartEvent):
            depth += 1
            if depth > MAX_YAML_DEPTH:
                line = event.start_mark.line + 1 if event.start_mark is not None else 0
                raise UserError(f"{path}{f':{line}' if line else ''}: {what} is nested more than {MAX_YAML_DEPTH} "
                                "levels deep; is this really a " + what + "?")
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1
