"""``ar3cli fix-collision``: replace non-convex collision meshes by a convex decomposition."""

from typing import TYPE_CHECKING, Annotated

import typer

from ar3cli.commands.fixer_options import fixer_command, run_fix
from ar3cli.commands.options import SeedOption, finite_float, samples_option
from ar3cli.infra.child_limits import LONG_TIMEOUT_S

if TYPE_CHECKING:
    from ar3cli.fix.driver import FixerArgs


@fixer_command(timeout=LONG_TIMEOUT_S)
def fix_collision(
    args: "FixerArgs",
    max_hull_ratio: Annotated[float, typer.Option(
        "--max-hull-ratio", click_type=finite_float(),
        help="Decompose a collision mesh whose convex hull has more than this many times "
                                 "its volume (the mesh must be closed).")] = 2.0,
    method: Annotated[str, typer.Option(
        "--method", help="coacd, vhacd (pybullet's), or auto: coacd when installed (pip install "
                         "'ar3cli[decompose]'), else vhacd.")] = "auto",
    resolution: Annotated[int, typer.Option(
        "--resolution", min=10_000, max=64_000_000,
        help="vhacd's voxel count: higher is finer and slower.")] = 100_000,
    from_visual: Annotated[bool, typer.Option(
        "--from-visual", help="Links with a `<visual>` but no `<collision>` get one: a primitive copied, a mesh "
                              "as its convex hull (decomposed when its hull ratio is above the limit).")] = False,
    verify: Annotated[bool, typer.Option(
        "--verify/--no-verify", help="Compare the original and the fixed robot in PyBullet (home contacts and "
                                     "sampled pair categories; a decomposition that makes a pair collide more "
                                     "is refused), and after writing count each changed link's collision "
                                     "shapes.")] = True,
    samples: Annotated[int, samples_option("Configurations sampled to compare pair categories before and "
                                           "after the fix.", 100_000)] = 300,
    seed: SeedOption = 0,
) -> None:
    """Replace a collision mesh that collides as a much larger convex hull by convex parts.

    PyBullet collides a moving link's mesh as its convex hull. Where hull volume / mesh volume is
    above --max-hull-ratio, that `<collision>` becomes one `<collision>` per part of a convex
    decomposition (CoACD or pybullet's V-HACD), written as OBJ files in
    `collision/LINK/` beside the URDF; origin, scale and formatting are kept. With --diff or
    --check nothing is written, part files included.
    """
    import tempfile
    from pathlib import Path

    from ar3cli.errors import UserError
    from ar3cli.fix.collision_plan import FIXER, CollisionOptions, remove_staging
    from ar3cli.fix.decompose import resolve_method

    if not max_hull_ratio > 1.0:
        raise UserError(f"--max-hull-ratio {max_hull_ratio}: must be above 1 (a convex mesh is 1)")
    options = CollisionOptions(max_hull_ratio=max_hull_ratio, method=resolve_method(method), resolution=resolution,
                               from_visual=from_visual, output=args.output, write=args.writes,
                               follow_symlinks=args.follow_symlinks, compare=verify, samples=samples, seed=seed,
                               staging=Path(tempfile.mkdtemp(prefix="ar3cli-parts-")))
    try:
        run_fix(FIXER, options, args, verify)
    finally:
        options.rollback()  # part files of a URDF that was not rewritten (an error, a failed check)
        remove_staging(options)
