"""``ar3cli fk-verify``: PyBullet's link frames, and optionally a DH table, against the URDF."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.commands.options import (
    FormatOption,
    RobotPathArgument,
    SeedOption,
    TimeoutOption,
    finite_float,
    samples_option,
)
from ar3cli.commands.robot_options import RobotSource, robot_input
from ar3cli.errors import UserError
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.output.formats import finish

SamplesOption = Annotated[int, samples_option("Random configurations to compare.", most=1_000_000)]
DhOption = Annotated[Optional[Path], typer.Option("--dh", metavar="DH.yaml",
                                                  help="A DH table to check against the URDF (see docs).")]
ToleranceMOption = Annotated[Optional[float], typer.Option(
    "--tolerance-m", show_default=False, click_type=finite_float(),
    help="Largest position error that passes (m). Default: 1e-6 m, raised far from the origin to 4 float32 epsilons "
         "x the link's reach (pybullet's single precision; a mobile base 20 m out gets 9.5e-6 m). A value given "
         "here is used as is.")]
ToleranceRadOption = Annotated[float, typer.Option("--tolerance-rad", click_type=finite_float(),
                                                   help="Largest orientation error that passes (rad, geodesic).")]


@robot_input
def fk_verify(
    path: RobotPathArgument,
    source: RobotSource,
    samples: SamplesOption = 1000,
    seed: SeedOption = 0,
    dh: DhOption = None,
    tolerance_m: ToleranceMOption = None,
    tolerance_rad: ToleranceRadOption = 1e-6,
    format: FormatOption = "text",
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
) -> None:
    """Check that PyBullet (and your DH table) put every link frame where the URDF says.

    Sets N random configurations in PyBullet, reads each link frame (getLinkState[4:6], not the
    centre of mass) and compares it with an independent vectorised FK of the URDF. With --dh, the
    table's tip pose is compared too, and a disagreement is diagnosed (tool offset, flipped sign,
    degrees read as radians, the first wrong row). Exit 1 when any error exceeds the tolerance.
    """
    from ar3cli.kinematics import dh as dh_module
    from ar3cli.kinematics.verify import DEFAULT_TOLERANCE_M, Tolerance, check_dh, fk_report, measure

    if not ((tolerance_m is None or tolerance_m > 0) and tolerance_rad > 0):
        raise UserError("--tolerance-m and --tolerance-rad must be positive")
    tolerance = (Tolerance(DEFAULT_TOLERANCE_M, tolerance_rad, scaled=True) if tolerance_m is None
                 else Tolerance(tolerance_m, tolerance_rad))
    model = source.load(path)
    table = dh_module.load_dh(dh, model) if dh is not None else None
    drawn, comparison = measure(model, samples, seed, announce=format == "text")
    checked = check_dh(table, dh, drawn, comparison, tolerance) if table is not None and dh is not None else None
    finish(fk_report(model, path, samples, seed, tolerance, drawn, comparison, checked), format)
