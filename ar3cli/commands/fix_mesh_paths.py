"""``ar3cli fix-mesh-paths``: absolute, file://, package:/// and relative mesh URIs become package://NAME/..."""

from typing import TYPE_CHECKING, Annotated

import typer

from ar3cli.commands.fixer_options import fixer_command, run_fix
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S

if TYPE_CHECKING:
    from ar3cli.fix.driver import FixerArgs


@fixer_command(timeout=DEFAULT_TIMEOUT_S)
def fix_mesh_paths(
    args: "FixerArgs",
    package: Annotated[list[str], typer.Option(
        "--package", metavar="NAME=DIR", show_default=False,
        help="The package the meshes belong to: a URI whose file lies under DIR becomes "
             "package://NAME/PATH, PATH relative to DIR (repeatable; required).")],
    verify: Annotated[bool, typer.Option(
        "--verify/--no-verify", help="After writing, load the result in PyBullet and check each rewritten "
                                     "mesh comes from the same file.")] = True,
) -> None:
    """Rewrite machine-bound mesh and texture URIs to `package://NAME/...`, byte for byte, atomically.

    Absolute paths, `file://` URIs, `package:///` URIs (no package name) and paths relative to
    the URDF are rewritten when the file they point to lies under a --package DIR, after checking
    that the new URI resolves to the same file with `--package-path NAME=DIR`. URIs that do not
    resolve, or point outside every DIR, are reported and left alone.
    """
    from dataclasses import replace

    from ar3cli.fix.mesh_paths_plan import FIXER, MeshPathOptions, parse_packages

    packages = parse_packages(package)
    specs = [f"{name}={folder}" for name, folder in packages.items()] + list(args.package_path or [])
    run_fix(FIXER, MeshPathOptions(packages), replace(args, package_path=specs), verify)
