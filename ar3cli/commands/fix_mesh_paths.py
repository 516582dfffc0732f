"""``ar3cli fix-mesh-paths``: absolute, file://, package:/// and relative mesh URIs become package://NAME/..."""

from typing import Annotated

import typer

from ar3cli.commands.options import (
    CheckOption,
    DiffOption,
    FixPathsArgument,
    FollowSymlinksOption,
    FormatOption,
    OutputOption,
    PackagePathOption,
    TimeoutOption,
)
from ar3cli.infra.child_limits import DEFAULT_TIMEOUT_S
from ar3cli.output.report import OutputFormat


def fix_mesh_paths(
    paths: FixPathsArgument,
    package: Annotated[list[str], typer.Option(
        "--package", metavar="NAME=DIR", show_default=False,
        help="The package the meshes belong to: a URI whose file lies under DIR becomes "
             "package://NAME/PATH, PATH relative to DIR (repeatable; required).")],
    verify: Annotated[bool, typer.Option(
        "--verify/--no-verify", help="After writing, load the result in PyBullet and check each rewritten "
                                     "mesh comes from the same file.")] = True,
    diff: DiffOption = False,
    check: CheckOption = False,
    output: OutputOption = None,
    follow_symlinks: FollowSymlinksOption = False,
    package_path: PackagePathOption = None,
    format: FormatOption = OutputFormat.text,
    timeout: TimeoutOption = DEFAULT_TIMEOUT_S,
) -> None:
    """Rewrite machine-bound mesh and texture URIs to `package://NAME/...`, byte for byte, atomically.

    Absolute paths, `file://` URIs, `package:///` URIs (no package name) and paths relative to
    the URDF are rewritten when the file they point to lies under a --package DIR, after checking
    that the new URI resolves to the same file with `--package-path NAME=DIR`. URIs that do not
    resolve, or point outside every DIR, are reported and left alone.
    """
    from ar3cli.fix.driver import run_fixer
    from ar3cli.fix.mesh_paths_plan import MeshPathOptions, make_fixer, parse_packages
    from ar3cli.fix.mesh_paths_plan import verify as verify_in_pybullet

    packages = parse_packages(package)
    specs = [f"{name}={folder}" for name, folder in packages.items()] + list(package_path or [])
    code = run_fixer("fix-mesh-paths", paths, make_fixer(MeshPathOptions(packages)), diff=diff, check=check,
                     output=output, fmt=format, package_path=specs, follow_symlinks=follow_symlinks,
                     verifier=verify_in_pybullet if verify else None)
    raise typer.Exit(code)
