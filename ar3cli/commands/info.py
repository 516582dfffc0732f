"""``ar3cli info``: the first look at a robot (tree, DOF, limits, mass, size, meshes), no pybullet."""

from ar3cli.commands.options import FormatOption, PackagePathOption, RobotPathArgument, XacroArgOption
from ar3cli.output.report import OutputFormat, finish
from ar3cli.urdf.loading import load_with_specs


def info(
    path: RobotPathArgument,
    package_path: PackagePathOption = None,
    xacro_arg: XacroArgOption = None,
    format: FormatOption = OutputFormat.text,
) -> None:
    """Show what a robot is made of: kinematic tree, DOF and joint limits, masses and centre of mass,
    bounding box, meshes, end effectors.

    Static and fast (no PyBullet): the centre of mass and the bounding box are computed at the
    zero configuration (every joint at 0) with the URDF's own forward kinematics.
    """
    from ar3cli.info.summary import summarize
    from ar3cli.info.text import report
    from ar3cli.kinematics.fk import urdf_link_frames

    def zero_frames(model):
        return {link: frames[0] for link, frames in urdf_link_frames(model, {}, 1).items()}

    model = load_with_specs(path, package_path, xacro_arg)
    finish(report(summarize(model, zero_frames), tree=format is OutputFormat.text), format)
