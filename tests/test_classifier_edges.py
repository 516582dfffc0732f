"""Both sides of the numeric thresholds that decide outside the lint rules (issue 39): the collision
matrix's "never" bound and its default-self-collision warning, robot-diff's, fk-verify's and
cross-check's tolerances, cross-check's stability verdict, ``--fail-on`` and scan's keep filters.

Each case sits just past and just inside its threshold (1.01e-9 against 0.99e-9 for a tolerance of
1e-9); the rule's own edges are in tests/test_rule_edges.py, the always threshold and ``settled`` in
tests/test_decisions.py and tests/test_collisions.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ar3cli.lint.rules.base import arm
from tests.conftest import run_cli


# ---- the collision matrix ------------------------------------------------------------------------------
@pytest.mark.parametrize("trials", [10, 300, 10_000])
def test_never_bound_is_the_probability_seen_zero_times_in_5_percent_of_runs(trials):
    """After N clean samples, a pair colliding with probability p stays unseen with probability (1 - p)^N.
    The bound is the p for which that is 5 %: just below it, more likely than 5 %; just above it, less.
    (The rule of three, 3 / N, is 16 % too high at N = 10.)"""
    from ar3cli.collisions.matrix import zero_success_upper_bound

    bound = zero_success_upper_bound(trials)
    assert (1 - 0.99 * bound) ** trials > 0.05 > (1 - 1.01 * bound) ** trials


def test_default_self_collision_warning_starts_at_the_always_threshold(tmp_path):
    """PyBullet's URDF_USE_SELF_COLLISION warning names a pair in contact in 95 of 100 samples, not one in 94."""
    from ar3cli.collisions.matrix import PairResult, findings
    from ar3cli.urdf.model import load_model

    path = tmp_path / "robot.urdf"
    path.write_text(arm())
    model = load_model(path)

    def warned(collisions: int) -> bool:
        pair = PairResult("base", "tool", "sometimes", collisions, 100, False, total=100)  # no parent-child pair
        return any(f.rule == "pybullet-default-self-collision" for f in findings(model, [pair], ["base", "tool"], 0.95))

    assert warned(95) and not warned(94)


# ---- robot diff ----------------------------------------------------------------------------------------
def test_diff_tolerances_edges():
    """1e-9 (m, rad, relative) by default: a change of 1.01e-9 is one, 0.99e-9 is none."""
    from ar3cli.robot_diff.tolerance import Tolerance, origin_changed
    from ar3cli.urdf.model import Origin

    tolerance = Tolerance()
    assert tolerance.relative_change(2.0, 2.0 * (1 + 1.01e-9)) is not None
    assert tolerance.relative_change(2.0, 2.0 * (1 + 0.99e-9)) is None
    assert tolerance.absolute_change(0.3, 0.3 + 1.01e-9, tolerance.length) is not None
    assert tolerance.absolute_change(0.3, 0.3 + 0.99e-9, tolerance.length) is None
    home = Origin(xyz=(0.0, 0.0, 0.3), rpy=(0.0, 0.0, 0.5))
    for moved, changed in (((0.0, 0.0, 0.3 + 1.01e-9), True), ((0.0, 0.0, 0.3 + 0.99e-9), False)):
        assert (origin_changed(home, Origin(xyz=moved, rpy=home.rpy), tolerance) is not None) is changed
    for yaw, changed in ((0.5 + 1.01e-9, True), (0.5 + 0.99e-9, False)):
        assert (origin_changed(home, Origin(xyz=home.xyz, rpy=(0.0, 0.0, yaw)), tolerance) is not None) is changed


def test_diff_cli_default_tolerance_edges(tmp_path):
    """The command's own default (not only the class's): exit 1 just past 1e-9 m, 0 just inside it."""
    old = tmp_path / "old.urdf"
    old.write_text(arm(joint_extra='<origin xyz="0 0 0.3"/><limit lower="-1" upper="1" effort="10" velocity="1"/>'))
    for moved, code in (("0.30000000101", 1), ("0.30000000099", 0)):
        new = tmp_path / f"new_{code}.urdf"
        new.write_text(old.read_text().replace('xyz="0 0 0.3"', f'xyz="0 0 {moved}"'))
        result = run_cli("diff", str(old), str(new), "--samples", "2")
        assert result.code == code, (moved, result.stdout, result.stderr)


# ---- fk-verify ----------------------------------------------------------------------------------------
def test_fk_verify_tolerance_edges():
    """1e-6 m and 1e-6 rad by default; far out, 4 float32 epsilons x the reach (9.54e-6 m at 20 m)."""
    from ar3cli.kinematics.compare import LinkError
    from ar3cli.kinematics.verify import DEFAULT_TOLERANCE_M, DEFAULT_TOLERANCE_RAD, Tolerance

    tolerance = Tolerance(DEFAULT_TOLERANCE_M, DEFAULT_TOLERANCE_RAD, scaled=True)
    assert tolerance.passes(0.99e-6, 0.0) and not tolerance.passes(1.01e-6, 0.0)
    assert tolerance.passes(0.0, 0.99e-6) and not tolerance.passes(0.0, 1.01e-6)
    allowed = 4 * 2.0 ** -23 * 20
    assert tolerance.passes(0.99 * allowed, 0.0, reach=20) and not tolerance.passes(1.01 * allowed, 0.0, reach=20)
    assert not Tolerance(1e-6, 1e-6).passes(0.99 * allowed, 0.0, reach=20)  # a tolerance the user gave is not scaled

    def link(position: float, reach: float) -> LinkError:
        return LinkError("tip", position, position, 0.0, 0.0, 0, np.array([position]), np.array([reach]))

    assert tolerance.link_passes(link(0.99 * allowed, 20)) and not tolerance.link_passes(link(1.01 * allowed, 20))


# ---- cross-check --------------------------------------------------------------------------------------
def _engines(frames_mj, link_masses_mj=None, driven_mj=None):
    """A plan and two engines' data that differ only where a test says."""
    from ar3cli.cross_check.measure import EngineData, Plan

    plan = Plan(["j1"], [("home", {"j1": 0.0})], {"j1": 0.0}, {"j1": 0.05}, followers=["j2"])  # j2 follows j1
    pybullet = EngineData("pybullet", ["j1", "j2"], frames=[{"tip": ((20.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))}], mass=1.0,
                          link_masses={"tip": 1e-3}, com=[(0.0, 0.0, 0.0)], driven={"j1": {"j2": 0.0}})
    mujoco = EngineData("mujoco", ["j1", "j2"], frames=[frames_mj], mass=1.0, link_masses=link_masses_mj or {"tip": 1e-3},
                        com=[(0.0, 0.0, 0.0)], driven={"j1": driven_mj or {"j2": 0.0}})
    return plan, pybullet, mujoco


def _disagreeing(tmp_path, **mujoco) -> set[str]:
    from ar3cli.cross_check.compare import compare
    from ar3cli.urdf.model import load_model

    path = tmp_path / "robot.urdf"
    path.write_text(arm())
    rows = compare(load_model(path), *_engines(**mujoco))
    return {row.quantity for row in rows if not row.agrees}


def test_cross_check_tolerance_edges(tmp_path):
    """Frames at 20 m: 4 float32 epsilons x 20 m; orientations 1e-5 rad; masses 1e-9 kg; a follower moved
    by the probe: a quarter of the leader's step."""
    same = ((20.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    allowed = 4 * 2.0 ** -23 * 20.0

    def at(x: float = 20.0, angle: float = 0.0):
        return {"tip": ((x, 0.0, 0.0), (math.sin(angle / 2), 0.0, 0.0, math.cos(angle / 2)))}

    assert _disagreeing(tmp_path, frames_mj={"tip": same}) == set()
    assert _disagreeing(tmp_path, frames_mj=at(20.0 + 1.01 * allowed)) == {"frame position (m)"}
    assert _disagreeing(tmp_path, frames_mj=at(20.0 + 0.99 * allowed)) == set()
    assert _disagreeing(tmp_path, frames_mj=at(angle=1.01e-5)) == {"frame orientation (rad)"}
    assert _disagreeing(tmp_path, frames_mj=at(angle=0.99e-5)) == set()
    assert _disagreeing(tmp_path, frames_mj=at(), link_masses_mj={"tip": 1e-3 + 1.01e-9}) == {"link mass (kg)"}
    assert _disagreeing(tmp_path, frames_mj=at(), link_masses_mj={"tip": 1e-3 + 0.99e-9}) == set()
    assert _disagreeing(tmp_path, frames_mj=at(), driven_mj={"j2": 0.0505 * 0.25}) == {"constraint: joint moved when driving"}
    assert _disagreeing(tmp_path, frames_mj=at(), driven_mj={"j2": 0.0495 * 0.25}) == set()


def test_stability_verdict_edges():
    """Energy may grow by 5 % of m g L (numerical slack) before the drop is unstable; NaN always is."""
    from ar3cli.cross_check.stability import _verdict

    assert _verdict("pybullet", 0.004, [1.0, 1.0 + 0.0495 * 10], scale=10)["stable"]
    assert not _verdict("pybullet", 0.004, [1.0, 1.0 + 0.0505 * 10], scale=10)["stable"]
    assert not _verdict("mujoco", 0.002, [1.0, math.nan], scale=10)["stable"]


# ---- --fail-on ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("worst, fail_on, failed", [
    ("info", "info", True), ("info", "warning", False),
    ("warning", "warning", True), ("warning", "error", False),
    ("error", "error", True)])
def test_fail_on_fails_at_its_level_and_not_below(worst, fail_on, failed):
    from ar3cli.findings import Finding, Severity
    from ar3cli.lint.engine import LintResult, summarize

    found = [Finding("X001", Severity(level), "m", "robot.urdf") for level in ("info", "warning", "error")
             if Severity(level) <= Severity(worst)]
    assert summarize([LintResult("robot.urdf", True, found)], Severity(fail_on))["failed"] is failed


def test_fail_on_info_exit_codes(tmp_path):
    """An info-only file: exit 1 with --fail-on info, 0 with --fail-on warning (the CLI's side of the edge)."""
    path = tmp_path / "robot.urdf"
    path.write_text(arm().replace('<link name="base">', '<link name="base"><visual><geometry><box size="0.1 0.1 0.1"/>'
                                  '</geometry><material name="nowhere"/></visual>', 1))  # S008 alone: an info
    args = ("lint-urdf", str(path), "--no-cache", "--no-config", "--select", "S008")
    assert run_cli(*args, "--fail-on", "info").code == 1
    assert run_cli(*args, "--fail-on", "warning").code == 0


# ---- scan's keep filters ------------------------------------------------------------------------------
def _row(findings: int = 0, dof: int | None = 3, severity: str = "warning"):
    from ar3cli.scan.record import Row

    return Row("r.urdf", "sha", "key", "findings" if findings else "clean",
               [{"rule": "J008", "severity": severity}] * findings, dof=dof)


@pytest.mark.parametrize("keep, inside, outside", [
    ("max-findings=2", _row(2), _row(3)),
    ("max-findings=0", _row(0), _row(1)),
    ("min-dof=3", _row(dof=3), _row(dof=2)),
    ("max-dof=3", _row(dof=3), _row(dof=4)),
    ("max-severity=warning", _row(1, severity="warning"), _row(1, severity="error")),
    ("max-severity=info", _row(1, severity="info"), _row(1, severity="warning")),
    ("no-errors", _row(1, severity="warning"), _row(1, severity="error")),
    ("no-warnings", _row(1, severity="info"), _row(1, severity="warning")),
])
def test_keep_filter_edges(keep, inside, outside):
    from ar3cli.scan.keep import kept, parse_keep

    assert kept([inside, outside], [parse_keep(keep)]) == [inside]
