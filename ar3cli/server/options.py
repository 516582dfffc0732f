"""How the language server checks robots: the command line's options and the editor's settings.

The command line (``ar3cli server --package-path ... --target ...``, parsed by ``commands/server.py``)
says what lint-urdf's command line says: packages, xacro arguments and policy, target engines. The
lint configuration is ``[tool.ar3cli.lint]`` of the workspace's ``pyproject.toml`` (found from the
workspace folder up, as lint-urdf finds it from the current folder). The editor may set, in
``initializationOptions`` or under ``ar3cli`` in its workspace settings:

- ``sim`` (bool): also run the PyBullet rules (``lint-urdf --sim``) when a file is saved;
- ``debounceMs`` (int): how long typing must pause before a changed buffer is checked.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ar3cli.analysis.settings import AnalysisSettings

DEFAULT_DEBOUNCE_MS = 150
"""A pause in typing this long starts a check. People type 5 to 8 characters a second (125 to 200 ms
apart): a check starts in the first real pause, and a burst of keystrokes costs one check."""
MAX_DEBOUNCE_MS = 10_000


@dataclass(frozen=True)
class ServerOptions:
    """What ``ar3cli server``'s command line and the editor's settings ask for."""

    packages: Mapping[str, Path] = field(default_factory=dict)
    xacro_args: Mapping[str, str] = field(default_factory=dict)
    targets: tuple[str, ...] | None = None
    """``--target`` (None: lint's default engines)."""
    sim: bool = False
    """Run the PyBullet rules on save (``--sim``, or the editor's ``sim`` setting)."""
    debounce_ms: int = DEFAULT_DEBOUNCE_MS
    use_config: bool = True
    """Read ``[tool.ar3cli.lint]`` (``--no-config``: every rule, lint's defaults)."""

    def with_client_settings(self, given: Any) -> tuple[ServerOptions, list[str]]:
        """These options with the editor's ``sim`` and ``debounceMs`` (from ``initializationOptions``
        or a ``workspace/didChangeConfiguration`` payload, bare or under ``ar3cli``), and one line
        per value that was refused (the editor's log says why a setting did nothing)."""
        if isinstance(given, Mapping) and isinstance(given.get("ar3cli"), Mapping):
            given = given["ar3cli"]
        if not isinstance(given, Mapping):
            return self, []
        changed, refused = {}, []
        if "sim" in given:
            if isinstance(given["sim"], bool):
                changed["sim"] = given["sim"]
            else:
                refused.append(f"setting sim must be true or false, got {given['sim']!r}")
        if "debounceMs" in given:
            value = given["debounceMs"]
            if isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= MAX_DEBOUNCE_MS:
                changed["debounce_ms"] = value
            else:
                refused.append(f"setting debounceMs must be a whole number of milliseconds from 0 to "
                               f"{MAX_DEBOUNCE_MS}, got {value!r}")
        return replace(self, **changed), refused

    def analysis_settings(self, folder: Path) -> tuple[AnalysisSettings, str | None]:
        """The settings every document is checked with: these options and the configuration found
        from ``folder`` up, and the configuration's one-line error when it is broken (then every rule
        runs, as with ``--no-config``, and the editor is told why)."""
        from ar3cli.analysis.settings import AnalysisSettings
        from ar3cli.errors import UserError
        from ar3cli.lint.config import LintConfig, load_config

        error = None
        config = LintConfig()
        if self.use_config:
            try:
                config = load_config(folder)
            except UserError as exc:
                error = exc.message
        return AnalysisSettings(packages=dict(self.packages), xacro_args=dict(self.xacro_args), config=config,
                                targets=self.targets), error
