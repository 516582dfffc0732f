"""``ar3cli fix-inertia``: recompute bad ``<inertial>`` elements from the link geometry."""

import math
from typing import TYPE_CHECKING, Annotated, Optional

import typer

from ar3cli.commands.fixer_options import fixer_command, run_fix
from ar3cli.commands.options import finite_float

if TYPE_CHECKING:
    from ar3cli.fix.driver import FixerArgs

DENSITY_RANGE = (0.01, 1e6)
"""Densities that are a material, in kg/m^3: expanded foams and aerogels start near 1, osmium is
22,590; the margins take units slips the user meant. Outside it the inertia written is no
physics (``--density 1e-320`` gave masses of 1e-323 kg, subnormal numbers that underflow to 0)."""


@fixer_command(timeout=None)
def fix_inertia(
    args: "FixerArgs",
    links: Annotated[Optional[str], typer.Option("--links", help="Comma-separated links to recompute "
                                                 "(default: the links the linter flags as invalid).")] = None,
    all_links: Annotated[bool, typer.Option("--all", help="Recompute every link that has geometry.")] = False,
    include_implausible: Annotated[bool, typer.Option(
        "--include-implausible",
        help="Also recompute links whose inertia is valid but implausible for their geometry (I007: "
             "often a hand-tuned value or a deliberate placeholder). By default they are left alone "
             "and listed.")] = False,
    density: Annotated[Optional[float], typer.Option("--density", metavar="KG_PER_M3", click_type=finite_float(),
                                                     help="Density for links without a valid mass.")] = None,
    mass: Annotated[Optional[list[str]], typer.Option("--mass", metavar="LINK=KG",
                                                      help="Mass of one link (repeatable); overrides the file.")] = None,
    total_mass: Annotated[Optional[float], typer.Option("--total-mass", metavar="KG", click_type=finite_float(),
                                                        help="The robot's total mass: what the known masses leave "
                                                             "is spread over links without one, by volume.")] = None,
) -> None:
    """Recompute mass, centre of mass and inertia tensor of links from their geometry.

    By default it fixes only links whose inertia is invalid (missing, mass <= 0, not positive
    definite, A + B < C, all zero) and lists the valid but implausible ones (I007) it left alone;
    --include-implausible recomputes those too.
    Edits only the fixed `<inertial>` elements, byte for byte, and writes atomically. A link
    without a valid mass needs --density, --mass or --total-mass: there is no default density.
    """
    from ar3cli.errors import UserError
    from ar3cli.fix.inertia_plan import FIXER, SMALLEST_MASS, InertiaOptions, parse_masses

    if density is not None and not DENSITY_RANGE[0] <= density <= DENSITY_RANGE[1]:
        raise UserError(f"--density {density}: must be a density between {DENSITY_RANGE[0]:g} and "
                        f"{DENSITY_RANGE[1]:g} kg/m^3 (e.g. 1200 for PLA, 2700 for aluminium, 7850 for steel)")
    if total_mass is not None and not SMALLEST_MASS <= total_mass < math.inf:
        raise UserError(f"--total-mass {total_mass}: must be a mass of at least {SMALLEST_MASS:g} kg")
    if links is not None and all_links:
        raise UserError("--links and --all exclude each other")
    if include_implausible and (links is not None or all_links):
        raise UserError("--include-implausible widens the default selection; --links and --all already "
                        "choose the links")
    names = [name.strip() for name in links.split(",") if name.strip()] if links is not None else None
    run_fix(FIXER, InertiaOptions(names, all_links, density, parse_masses(mass), total_mass, include_implausible), args)
