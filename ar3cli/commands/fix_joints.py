"""``ar3cli fix-joints``: swap inverted limits, degrees to radians, unit axes, missing effort/velocity."""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Optional

import typer

from ar3cli.commands.fixer_options import fixer_command, run_fix
from ar3cli.commands.options import finite_float
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S

if TYPE_CHECKING:
    from ar3cli.fix.driver import FixerArgs


@fixer_command(timeout=DEFAULT_TIMEOUT_S)
def fix_joints(
    args: "FixerArgs",
    effort: Annotated[Optional[float], typer.Option(
        "--effort", click_type=finite_float(), help="Effort (N*m or N) to add where a `<limit>` has none (J007).")] = None,
    velocity: Annotated[Optional[float], typer.Option(
        "--velocity", click_type=finite_float(),
        help="Velocity (rad/s or m/s) to add where a `<limit>` has none (J007).")] = None,
    limits_from: Annotated[Optional[Path], typer.Option(
        "--limits-from", metavar="JOINT_LIMITS_YAML",
        help="MoveIt joint_limits.yaml: its max_effort / max_velocity fill a `<limit>` without them "
             "(before --effort / --velocity).")] = None,
    verify: Annotated[bool, typer.Option(
        "--verify/--no-verify", help="After writing, load the result in PyBullet and read the joints back.")] = True,
) -> None:
    """Fix the joint findings of lint-urdf that have one right answer, byte for byte, atomically.

    Inverted limits (J003) are swapped; revolute limits in degrees (J005) become radians; a
    non-unit axis (J010) is normalised; a `<limit>` without effort or velocity (J007) gets them
    from --limits-from or --effort/--velocity. A zero axis (J009) cannot be fixed automatically:
    it is reported, with what to do. Only the changed attributes are edited.
    """
    from ar3cli.errors import UserError
    from ar3cli.fix.joints_plan import FIXER, JointsOptions
    from ar3cli.urdf.joint_limits_yaml import read_joint_limits

    for name, value in (("--effort", effort), ("--velocity", velocity)):
        if value is not None and not value > 0:
            raise UserError(f"{name} {value}: must be positive")
    limits = read_joint_limits(limits_from) if limits_from is not None else None
    run_fix(FIXER, JointsOptions(effort, velocity, limits, limits_from), args, verify)
