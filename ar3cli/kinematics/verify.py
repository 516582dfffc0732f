"""fk-verify's run and report: PyBullet's link frames (and a DH table) against the URDF's own FK.

One pass predicate (:class:`Tolerance`) and one set of error columns serve both the link table and
the DH table, so the verdict line always agrees with the tables.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ar3cli.findings import listed
from ar3cli.kinematics import compare as fk_compare
from ar3cli.kinematics import dh as dh_module
from ar3cli.output.report import Report, Table, log
from ar3cli.urdf.model import Model

FLOAT32_EPSILON = 2.0 ** -23
"""Spacing of single-precision numbers at 1.0 (1.19e-7): pybullet computes and reports link frames in
float32, so a coordinate near x metres is only known to about x times this."""
REACH_EPSILONS = 4.0
"""The scaled position tolerance is this many float32 epsilons times the reach. Measured on a mobile
base with prismatic x/y joints of +-20 m and a two-link arm (tests/test_fk_verify.py): errors up to
0.5 epsilon x reach (1.3e-6 m at 22 m); Fetch, a mobile Panda and a Dingo-Kinova show 1.1-2.4e-6 m at
10-20 m. 4 epsilons leave room for rounding that accumulates along a chain while a 0.1 mm mistake at
20 m still fails (the allowance there is 9.5e-6 m)."""
DEFAULT_TOLERANCE_M = 1e-6
"""fk-verify's position tolerance (m) when none is given: scaled with the reach (:class:`Tolerance`)."""
DEFAULT_TOLERANCE_RAD = 1e-6
"""fk-verify's orientation tolerance (rad, geodesic) when none is given (its --tolerance-rad default)."""
ERROR_COLUMNS = ["max position (m)", "mean position (m)", "max orientation (rad)", "mean orientation (rad)"]


@dataclass(frozen=True)
class Tolerance:
    """Largest position (m) and orientation (rad, geodesic) errors that pass.

    With ``scaled`` (the default: no ``--tolerance-m`` given), the position tolerance of a link in a
    sample is ``max(position, REACH_EPSILONS * FLOAT32_EPSILON * reach)``: far from the origin (a
    mobile base's virtual joints reach +-20 m) float32 frames cannot be closer than that, and an
    absolute 1e-6 m would fail a correct robot. A tolerance the user gives is used as given.
    Orientation errors do not grow with distance, so the orientation tolerance is always absolute.
    """

    position: float
    orientation: float
    scaled: bool = False

    @property
    def per_metre(self) -> float:
        """Position tolerance per metre of reach (0 when not scaled)."""
        return REACH_EPSILONS * FLOAT32_EPSILON if self.scaled else 0.0

    def position_at(self, reach: Any) -> Any:
        """The position tolerance at ``reach`` metres (a float or an array of them)."""
        import numpy as np

        return np.maximum(self.position, self.per_metre * np.asarray(reach, dtype=float))

    def passes(self, position: float, orientation: float, reach: float = 0.0) -> bool:
        return position <= float(self.position_at(reach)) and orientation <= self.orientation

    def link_severity(self, error: fk_compare.LinkError) -> float:
        """How far past the tolerance the link's worst sample is (1 = at it), for the worst case and the verdict."""
        position = float((error.position_errors / self.position_at(error.reaches)).max()) \
            if error.position_errors.size else error.max_position / self.position
        return max(position, error.max_orientation / self.orientation)

    def link_passes(self, error: fk_compare.LinkError) -> bool:
        return self.link_severity(error) <= 1.0

    def describe(self) -> str:
        """The rule in words, for the verdict line."""
        if not self.scaled:
            return f"{self.position:g} m as given"
        return f"max({self.position:g} m, {REACH_EPSILONS:g} float32 epsilons x reach)"


@dataclass
class DhCheck:
    """The DH table against the URDF: JSON data, its table row, diagnosis lines, verdict."""

    data: dict[str, Any]
    table: Table
    lines: list[str]
    ok: bool


def measure(model: Model, samples: int, seed: int, announce: bool) -> tuple[fk_compare.Samples, fk_compare.Comparison]:
    """Draw the configurations and compare pybullet's frames with the URDF FK (in a forked child).

    A collision mesh pybullet cannot load (a file not found) is left out with one warning line: link
    frames do not depend on meshes (``Comparison.left_out`` lists it)."""
    from ar3cli.sim.loadable_copy import left_out_summary, unloadable_shapes
    from ar3cli.sim.session import Session, run_pybullet

    left_out = unloadable_shapes(model, roles=("collision",))
    if left_out:
        log(f"fk-verify: warning: {model.path}: {left_out_summary(left_out)}: pybullet cannot load it; "
            "link frames do not depend on meshes")

    def in_pybullet() -> tuple[fk_compare.Samples, fk_compare.Comparison]:
        with Session() as session:
            body = session.load(model, fixed_base=True, visuals=False, leave_out_unloadable=True)
            drawn = fk_compare.draw_samples(model, body, samples, seed)
            if announce:
                log(f"fk-verify: {samples} samples, seed {seed}")
            return drawn, fk_compare.compare(model, body, drawn)

    drawn, comparison = run_pybullet(in_pybullet, model)
    comparison.left_out = left_out
    return drawn, comparison


def check_dh(table: dh_module.DHTable, dh_path: Path, drawn: fk_compare.Samples,
             comparison: fk_compare.Comparison, tolerance: Tolerance) -> DhCheck:
    """Evaluate the DH table's tip against the URDF's over the same samples, with diagnoses."""
    import numpy as np

    tip = next((error for error in comparison.links if error.link == table.tip), None)
    tolerance = Tolerance(float(tolerance.position_at(tip.max_reach if tip else 0.0)), tolerance.orientation)
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
        "tolerance_m": tolerance.position,
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
    worst = max(links, key=tolerance.link_severity)
    passed = all(tolerance.link_passes(e) for e in links) and (dh is None or dh.ok)
    largest = max(float(tolerance.position_at(e.max_reach)) for e in links)
    max_position = max([e.max_position for e in links] + ([dh.data["max_position_error_m"]] if dh else []))
    max_orientation = max([e.max_orientation for e in links] + ([dh.data["max_orientation_error_rad"]] if dh else []))
    data: dict[str, Any] = {
        "path": str(path), "samples": samples, "seed": seed, "passed": passed,
        "tolerance_m": tolerance.position, "tolerance_rad": tolerance.orientation,
        "tolerance_scaled": tolerance.scaled, "tolerance_m_per_m_reach": tolerance.per_metre,
        "largest_position_tolerance_m": largest,
        "max_position_error_m": max_position, "max_orientation_error_rad": max_orientation,
        "links": [{**e.to_dict(), "position_tolerance_m": float(tolerance.position_at(e.max_reach)),
                   "passed": tolerance.link_passes(e)} for e in links],
        "worst": {"link": worst.link, "sample": worst.worst_sample,
                  "configuration": drawn.configuration(worst.worst_sample)},
        "notes": comparison.notes, "dh": dh.data if dh else None,
        "left_out": [item.to_dict() for item in comparison.left_out],
    }
    link_table = _error_table(
        f"PyBullet link frames vs URDF FK: {model.path.name}, {samples} samples, seed {seed}", "link",
        [[e.link, e.max_position, e.mean_position, e.max_orientation, e.mean_orientation,
          "pass" if tolerance.link_passes(e) else "fail"] for e in links],
        caption="pybullet reports link frames in single precision: ~1e-7 m / ~6e-7 rad is its floor")
    lines = [f"note: {note}" for note in comparison.notes] + (dh.lines if dh else [])
    worst_at = drawn.configuration(worst.worst_sample)
    lines.append(f"worst link: {worst.link} " + (f"(sample {worst.worst_sample}: {_configuration(worst_at)})" if worst_at
                                                 else "(no movable joint: every sample is the same configuration)"))
    scaled = (f", up to {largest:.3g} m at {max(e.max_reach for e in links):.3g} m reach"
              if largest > tolerance.position else "")
    lines.append(f"{'PASS' if passed else 'FAIL'}: max position error {max_position:.3g} m (tolerance "
                 f"{tolerance.describe()}{scaled}), max orientation error {max_orientation:.3g} rad (tolerance "
                 f"{tolerance.orientation:g}); {samples} samples, seed {seed}")
    return Report(data=data, tables=[link_table, *([dh.table] if dh else [])], lines=lines, ok=passed)


def _error_table(title: str, first: str, rows: list[list[Any]], caption: str = "") -> Table:
    return Table(title=title, columns=[first, *ERROR_COLUMNS, "status"], rows=rows, caption=caption,
                 status_column="status", numeric_columns=tuple(ERROR_COLUMNS))


def _configuration(values: dict[str, float]) -> str:
    return listed(f"{name}={value:.6g}" for name, value in values.items())
