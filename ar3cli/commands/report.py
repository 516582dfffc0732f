"""``ar3cli report``: one self-contained HTML page per robot.

Features never import each other, so this command module is where the page's data is gathered:
it calls each feature the way its own command does (info, lint-urdf, render, sample-collisions,
fk-verify) and hands the plain results (their JSON documents, summary lines, PNG bytes) to
:mod:`ar3cli.output.html`, which only renders. The JSON documents on the page are built by the
same functions as those commands' ``--format json``, so the numbers are equal by construction.
A section that cannot be computed (no collision geometry, a pybullet crash) says why on the page.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer

from ar3cli.commands.options import (
    FollowSymlinksOption,
    FormatOption,
    RobotPathArgument,
    SeedOption,
    TimeoutOption,
    samples_option,
)
from ar3cli.commands.robot_options import RobotSource, robot_input
from ar3cli.errors import UserError
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.output.formats import finish
from ar3cli.output.report import Report, log

T = TypeVar("T")
VIEWS = (("front", 0.0, -10.0), ("side", 90.0, -10.0), ("top", 0.0, -89.0))
"""(name, camera yaw, camera pitch) of the three pictures, each drawn with the visual and the collision geometry."""
PICTURE_SIZE = (360, 300)
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
    format: FormatOption = "text",
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
) -> None:
    """Write one self-contained HTML page about a robot: summary, kinematic tree, pictures from three
    sides (visual and collision, contacts at home in red), lint findings with their source lines
    and fix commands, the self-collision heat map, torque margins and fk-verify's verdict.

    The page works offline and loads nothing (inline CSS, JS and pictures). Its data island holds the
    JSON documents of info --torques, lint-urdf, sample-collisions and fk-verify for the same
    --samples and --seed.
    """
    from ar3cli.commands.lint_report import lint_document
    from ar3cli.infra.atomic import atomic_write, check_writable
    from ar3cli.output.html import robot_page

    output = check_writable(output, follow_symlinks)
    data: dict[str, Any] = {"settings": {"samples": samples, "seed": seed,
                                         "described": f"{samples} samples, seed {seed}"}, "skipped": {},
                            "cross_check": None}
    lines: dict[str, list[str]] = {}
    data["lint"], linted = lint_document(path, source)
    model = source.load(path)
    data["info"], lines["info"], lines["torques"] = _limited_info(model, path, samples, seed, data["skipped"])
    pictures = _pictures(model, lines.setdefault("pictures", []))
    data["renders"] = [{key: value for key, value in p.items() if key != "png"} for p in pictures]
    data["collisions"], lines["collisions"] = _attempt(lambda: _collisions(model, samples, seed),
                                                       "collisions", data["skipped"])
    data["fk"], lines["fk"] = _attempt(lambda: _fk(model, path, samples, seed), "fk", data["skipped"])
    data["cross_check"], lines["cross_check"] = _attempt(lambda: _cross_check(model, path, samples, seed),
                                                         "cross_check", data["skipped"])
    context = {"lines": lines, **linted.context(linted.findings)}
    document = robot_page(data, context, pictures).encode("utf-8")
    atomic_write(output, document)
    summary = data["lint"]["summary"]
    finish(Report(data={"path": str(output), "bytes": len(document), "lint": summary, "skipped": data["skipped"]},
                  lines=[f"wrote {output} ({len(document) / 1024:.0f} KB): {summary['error']} errors, "
                         f"{summary['warning']} warnings, {summary['info']} info"]
                  + [f"not on the page: {key}: {why}" for key, why in data["skipped"].items()]), format)


def _attempt(work: Callable[[], tuple[T, list[str]]], key: str, skipped: dict[str, str]) -> tuple[T | None, list[str]]:
    """Run one section's work; a UserError (nothing to check, pybullet crashed) leaves it out with its reason."""
    try:
        return work()
    except UserError as exc:
        skipped[key] = exc.message
        log(f"report: {key} left out: {exc.message}")
        return None, []


def _limited_info(model, path: Path, samples: int, seed: int, skipped: dict[str, str]) -> tuple[dict, list[str], list[str]]:
    """:func:`_info` in a child with the limits of every child (a file built to make the summary
    take hours or gigabytes is one line); what it left out is added to ``skipped``."""
    from ar3cli.infra.isolation import run_limited

    def work() -> tuple[tuple[dict, list[str], list[str]], dict[str, str]]:
        left_out: dict[str, str] = {}
        return _info(model, samples, seed, left_out), left_out

    made, left_out = run_limited(work, str(path), "summarising it")
    skipped.update(left_out)
    return made


def _info(model, samples: int, seed: int, skipped: dict[str, str]) -> tuple[dict, list[str], list[str]]:
    """``info --torques --samples N --seed S --format json``'s document, its summary and torque lines."""
    from ar3cli.info.presentation import report, summary_lines, torque_lines
    from ar3cli.info.summary import summarize
    from ar3cli.info.torques import gravity_torques
    from ar3cli.kinematics.fk import urdf_link_frames

    summary = summarize(model, lambda m: {link: f[0] for link, f in urdf_link_frames(m, {}, 1).items()})
    torques, _ = _attempt(lambda: (gravity_torques(model, samples, seed), []), "torques", skipped)
    document = report(summary, tree=False, torques=torques).data
    return document, summary_lines(summary), torque_lines(torques) if torques is not None else []


def _pictures(model, notes: list[str]) -> list[dict[str, Any]]:
    """Three sides, visual then collision geometry (render's own drawing: contacts at home in red); each
    geometry's three sides are drawn in one pybullet child."""
    import tempfile

    from ar3cli.pictures.draw import draw_views

    pictures = []
    with tempfile.TemporaryDirectory(prefix="ar3cli-report-") as folder:
        for geometry in ("visual", "collision"):
            views = [(Path(folder) / f"{geometry}-{side}.png", yaw, pitch) for side, yaw, pitch in VIEWS]
            try:
                drawn: list = draw_views(model, views, None, *PICTURE_SIZE, show_collision=geometry == "collision",
                                         warn=notes.append)
            except UserError as exc:
                drawn = [exc] * len(views)
            for (side, _yaw, _pitch), (target, _, _), result in zip(VIEWS, views, drawn):
                entry: dict[str, Any] = {"side": side, "geometry": geometry}
                if isinstance(result, UserError):
                    entry["error"] = result.message
                else:
                    entry.update(result.to_dict(), png=target.read_bytes())
                    del entry["path"]
                pictures.append(entry)
                if entry.get("error") and geometry == "visual":
                    break  # the same reason for the other sides
    return pictures


def _cross_check(model, path: Path, samples: int, seed: int) -> tuple[dict | None, list[str]]:
    """``cross-check --format json``'s document (with ``passed`` and its ``lines``) where MuJoCo is
    installed (the ``mujoco`` extra); None, and the page says how to get it, where it is not."""
    import importlib.util

    if importlib.util.find_spec("mujoco") is None:
        return None, []
    from ar3cli.cross_check.run import cross_check

    made = cross_check(model, path, samples, seed, announce=False)
    return {**made.data, "passed": made.ok, "lines": made.lines}, made.lines


def _collisions(model, samples: int, seed: int) -> tuple[dict, list[str]]:
    """``sample-collisions --samples N --seed S --format json``'s document and summary lines."""
    from ar3cli.collisions.matrix_report import matrix_report
    from ar3cli.collisions.run import sample_matrix

    made = matrix_report(model, sample_matrix(model, samples, seed, None, 0.95), "text")
    return made.data, made.lines


def _fk(model, path: Path, samples: int, seed: int) -> tuple[dict, list[str]]:
    """``fk-verify --samples N --seed S --format json``'s document and its verdict lines."""
    from ar3cli.commands.fk_verify import DEFAULT_TOLERANCE_M
    from ar3cli.kinematics.verify import Tolerance, fk_report, measure

    drawn, comparison = measure(model, samples, seed, announce=False)
    made = fk_report(model, path, samples, seed, Tolerance(DEFAULT_TOLERANCE_M, 1e-6, scaled=True), drawn,
                     comparison, None)
    return made.data, made.lines
