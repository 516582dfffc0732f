"""fk-verify's run and report: PyBullet's link frames (and a DH table) against the URDF's own FK.

One pass predicate (:class:`Tolerance`) and one set of error columns serve both the link table and
the DH table, so the verdict line always agrees with the tables.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ar3cli.kinematics import compare as fk_compare
from ar3cli.kinematics import dh as dh_module
from ar3cli.output.report import Report, Table, log
from ar3cli.urdf.model import Model

ERROR_COLUMNS = ["max position (m)", "mean position (m)", "max orientation (rad)", "mean orientation (rad)"]


@dataclass(frozen=True)
class Tolerance:
    """Largest position (m) and orientation (rad, geodesic) errors that pass."""

    position: float
    orientation: float

    def passes(self, position: float, orientation: float) -> bool:
        return position <= self.position and orientation <= self.orientation

    def severity(self, position: float, orientation: float) -> float:
        """How far past the tolerance (1 = at it), for picking the worst case."""
        return max(position / self.position, orientation / self.orientation)


@dataclass
class DhCheck:
    """The DH table against the URDF: JSON data, its table row, diagnosis lines, verdict."""

    data: dict[str, Any]
    table: Table
    lines: list[str]
    ok: bool


def measure(model: Model, samples: int, seed: int, announce: bool) -> tuple[fk_compare.Samples, fk_compare.Comparison]:
    """Draw the configurations and compare pybullet's frames with the URDF FK (in a forked child)."""
    from ar3cli.sim.session import Session, run_pybullet

    def in_pybullet() -> tuple[fk_compare.Samples, fk_compare.Comparison]:
        with Session() as session:
            body = session.load(model, fixed_base=True, visuals=False)
            drawn = fk_compare.draw_samples(model, body, samples, seed)
            if announce:
                log(f"fk-verify: {samples} samples, seed {seed}")
            return drawn, fk_compare.compare(model, body, drawn)

    return run_pybullet(in_pybullet, model)


def check_dh(table: dh_module.DHTable, dh_path: Path, drawn: fk_compare.Samples,
             comparison: fk_compare.Comparison, tolerance: Tolerance) -> DhCheck:
    """Evaluate the DH table's tip against the URDF's over the same samples, with diagnoses."""
    import numpy as np

    q = dh_module.joint_matrix(table, drawn.all_values)
    evaluation = dh_module.evaluate(table, comparison.reference, q)
    ok = evaluation.within(tolerance.position, tolerance.orientation)
    diagnoses = dh_module.diagnose(table, comparison.reference, q, tolerance.position, tolerance.orientation)
    worst = int(np.argmax(evaluation.position_error / tolerance.position
                          + evaluation.orientation_error / tolerance.orientation))
    errors = [evaluation.max_position, float(evaluation.position_error.mean()), evaluation.max_orientation,
              float(evaluation.orientation_error.mean())]
    data = {
        "path": str(dh_path), "convention": table.convention, "base": table.base, "tip": table.tip, "passed": ok,
        **dict(zip(("max_position_error_m", "mean_position_error_m", "max_orientation_error_rad",
                    "mean_orientation_error_rad"), errors)),
        "worst_configuration": drawn.configuration(worst),
        "diagnoses": [d.to_dict() for d in diagnoses],
    }
    lines = [f"DH diagnosis: {d.message}" for d in diagnoses]
    if not ok:
        lines.append(f"DH worst configuration (sample {worst}): {_configuration(drawn.configuration(worst))}")
    return DhCheck(data, _error_table(f"DH table {dh_path} ({table.convention}) vs URDF: {table.base} -> {table.tip}",
                                      "tip", [[table.tip, *errors, "pass" if ok else "fail"]]), lines, ok)


def fk_report(model: Model, path: Path, samples: int, seed: int, tolerance: Tolerance, drawn: fk_compare.Samples,
              comparison: fk_compare.Comparison, dh: DhCheck | None) -> Report:
    """The JSON document, the link table (and the DH table), the notes and one verdict line."""
    links = comparison.links
    worst = max(links, key=lambda e: tolerance.severity(e.max_position, e.max_orientation))
    passed = all(tolerance.passes(e.max_position, e.max_orientation) for e in links) and (dh is None or dh.ok)
    max_position = max([e.max_position for e in links] + ([dh.data["max_position_error_m"]] if dh else []))
    max_orientation = max([e.max_orientation for e in links] + ([dh.data["max_orientation_error_rad"]] if dh else []))
    data: dict[str, Any] = {
        "path": str(path), "samples": samples, "seed": seed, "passed": passed,
        "tolerance_m": tolerance.position, "tolerance_rad": tolerance.orientation,
        "max_position_error_m": max_position, "max_orientation_error_rad": max_orientation,
        "links": [e.to_dict() for e in links],
        "worst": {"link": worst.link, "sample": worst.worst_sample,
                  "configuration": drawn.configuration(worst.worst_sample)},
        "notes": comparison.notes, "dh": dh.data if dh else None,
    }
    link_table = _error_table(
        f"PyBullet link frames vs URDF FK: {model.path.name}, {samples} samples, seed {seed}", "link",
        [[e.link, e.max_position, e.mean_position, e.max_orientation, e.mean_orientation,
          "pass" if tolerance.passes(e.max_position, e.max_orientation) else "fail"] for e in links],
        caption="pybullet reports link frames in single precision: ~1e-7 m / ~6e-7 rad is its floor")
    lines = [f"note: {note}" for note in comparison.notes] + (dh.lines if dh else [])
    lines.append(f"worst link: {worst.link} (sample {worst.worst_sample}: "
                 f"{_configuration(drawn.configuration(worst.worst_sample))})")
    lines.append(f"{'PASS' if passed else 'FAIL'}: max position error {max_position:.3g} m (tolerance "
                 f"{tolerance.position:g}), max orientation error {max_orientation:.3g} rad (tolerance "
                 f"{tolerance.orientation:g}); {samples} samples, seed {seed}")
    return Report(data=data, tables=[link_table, *([dh.table] if dh else [])], lines=lines, ok=passed)


def _error_table(title: str, first: str, rows: list[list[Any]], caption: str = "") -> Table:
    return Table(title=title, columns=[first, *ERROR_COLUMNS, "status"], rows=rows, caption=caption,
                 status_column="status", numeric_columns=tuple(ERROR_COLUMNS))


def _configuration(values: dict[str, float]) -> str:
    return ", ".join(f"{name}={value:.6g}" for name, value in values.items())
