"""``ar3cli fix-continuous``: remove fake limits from continuous joints, or give them real ones."""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Optional

import typer

from ar3cli.commands.fixer_options import fixer_command, run_fix
from ar3cli.commands.options import finite_float
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S

if TYPE_CHECKING:
    from ar3cli.fix.driver import FixerArgs


@fixer_command(timeout=DEFAULT_TIMEOUT_S)
def fix_continuous(
    args: "FixerArgs",
    limits_from: Annotated[Optional[Path], typer.Option(
        "--limits-from", metavar="JOINT_LIMITS_YAML",
        help="MoveIt joint_limits.yaml: joints with has_position_limits become revolute with its limits.")] = None,
    to_continuous: Annotated[bool, typer.Option(
        "--to-continuous", help="Revolute joints whose range covers a full turn (>= 2 pi) become continuous.")] = False,
    effort: Annotated[Optional[float], typer.Option(
        "--effort", click_type=finite_float(),
        help="Effort (N*m or N) to add where a fixed joint's `<limit>` has none.")] = None,
    velocity: Annotated[Optional[float], typer.Option(
        "--velocity", click_type=finite_float(),
        help="Velocity (rad/s or m/s) to add where a fixed joint's `<limit>` has none.")] = None,
    verify: Annotated[bool, typer.Option(
        "--verify/--no-verify", help="After writing, load the result in PyBullet and check the joints.")] = True,
) -> None:
    """Fix continuous joints: lower/upper on a continuous joint only add a PyBullet position clamp.

    Default: remove them (keep effort/velocity). --limits-from turns joints with hard stops
    into revolute joints with the real limits. Edits only those joints, byte for byte, atomically.
    """
    from ar3cli.errors import UserError
    from ar3cli.fix.continuous_plan import FIXER, ContinuousOptions
    from ar3cli.urdf.joint_limits_yaml import read_joint_limits

    for name, value in (("--effort", effort), ("--velocity", velocity)):
        if value is not None and not value > 0:
            raise UserError(f"{name} {value}: must be positive")
    limits = read_joint_limits(limits_from) if limits_from is not None else None
    run_fix(FIXER, ContinuousOptions(limits, limits_from, to_continuous, effort, velocity), args, verify)
