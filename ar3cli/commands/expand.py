"""``ar3cli expand``: the URDF ar3cli checks for a robot file, with its package resolution and xacro safe mode."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.commands.options import FollowSymlinksOption, FormatOption, RobotPathArgument
from ar3cli.commands.robot_options import RobotSource, robot_input
from ar3cli.output.formats import finish
from ar3cli.output.report import Report

OutputOption = Annotated[Optional[Path], typer.Option(
    "--output", "-o", show_default=False, help="Write the URDF to FILE (atomically) instead of to stdout.")]


@robot_input
def expand(
    path: RobotPathArgument,
    source: RobotSource,
    output: OutputOption = None,
    follow_symlinks: FollowSymlinksOption = False,
    format: FormatOption = "text",
) -> None:
    """Print the URDF that every ar3cli command checks for PATH: a .xacro expanded as ar3cli expands it.

    The same expansion lint-urdf, info and the simulating commands read: `package://` and `$(find)`
    resolved by ar3cli (--package-path, ROS_PACKAGE_PATH, the packages above the file), and in safe
    mode by default (no Python, no files outside the robot's packages, no environment; see
    docs/security.md), so a finding's element can be looked at in the URDF it came from. A .urdf is
    printed as ar3cli reads it. With -o the URDF is written atomically and stdout stays empty.
    """
    from ar3cli.infra.atomic import atomic_write, check_writable
    from ar3cli.urdf.xacro_expand import included_files

    target = check_writable(output, follow_symlinks) if output is not None else None  # before any work
    model = source.load(path)
    urdf = model.xml_bytes
    included = included_files(urdf) if model.is_xacro else []
    data = {"path": str(path), "xacro": model.is_xacro, "bytes": len(urdf), "included": included,
            "output": str(output) if output is not None else None}
    if target is None:
        data["urdf"] = urdf.decode("utf-8", "replace")
        finish(Report(data=data, text=data["urdf"]), format)
    atomic_write(target, urdf, follow_symlinks=follow_symlinks)
    what = ", expanded from xacro" if model.is_xacro else ""
    finish(Report(data=data, lines=[f"wrote {output} ({len(urdf):,} bytes{what})"]), format)
