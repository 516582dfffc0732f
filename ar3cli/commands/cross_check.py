"""``ar3cli cross-check``: the same robot in PyBullet and MuJoCo, compared."""

from typing import Annotated

import typer

from ar3cli.commands.options import (
    FormatOption,
    RobotPathArgument,
    SeedOption,
    samples_option,
)
from ar3cli.commands.robot_options import RobotSource, robot_input
from ar3cli.output.formats import finish

SamplesOption = Annotated[int, samples_option("Random configurations compared after the home pose.", most=10_000)]
StabilityOption = Annotated[bool, typer.Option("--stability", help="Also drop the robot passively for 1 s in both "
                                                                   "engines at two timesteps; energy growth fails.")]
TopOption = Annotated[int, typer.Option("--top", min=1, max=1000, help="Rows of the table (largest differences first).")]


@robot_input
def cross_check(
    path: RobotPathArgument,
    source: RobotSource,
    samples: SamplesOption = 20,
    seed: SeedOption = 0,
    stability: StabilityOption = False,
    top: TopOption = 10,
    format: FormatOption = "text",
) -> None:
    """Check that PyBullet and MuJoCo simulate the same robot from this file.

    At the home pose and N sampled configurations, compares every link frame, link masses, total
    mass and centre of mass, the joint-space mass matrix and gravity torques, then drives each leader
    joint a little in both engines to see which constraints each enforces (a `<mimic>` follower).
    Tolerances scale with each quantity. Exit 0 on agreement, 1 on disagreement, 2 on bad input
    or when MuJoCo is not installed (pip install 'ar3cli[mujoco]').
    """
    from ar3cli.cross_check.run import cross_check as run
    from ar3cli.sim.mujoco_session import import_mujoco

    import_mujoco()
    model = source.load(path)
    finish(run(model, path, samples, seed, stability, top, announce=format == "text"), format)
