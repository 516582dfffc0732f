"""How a robot is read and checked: the settings one :class:`~ar3cli.analysis.robot.RobotAnalysis`
answers every question with.

The front-end parses its own options and configuration into this value, once: the command line's
``--package-path`` and ``--xacro-arg`` (:func:`ar3cli.urdf.loading.read_specs`, which also makes
``--xacro trusted`` / ``--xacro-env`` the process's xacro policy: safe mode unless asked),
``[tool.ar3cli.lint]`` (:func:`ar3cli.lint.config.load_config`, from the folder the front-end
chooses: the current one for a command, the workspace for an editor), ``--target``, and the
sampling of the simulated sections (``--samples``, ``--seed``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ar3cli.findings import Severity
from ar3cli.lint.config import LintConfig

if TYPE_CHECKING:
    from ar3cli.lint.engine import LintOptions
    from ar3cli.urdf.srdf_read import DisabledPairs

DEFAULT_SAMPLES = 100
"""Random configurations of the simulated sections (collision matrix, torques, FK, cross-check):
a page, not a study (sample-collisions defaults to 10000)."""


@dataclass(frozen=True)
class AnalysisSettings:
    """Everything an analysis depends on besides the robot's own files.

    ``packages`` and ``xacro_args`` are parsed (package -> folder, name -> value); ``config`` is the
    lint configuration (empty: every rule, as ``lint-urdf --no-config``); ``targets`` the engines the
    robot is meant for (``--target``; its T rules run); ``srdf_disabled`` the link pairs a MoveIt
    SRDF disables (not reported as colliding at home by the simulated lint); ``samples`` and ``seed``
    the random configurations of every sampling section.
    """

    packages: Mapping[str, Path] = field(default_factory=dict)
    xacro_args: Mapping[str, str] = field(default_factory=dict)
    config: LintConfig = field(default_factory=LintConfig)
    targets: tuple[str, ...] | None = None
    """None: lint's default targets (pybullet and ros)."""
    srdf_disabled: DisabledPairs | None = None
    samples: int = DEFAULT_SAMPLES
    seed: int = 0

    @property
    def fail_on(self) -> Severity:
        """The severity from which a finding fails (the configuration's ``fail-on``, else error)."""
        return self.config.fail_on or Severity.ERROR

    def lint_options(self, sim: bool) -> LintOptions:
        """The linter's options for these settings, as lint-urdf builds them from the same
        configuration (``sim``: the PyBullet rules too, as ``--sim``)."""
        from ar3cli.lint.engine import LintOptions

        options = LintOptions.configured(self.config, sim=sim, package_paths=self.packages,
                                         xacro_args=self.xacro_args, srdf_disabled=self.srdf_disabled, sources=True)
        if self.targets is not None:
            options.targets = self.targets
        return options
