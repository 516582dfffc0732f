"""Expand ``.xacro`` files in-process with the ``xacro`` package.

No ROS installation is needed: ``$(find NAME)`` is answered by the same
:class:`~ar3cli.urdf.packages.PackageResolver` that resolves ``package://`` URIs, and ``$(arg ...)``
values come from ``--xacro-arg NAME:=VALUE``. Whatever goes wrong inside xacro becomes a one-line
:class:`~ar3cli.errors.UserError` naming the file.
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

from ar3cli.errors import UserError
from ar3cli.output.report import log
from ar3cli.urdf.packages import PackageResolver


def is_xacro(path: Path) -> bool:
    """True for ``robot.xacro`` and ``robot.urdf.xacro``."""
    return path.suffix.lower() == ".xacro"


def parse_xacro_args(items: list[str] | None) -> dict[str, str]:
    """Turn repeated ``NAME:=VALUE`` options into a mapping; raises ValueError when malformed."""
    mapping: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition(":=")
        if not sep or not name.strip():
            raise ValueError(f"--xacro-arg expects NAME:=VALUE, got {item!r}")
        mapping[name.strip()] = value
    return mapping


def expand(path: Path, args: dict[str, str], resolver: PackageResolver) -> bytes:
    """Return the expanded URDF as UTF-8 bytes.

    xacro keeps module-level state and prints diagnostics with ``print``; both are contained
    here: its ``$(find)`` hook is swapped for ours for the duration of the call, and anything it
    prints is kept off stdout (stdout may be carrying JSON).
    """
    import xacro
    from xacro import substitution_args

    not_found: list[UserError] = []  # xacro wraps what the hook raises; keep ours to re-raise it as is

    def find_package(name: str) -> str:
        folder, tried = resolver.find_package(name)
        if folder is None:
            not_found.append(UserError(f"{path}: $(find {name}): package not found; tried {', '.join(tried)}; "
                                       f"pass --package-path {name}=DIR"))
            raise not_found[-1]
        return str(folder)

    original_find = substitution_args._eval_find
    substitution_args._eval_find = find_package
    chatter = io.StringIO()
    try:
        with contextlib.redirect_stdout(chatter), contextlib.redirect_stderr(chatter):
            document = xacro.process_file(str(path), mappings=dict(args))
            text = document.toprettyxml(indent="  ")
    except UserError:
        raise
    except Exception as exc:  # noqa: BLE001 - xacro raises many types: XacroException, NameError, XML errors...
        if not_found:
            raise not_found[-1] from None
        if isinstance(exc, RecursionError):
            raise UserError(f"{path}: xacro error: macro recursion too deep") from None
        raise UserError(f"{path}: xacro error: {_one_line(exc)}") from None
    finally:
        substitution_args._eval_find = original_find
    for line in chatter.getvalue().splitlines():
        if line.strip() and not line.startswith("when processing file:"):
            log(f"ar3cli: note: {path}: xacro says: {line.strip()}")
    return text.encode("utf-8")


def _one_line(exc: BaseException) -> str:
    inner = getattr(exc, "exc", None)  # XacroException wraps the real error and repeats its text
    if isinstance(inner, OSError) and inner.filename:
        message = f"cannot read {inner.filename}: {inner.strerror or inner}"
    else:
        message = " ".join(str(exc).split()) or type(exc).__name__
    location = _xacro_location()
    return f"{message} (in {location})" if location else message


def _xacro_location() -> str:
    """The innermost file xacro was reading when it failed, when xacro recorded one."""
    try:
        import xacro

        stack = [entry for entry in getattr(xacro, "filestack", None) or [] if entry]
    except Exception:  # noqa: BLE001 - defensive: xacro internals differ between versions
        return ""
    return str(stack[-1]) if stack else ""
