"""``ar3cli info``: the first look at a robot (tree, DOF, limits, mass, size, meshes), no pybullet;
``--torques`` adds the gravity torque check (pybullet, in a forked child), ``--png`` a picture of the tree."""

from pathlib import Path
from typing import Annotated, Optional

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

TorquesOption = Annotated[bool, typer.Option(
    "--torques", help="Check that every actuated joint can hold the robot up: the largest gravity torque it needs "
                      "(PyBullet's inverse dynamics, base fixed, at rest) over the home pose, the limit "
                      "configurations and --samples uniform configurations, against its declared limit effort.")]
SamplesOption = Annotated[int, samples_option("With --torques: uniform random configurations to check on top of "
                                              "the home and limit configurations.", most=1_000_000)]
PngOption = Annotated[Optional[Path], typer.Option(
    "--png", metavar="OUT.png", dir_okay=False, show_default=False,
    help="Draw the kinematic tree as a picture: link boxes, joints (name and type) on the edges.")]


@robot_input
def info(
    path: RobotPathArgument,
    source: RobotSource,
    torques: TorquesOption = False,
    samples: SamplesOption = 200,
    seed: SeedOption = 0,
    png: PngOption = None,
    follow_symlinks: FollowSymlinksOption = False,
    format: FormatOption = "text",
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
) -> None:
    """Show what a robot is made of: kinematic tree, DOF and joint limits, masses and centre of mass,
    bounding box, meshes, end effectors.

    Static and fast (no PyBullet): the centre of mass and the bounding box are computed at the
    zero configuration (every joint at 0) with the URDF's own forward kinematics. --torques adds
    the gravity torque check (PyBullet), --png a picture of the kinematic tree.
    """
    from ar3cli.info.presentation import report
    from ar3cli.infra.isolation import run_limited

    if png is not None:
        png = _check_png(png, follow_symlinks)
    source.specs()  # this run's xacro policy, set before the child starts (a bad spec: one line here)
    # the file is read and summed up in a child with the limits of every child (time, memory)
    summary, check, library = run_limited(lambda: _summarize(path, source, torques, samples, seed), str(path),
                                          "summarising it")
    if library is not None:  # macros for an entry file to include: nothing to summarise here
        from ar3cli.info.presentation import library_report

        finish(library_report(path, library), format)
    if png is not None:
        from ar3cli.info.tree_png import tree_png
        from ar3cli.infra.atomic import atomic_write

        atomic_write(png, tree_png(summary))
    finish(report(summary, tree=format == "text", torques=check,
                  picture=None if png is None else str(png)), format)


def _summarize(path: Path, source: RobotSource, torques: bool, samples: int, seed: int):
    """(the summary, the torque check or None, None) of the robot file, as ``info`` shows them; for a
    xacro library (:mod:`ar3cli.urdf.macro_library`), which makes no robot: (None, None, the library)."""
    from ar3cli.info.summary import summarize
    from ar3cli.kinematics.fk import urdf_link_frames
    from ar3cli.urdf.macro_library import macro_library

    model = source.load(path)
    library = macro_library(model)
    if library is not None:
        return None, None, library
    summary = summarize(model, lambda model: {link: frames[0] for link, frames in urdf_link_frames(model, {}, 1).items()})
    if not torques:
        return summary, None, None
    from ar3cli.info.torques import gravity_torques

    return summary, gravity_torques(model, samples, seed), None


def _check_png(png: Path, follow_symlinks: bool) -> Path:
    """Refuse an unusable --png before any work; the file to write (a link's target with --follow-symlinks)."""
    from ar3cli.infra.atomic import check_writable

    if png.suffix.lower() != ".png":
        raise UserError(f"--png {png}: the file name must end in .png")
    return check_writable(png, follow_symlinks)
