"""``ar3cli render``: a picture of the model, offscreen."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.commands.options import (
    FollowSymlinksOption,
    FormatOption,
    RobotPathArgument,
    TimeoutOption,
    finite_float,
)
from ar3cli.commands.robot_options import RobotSource, robot_input
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.output.formats import finish
from ar3cli.output.report import Report, Table, log


@robot_input
def render_command(
    path: RobotPathArgument,
    source: RobotSource,
    output: Annotated[Path, typer.Option("--output", "-o", help="PNG file to write.")] = Path("robot.png"),
    config: Annotated[Optional[str], typer.Option(
        "--config", metavar="JOINT=VALUE,...",
        help="Joint values in rad (or m); joints not named stay at home (0, or mid-range when 0 is outside "
             "the limits).")] = None,
    collision: Annotated[bool, typer.Option(
        "--collision", help="Draw the collision geometry (blue) instead of the visual geometry.")] = False,
    width: Annotated[int, typer.Option(help="Image width in pixels.")] = 800,
    height: Annotated[int, typer.Option(help="Image height in pixels.")] = 600,
    yaw: Annotated[float, typer.Option(click_type=finite_float(), help="Camera yaw around the robot, degrees.")] = 45.0,
    pitch: Annotated[float, typer.Option(click_type=finite_float(),
                                         help="Camera pitch, degrees (negative looks down).")] = -20.0,
    follow_symlinks: FollowSymlinksOption = False,
    format: FormatOption = "text",
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
) -> None:
    """Draw the model at its home pose (or --config) to a PNG with PyBullet's CPU renderer.

    Links in contact with a link they are not joined to are drawn red: the problem `lint-urdf --sim` reports.
    No display or GPU is needed.
    """
    from ar3cli.infra.atomic import check_writable
    from ar3cli.pictures.draw import draw_robot, parse_configuration

    output = check_writable(output, follow_symlinks)  # before any work; a planted link is refused
    configuration = parse_configuration(config)
    model = source.load(path)
    result = draw_robot(model, output, configuration, width=width, height=height, yaw_deg=yaw, pitch_deg=pitch,
                  show_collision=collision, warn=log)
    tables = []
    if result.contacts:
        tables.append(Table(title="links in contact (drawn red)", columns=["link a", "link b", "depth (m)"],
                            rows=[[a, b, d] for a, b, d in result.contacts], numeric_columns=("depth (m)",)))
    lines = [f"wrote {result.path} ({result.width}x{result.height})"]
    finish(Report(data=result.to_dict(), tables=tables, lines=lines), format)
