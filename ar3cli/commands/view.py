"""``ar3cli view``: the robot in a browser, live: move its joints, see its findings, edit the file.

A thin adapter: the options become :class:`~ar3cli.analysis.settings.AnalysisSettings` and an
address, :func:`ar3cli.view.server.serve` does the rest, and the URL is printed through the output
layer (``--format json``: the document ``{"url": ..., "path": ...}`` alone) once the robot is drawn.
"""

from __future__ import annotations

from typing import Annotated, Optional

import typer

from ar3cli.commands.options import FormatOption, RobotPathArgument, SeedOption, TimeoutOption
from ar3cli.commands.robot_options import RobotSource, robot_input
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S

HostOption = Annotated[str, typer.Option(
    "--host", help="Address to listen on. Anything but 127.0.0.1, localhost or ::1 lets other machines see the "
                   "robot, its meshes and its findings (a warning says so).")]
PortOption = Annotated[Optional[int], typer.Option(
    "--port", min=0, max=65535, show_default=False,
    help="Port to listen on (default 8080, or the next free one; 0: any free port). A given port that is in use "
         "is an error.")]


@robot_input
def view(
    path: RobotPathArgument,
    source: RobotSource,
    host: HostOption = "127.0.0.1",
    port: PortOption = None,
    open_browser: Annotated[bool, typer.Option("--open", help="Open the viewer in the default web browser.")] = False,
    seed: SeedOption = 0,
    format: FormatOption = "text",
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
) -> None:
    """Show a robot in the browser and keep it live: one slider per joint, links with findings coloured
    by the worst one, links in contact at the current pose in red, inertia boxes and centres of mass,
    link frames and joint axes. When the file, a xacro include or a mesh changes, the robot is redrawn
    with the sliders where they were; a file that no longer loads leaves the last good robot on screen
    with the error above it. Ctrl-C stops it.

    Needs the optional extra: pip install 'ar3cli[view]'. The file is read with the same limits as
    lint-urdf (safe xacro, capped reads); nothing is written.
    """
    from ar3cli.analysis.settings import AnalysisSettings
    from ar3cli.errors import UserError
    from ar3cli.lint.config import load_config
    from ar3cli.output.formats import REPORT, render
    from ar3cli.output.report import Report, log, render_report
    from ar3cli.view.server import import_viser, serve

    import_viser()  # before any work: without the extra, one line naming the pip command
    if not path.is_file():
        raise UserError(f"{path}: {'is not a regular file' if path.exists() else 'no such file'}")
    packages, xacro_args = source.specs()
    settings = AnalysisSettings(packages=packages, xacro_args=xacro_args, config=load_config(), seed=seed)

    def announce(url: str) -> None:
        made, stream = render(Report(data={"url": url, "path": str(path)},
                                     lines=[f"ar3cli view: {url} (Ctrl-C to stop)"]), (REPORT,), format)
        render_report(made, stream)

    serve(path, settings, host, port, seed, open_browser, announce, log=lambda line: log(f"ar3cli view: {line}"))
