"""``ar3cli report``: one self-contained HTML page per robot.

A thin adapter: the options become one :class:`~ar3cli.analysis.robot.RobotAnalysis`,
:func:`~ar3cli.analysis.report.robot_report` gathers every section from it (the same documents as
info, lint-urdf, render, sample-collisions, fk-verify and cross-check print with ``--format json``),
and :func:`~ar3cli.output.html.robot_page` renders them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ar3cli.commands.lint_options import TargetOption, parse_targets
from ar3cli.commands.options import (
    FollowSymlinksOption,
    FormatOption,
    RobotPathArgument,
    SeedOption,
    TimeoutOption,
    samples_option,
)
from ar3cli.commands.robot_options import RobotSource, robot_input
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.output.formats import finish
from ar3cli.output.report import Report

SamplesOption = Annotated[int, samples_option(
    "Random configurations for the collision matrix, the torque check and fk-verify (small by default: "
    "a page, not a study; sample-collisions defaults to 10000).", most=100_000)]


@robot_input
def report(
    path: RobotPathArgument,
    source: RobotSource,
    output: Annotated[Path, typer.Option("--output", "-o", metavar="FILE.html", dir_okay=False,
                                         help="The HTML file to write.", show_default=False)],
    samples: SamplesOption = 100,
    seed: SeedOption = 0,
    follow_symlinks: FollowSymlinksOption = False,
    target: TargetOption = None,
    format: FormatOption = "text",
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
) -> None:
    """Write one self-contained HTML page about a robot: one verdict built from every section, then
    each section collapsed to its own verdict and count: summary, kinematic tree, pictures from three
    sides (visual and collision, contacts at home in red), lint findings (static and PyBullet rules,
    as lint-urdf --sim) with their source lines and fix commands, the self-collision heat map,
    torque margins, fk-verify and cross-check.

    The page works offline and loads nothing (inline CSS, JS and pictures). Its data island holds the
    JSON documents of info --torques, lint-urdf --sim, sample-collisions, fk-verify and cross-check
    for the same --samples and --seed, and the verdict. Exit 0 once the page is written, whatever
    the verdict (use lint-urdf as a gate).
    """
    from ar3cli.analysis.report import robot_report
    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.analysis.settings import AnalysisSettings
    from ar3cli.commands.finding_context import finding_context
    from ar3cli.infra.atomic import atomic_write, check_writable
    from ar3cli.lint.config import load_config
    from ar3cli.output.html import robot_page

    output = check_writable(output, follow_symlinks)
    packages, xacro_args = source.specs()
    settings = AnalysisSettings(packages=packages, xacro_args=xacro_args, config=load_config(),
                                targets=parse_targets(target) if target else None, samples=samples, seed=seed)
    made = robot_report(RobotAnalysis.load(path, settings))
    document = robot_page(made.data, {"lines": made.lines, **finding_context(made.findings, made.sources)},
                          made.pictures).encode("utf-8")
    atomic_write(output, document)
    summary, skipped, verdict = made.data["lint"]["summary"], made.data["skipped"], made.data["verdict"]
    finish(Report(data={"path": str(output), "bytes": len(document), "verdict": verdict, "lint": summary,
                        "skipped": skipped},
                  lines=[f"wrote {output} ({len(document) / 1024:.0f} KB): {verdict['headline']}"]
                  + [f"{check['title']}: {check['status']}: {check['line']}" for check in verdict["checks"]
                     if check["status"] != "pass"]
                  + [f"note: {note}" for note in verdict["notes"]]), format)
