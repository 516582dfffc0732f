"""``[tool.ar3cli.lint]`` in the nearest ``pyproject.toml`` (walking up from the current directory).

Recognised keys (all optional)::

    [tool.ar3cli.lint]
    select = ["ALL"]                 # codes or prefixes
    ignore = ["G009"]
    fail-on = "warning"              # error | warning | info
    [tool.ar3cli.lint.per-file-ignores]
    "tests/fixtures/*.urdf" = ["I", "G008"]
    [tool.ar3cli.lint.severity]
    J008 = "error"

A typo in a key or a code is a usage error (exit 2), not silently ignored. Python 3.10 has no
``tomllib``; there ``tomli`` (the same parser, a dependency on 3.10 only) reads it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError
from ar3cli.findings import Severity, listed

KNOWN_KEYS = {"select", "ignore", "per-file-ignores", "severity", "fail-on"}


@dataclass
class LintConfig:
    """The validated configuration; ``path`` is the pyproject.toml it came from (None: none found)."""

    path: Path | None = None
    select: list[str] | None = None
    ignore: list[str] = field(default_factory=list)
    per_file_ignores: dict[str, list[str]] = field(default_factory=dict)
    severity: dict[str, Severity] = field(default_factory=dict)
    fail_on: Severity | None = None


def find_pyproject(start: Path) -> Path | None:
    """The nearest pyproject.toml in ``start`` or its ancestors."""
    for folder in [start, *start.parents]:
        candidate = folder / "pyproject.toml"
        if candidate.is_file():
            return candidate
    return None


def load_config(start: Path | None = None) -> LintConfig:
    """Read and validate ``[tool.ar3cli.lint]``; raises UserError (exit 2) on a bad configuration."""
    from ar3cli.lint.rules import REGISTRY, validate_patterns
    path = find_pyproject((start or Path.cwd()).resolve())
    if path is None:
        return LintConfig()
    from ar3cli.infra.safe_read import read_bytes

    try:  # capped and non-blocking, like every file ar3cli reads (the 50 MB default cap: pyprojects are KB)
        text = read_bytes(path, what="a pyproject.toml").decode("utf-8")
    except UnicodeDecodeError as exc:
        raise UserError(f"{path}: cannot read configuration: {exc}") from None
    if "ar3cli" not in text:  # another tool's pyproject: no need to parse it (or import tomllib)
        return LintConfig(path)
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10: tomli, a declared dependency there, is the same parser
        import tomli as tomllib
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise UserError(f"{path}: cannot read configuration: {exc}") from None
    except RecursionError:  # tomllib parses nested arrays recursively: 100,000 brackets are bad input, not a bug
        raise UserError(f"{path}: cannot read configuration: nested too deeply") from None
    table: dict[str, Any] = data.get("tool", {}).get("ar3cli", {}).get("lint", {})
    if not isinstance(table, dict):
        raise UserError(f"{path}: [tool.ar3cli.lint] must be a table")
    where = f"{path} [tool.ar3cli.lint]"
    unknown = set(table) - KNOWN_KEYS
    if unknown:
        raise UserError(f"{where}: unknown key(s) {listed(sorted(unknown))}; known: {', '.join(sorted(KNOWN_KEYS))}")
    try:
        config = LintConfig(path)
        if "select" in table:
            config.select = validate_patterns(_list(table["select"], "select"), f"{where} select")
        config.ignore = validate_patterns(_list(table.get("ignore", []), "ignore"), f"{where} ignore")
        for pattern, codes in dict(table.get("per-file-ignores", {})).items():
            config.per_file_ignores[str(pattern)] = validate_patterns(_list(codes, f"per-file-ignores {pattern!r}"),
                                                                      f"{where} per-file-ignores")
        for code, level in dict(table.get("severity", {})).items():
            if code.upper() not in REGISTRY:
                raise ValueError(f"severity: unknown rule code {code!r}")
            config.severity[code.upper()] = _severity(level, f"severity {code}")
        if "fail-on" in table:
            config.fail_on = _severity(table["fail-on"], "fail-on")
    except (ValueError, TypeError) as exc:
        raise UserError(f"{where}: {exc}" if str(path) not in str(exc) else str(exc)) from None
    return config


def _list(value: Any, key: str) -> list[str]:
    if isinstance(value, str):
        return [value]
    if not isinstance(value, list):
        raise ValueError(f"{key} must be a list of rule codes")
    return [str(v) for v in value]


def _severity(value: Any, key: str) -> Severity:
    try:
        return Severity(str(value).lower())
    except ValueError:
        raise ValueError(f"{key} must be error, warning or info, got {value!r}") from None
