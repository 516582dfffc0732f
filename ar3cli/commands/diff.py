"""``ar3cli diff OLD NEW``: what a change to a robot description does to the robot, compared
semantically (structure, end-effector kinematics, dynamics, limits, geometry, lint findings).

The work is in :mod:`ar3cli.robot_diff`; this module reads the sides (paths, ``REV:path``, or every
robot file ``--changed-since`` selects), lints both models and hands the findings and ar3cli's own
forward kinematics to the diff (feature packages do not import each other).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Optional

import typer

from ar3cli.commands.options import (
    PackagePathOption,
    SeedOption,
    TimeoutOption,
    XacroArgOption,
    finite_float,
    format_option,
    samples_option,
)
from ar3cli.errors import UserError
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.output.formats import ANNOTATIONS, MARKDOWN, REPORT, finish_as

if TYPE_CHECKING:
    from ar3cli.robot_diff.git_source import SideSpec

KINDS = (ANNOTATIONS, MARKDOWN, REPORT)
"""A diff is a table report with a Markdown form and workflow annotations."""

SidesArgument = Annotated[Optional[list[str]], typer.Argument(
    metavar="OLD NEW", show_default=False,
    help="Two robot files, each a path or REV:path (the file as git revision REV holds it, read without a "
         "checkout; REV:path is a revision whenever REV resolves in git, ./REV:path a file). With --old-rev: NEW "
         "alone. With --changed-since: the files or folders to search (default: the current folder).")]
OldRevOption = Annotated[Optional[str], typer.Option(
    "--old-rev", metavar="REV", show_default=False,
    help="OLD is NEW's file as git revision REV holds it (the same as OLD = REV:NEW, spelled out).")]
ChangedSinceOption = Annotated[Optional[str], typer.Option(
    "--changed-since", metavar="REF", show_default=False,
    help="Compare every robot file that changed since the git ref REF (or uses a changed file, as lint-urdf "
         "--changed-since selects them) with its version at REF.")]
SamplesOption = Annotated[int, samples_option("Random configurations of the shared joints, on top of the home pose.",
                                              most=100_000)]
ToleranceOption = Annotated[float, typer.Option(
    "--tolerance", click_type=finite_float(),
    help="What counts as a change: metres for lengths, radians for angles, and a fraction of the "
         "larger value for masses, inertias, efforts and velocities.")]
ToleranceMOption = Annotated[Optional[float], typer.Option(
    "--tolerance-m", show_default=False, click_type=finite_float(), help="Length tolerance (m); default: --tolerance.")]
ToleranceRadOption = Annotated[Optional[float], typer.Option(
    "--tolerance-rad", show_default=False, click_type=finite_float(),
    help="Angle tolerance (rad); default: --tolerance.")]
FormatOption = format_option(KINDS, "DiffFormat")


def diff(
    sides: SidesArgument = None,
    old_rev: OldRevOption = None,
    changed_since: ChangedSinceOption = None,
    samples: SamplesOption = 100,
    seed: SeedOption = 0,
    tolerance: ToleranceOption = 1e-9,
    tolerance_m: ToleranceMOption = None,
    tolerance_rad: ToleranceRadOption = None,
    package_path: PackagePathOption = None,
    xacro_arg: XacroArgOption = None,
    format: FormatOption = "text",
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
) -> None:
    """Show what NEW changes about OLD's robot: links and joints added, removed or renamed, how far
    every end effector moved (home pose and random configurations) and which joint moved it, masses
    and inertias, limits, geometry, and the lint findings that came or went.

    Semantic, not textual: comments, attribute order, whitespace, number spelling and equal
    rotations written differently are no change. Exit 0 no change, 1 changes beyond the tolerance,
    2 usage errors.
    """
    from ar3cli.robot_diff.tolerance import Tolerance

    values = [tolerance, tolerance_m, tolerance_rad]
    if not all(value is None or value >= 0 for value in values):
        raise UserError("--tolerance, --tolerance-m and --tolerance-rad must be zero or positive numbers")
    limits = Tolerance(tolerance if tolerance_m is None else tolerance_m,
                       tolerance if tolerance_rad is None else tolerance_rad, tolerance)
    pairs = _pairs(sides or [], old_rev, changed_since, package_path, xacro_arg)
    from ar3cli.infra.isolation import run_limited

    diffs, errors = [], []
    for old_spec, new_spec in pairs:
        try:  # each pair in a child with the limits of every child: a file built to stall is one line
            diffs.append(run_limited(lambda old_spec=old_spec, new_spec=new_spec: _compare(
                old_spec, new_spec, limits, samples, seed, package_path, xacro_arg), new_spec.label, "comparing it"))
        except UserError as exc:
            if len(pairs) == 1:
                raise
            errors.append(exc.message)
    _finish(diffs, errors, limits, samples, seed, format)


def _pairs(sides: list[str], old_rev: str | None, changed_since: str | None, package_path,
           xacro_arg) -> list[tuple[SideSpec | None, SideSpec]]:
    """(OLD or None for a file REF does not have, NEW) of every robot to compare; how a ``REV:path``
    argument was read is said on stderr (a revision whenever REV resolves in git)."""
    from ar3cli.output.report import log
    from ar3cli.robot_diff.git_source import SideSpec, read_spec

    if old_rev is not None and changed_since is not None:
        raise UserError("--old-rev and --changed-since both choose OLD: give one")
    if old_rev is not None:
        if len(sides) != 1:
            raise UserError(f"with --old-rev, diff takes one robot file, NEW (got {len(sides)})")
        new, note = read_spec(sides[0])
        if note:
            log(f"ar3cli: note: NEW {note}")
        return [(SideSpec.at(old_rev, new.path), new)]
    if changed_since is None:
        if len(sides) != 2:
            raise UserError(f"diff takes two robot files, OLD and NEW (got {len(sides)}); or --old-rev REV NEW, or "
                            "--changed-since REF")
        read = [read_spec(side) for side in sides]
        for which, (_, note) in zip(("OLD", "NEW"), read):
            if note:
                log(f"ar3cli: note: {which} {note}")
        return [(read[0][0], read[1][0])]
    from pathlib import Path

    from ar3cli.lint.changed import select_changed
    from ar3cli.lint.engine import display_path
    from ar3cli.urdf.loading import read_specs

    packages, arguments = read_specs(package_path, xacro_arg)
    selection = select_changed([Path(side) for side in sides or ["."]], changed_since, packages, arguments)
    parts = {used for users in selection.dependents.values() for used in users}  # compared through their users
    return [(_at_ref(changed_since, display_path(path)), SideSpec(display_path(path), display_path(path)))
            for path in selection.files if display_path(path) not in parts]


def _at_ref(ref: str, path: str) -> SideSpec | None:
    """``path`` as REF holds it when REF has the file, else None (the file was added since): a
    revision by construction, never a file that happens to be named ``REF:path``."""
    from ar3cli.robot_diff.git_source import SideSpec, exists_at, repository_path, resolve_commit

    root, inside = repository_path(path)
    return SideSpec.at(ref, path) if exists_at(root, resolve_commit(root, ref), inside) else None


def _compare(old_spec: SideSpec | None, new_spec: SideSpec, limits, samples: int, seed: int, package_path,
             xacro_arg):
    """Load both sides (a revision from its temporary copy), lint them and diff them."""
    from ar3cli.kinematics import fk
    from ar3cli.robot_diff.compare import compare_models
    from ar3cli.robot_diff.git_source import open_side
    from ar3cli.robot_diff.records import Change, RobotDiff
    from ar3cli.urdf.loading import load_with_specs

    if old_spec is None:
        label = new_spec.label
        return RobotDiff("(none)", label, [Change("structure", "robot file", "added", new=label, file=label)])
    with open_side(old_spec) as old_side, open_side(new_spec) as new_side:
        models = []
        for side in (old_side, new_side):
            try:
                models.append(load_with_specs(side.path, package_path, xacro_arg))
            except UserError as exc:
                raise UserError(side.relabel(exc.message)) from None
        findings = tuple(_lint(model, side.label) for model, side in zip(models, (old_side, new_side)))
        return compare_models(models[0], models[1], old_side.label, new_side.label, fk=fk, tolerance=limits,
                              samples=samples, seed=seed, findings=findings,  # type: ignore[arg-type]
                              show_old=old_side.show, show_new=new_side.show)


def _lint(model, shown: str) -> list:
    """The static lint findings of a loaded model (every rule, default severities)."""
    from ar3cli.lint.engine import LintOptions, lint_model

    options = LintOptions()
    return lint_model(model, shown, options.rules(), options).findings


def _finish(diffs, errors: list[str], limits, samples: int, seed: int, fmt) -> None:
    """The diff's report, with its Markdown and annotation forms, in the format ``fmt``."""
    from ar3cli.robot_diff.render import annotations, markdown, report

    result = report(diffs, limits, samples, seed, errors)
    result.markdown = lambda: markdown(diffs, samples, seed)
    result.annotations = lambda: annotations(diffs)
    finish_as(result, KINDS, fmt)
