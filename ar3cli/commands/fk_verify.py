"""``ar3cli fk-verify``: PyBullet's link frames, and optionally a DH table, against the URDF."""

from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ar3cli.commands.options import (
    FormatOption,
    PackagePathOption,
    RobotPathArgument,
    SeedOption,
    XacroArgOption,
    samples_option,
)
from ar3cli.errors import UserError
from ar3cli.output.report import OutputFormat, Report, Table, finish, log
from ar3cli.urdf.loading import load_with_specs

SamplesOption = Annotated[int, samples_option("Random configurations to compare.", most=1_000_000)]
DhOption = Annotated[Optional[Path], typer.Option("--dh", metavar="DH.yaml",
                                                  help="A DH table to check against the URDF (see docs).")]
ToleranceMOption = Annotated[float, typer.Option("--tolerance-m", help="Largest position error that passes (m).")]
ToleranceRadOption = Annotated[float, typer.Option("--tolerance-rad",
                                                   help="Largest orientation error that passes (rad, geodesic).")]


def fk_verify(
    path: RobotPathArgument,
    samples: SamplesOption = 1000,
    seed: SeedOption = 0,
    dh: DhOption = None,
    tolerance_m: ToleranceMOption = 1e-6,
    tolerance_rad: ToleranceRadOption = 1e-6,
    format: FormatOption = OutputFormat.text,
    package_path: PackagePathOption = None,
    xacro_arg: XacroArgOption = None,
) -> None:
    """Check that PyBullet (and your DH table) put every link frame where the URDF says.

    Sets N random configurations in PyBullet, reads each link frame (getLinkState[4:6], not the
    centre of mass) and compares it with an independent vectorised FK of the URDF. With --dh, the
    table's tip pose is compared too, and a disagreement is diagnosed (tool offset, flipped sign,
    degrees read as radians, the first wrong row). Exit 1 when any error exceeds the tolerance.
    """
    import numpy as np

    from ar3cli.kinematics import compare as fk_compare
    from ar3cli.kinematics import dh as dh_module
    from ar3cli.sim.session import Session, run_pybullet

    if not (tolerance_m > 0 and tolerance_rad > 0):
        raise UserError("--tolerance-m and --tolerance-rad must be positive")
    model = load_with_specs(path, package_path, xacro_arg)
    table = dh_module.load_dh(dh, model) if dh is not None else None

    def measure() -> tuple[fk_compare.Samples, fk_compare.Comparison]:
        with Session() as session:
            body = session.load(model, fixed_base=True, visuals=False)
            drawn = fk_compare.draw_samples(model, body, samples, seed)
            if format is OutputFormat.text:
                log(f"fk-verify: {samples} samples, seed {seed}")
            return drawn, fk_compare.compare(model, body, drawn)

    drawn, comparison = run_pybullet(measure, model)

    links_ok = all(e.max_position <= tolerance_m and e.max_orientation <= tolerance_rad for e in comparison.links)
    worst = max(comparison.links, key=lambda e: max(e.max_position / tolerance_m, e.max_orientation / tolerance_rad))
    dh_data, dh_tables, dh_lines, dh_ok = None, [], [], True
    if table is not None:
        q = dh_module.joint_matrix(table, drawn.all_values)
        evaluation = dh_module.evaluate(table, comparison.reference, q)
        dh_ok = evaluation.within(tolerance_m, tolerance_rad)
        diagnoses = dh_module.diagnose(table, comparison.reference, q, tolerance_m, tolerance_rad)
        worst_index = int(np.argmax(evaluation.position_error / tolerance_m + evaluation.orientation_error / tolerance_rad))
        dh_data = {
            "path": str(dh), "convention": table.convention, "base": table.base, "tip": table.tip, "passed": dh_ok,
            "max_position_error_m": evaluation.max_position,
            "mean_position_error_m": float(evaluation.position_error.mean()),
            "max_orientation_error_rad": evaluation.max_orientation,
            "mean_orientation_error_rad": float(evaluation.orientation_error.mean()),
            "worst_configuration": drawn.configuration(worst_index),
            "diagnoses": [d.to_dict() for d in diagnoses],
        }
        dh_tables.append(Table(
            title=f"DH table {dh} ({table.convention}) vs URDF: {table.base} -> {table.tip}",
            columns=["tip", "max position (m)", "mean position (m)", "max orientation (rad)",
                     "mean orientation (rad)", "status"],
            rows=[[table.tip, evaluation.max_position, dh_data["mean_position_error_m"], evaluation.max_orientation,
                   dh_data["mean_orientation_error_rad"], "pass" if dh_ok else "fail"]],
            status_column="status", numeric_columns=("max position (m)", "mean position (m)",
                                                     "max orientation (rad)", "mean orientation (rad)")))
        dh_lines = [f"DH diagnosis: {d.message}" for d in diagnoses]
        if not dh_ok:
            worst_values = _configuration(drawn.configuration(worst_index))
            dh_lines.append(f"DH worst configuration (sample {worst_index}): {worst_values}")

    passed = links_ok and dh_ok
    max_position = max((e.max_position for e in comparison.links), default=0.0)
    max_orientation = max((e.max_orientation for e in comparison.links), default=0.0)
    if dh_data is not None:
        max_position = max(max_position, dh_data["max_position_error_m"])
        max_orientation = max(max_orientation, dh_data["max_orientation_error_rad"])
    data: dict[str, Any] = {
        "path": str(path), "samples": samples, "seed": seed, "passed": passed,
        "tolerance_m": tolerance_m, "tolerance_rad": tolerance_rad,
        "max_position_error_m": max_position, "max_orientation_error_rad": max_orientation,
        "links": [e.to_dict() for e in comparison.links],
        "worst": {"link": worst.link, "sample": worst.worst_sample,
                  "configuration": drawn.configuration(worst.worst_sample)},
        "notes": comparison.notes, "dh": dh_data,
    }
    link_table = Table(
        title=f"PyBullet link frames vs URDF FK: {model.path.name}, {samples} samples, seed {seed}",
        columns=["link", "max position (m)", "mean position (m)", "max orientation (rad)",
                 "mean orientation (rad)", "status"],
        rows=[[e.link, e.max_position, e.mean_position, e.max_orientation, e.mean_orientation,
               "pass" if e.max_position <= tolerance_m and e.max_orientation <= tolerance_rad else "fail"]
              for e in comparison.links],
        caption="pybullet reports link frames in single precision: ~1e-7 m / ~6e-7 rad is its floor",
        status_column="status", numeric_columns=("max position (m)", "mean position (m)",
                                                 "max orientation (rad)", "mean orientation (rad)"))
    lines = [f"note: {note}" for note in comparison.notes] + dh_lines
    lines.append(f"worst link: {worst.link} (sample {worst.worst_sample}: "
                 f"{_configuration(drawn.configuration(worst.worst_sample))})")
    verdict = "PASS" if passed else "FAIL"
    lines.append(f"{verdict}: max position error {max_position:.3g} m (tolerance {tolerance_m:g}), max orientation "
                 f"error {max_orientation:.3g} rad (tolerance {tolerance_rad:g}); {samples} samples, seed {seed}")
    finish(Report(data=data, tables=[link_table, *dh_tables], lines=lines, ok=passed), format)


def _configuration(values: dict[str, float]) -> str:
    return ", ".join(f"{name}={value:.6g}" for name, value in values.items())
