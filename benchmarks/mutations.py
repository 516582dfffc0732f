"""Does the test suite catch small, realistic bugs? Apply one-line mutations, one at a time, to a copy
of the project and report which the suite catches.

Each mutation is a bug that once survived the whole suite (issue 39's spot-check) or guards a
decision worth keeping: a threshold moved, a candidate ignored, a mapping value swapped. A mutation
is *caught* when at least one test fails on the mutated copy; it *survives* when every test passes.
The copy is made in a temporary folder (``ar3cli/``, ``tests/``, ``assets/``, ``pyproject.toml``, with
``shared/`` linked beside it as in CI), so the working tree is never touched.

Usage (inside the project's venv)::

    python benchmarks/mutations.py                  # every mutation, the whole suite each (-x: stops at the first failure)
    python benchmarks/mutations.py --quick          # only the tests each mutation names (node ids: a few minutes)
    python benchmarks/mutations.py --only I007-factor,sarif-warning-level
    python benchmarks/mutations.py --list

Exit status: 0 when every mutation is caught, 1 when one survives, 2 when a mutation no longer
applies (its line changed: update the list) or the unmutated copy already fails.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
COPIED = ("ar3cli", "tests", "assets", "pyproject.toml")


@dataclass(frozen=True)
class Mutation:
    """Replace ``old`` (which must occur exactly once in ``file``) by ``new``; ``tests`` catch it quickly."""

    name: str
    file: str
    old: str
    new: str
    tests: tuple[str, ...]
    why: str


EDGE_TEST = "tests/test_rule_edges.py::test_threshold_edge[{}]"


def edges(*names: str) -> tuple[str, ...]:
    """The edge tests of tests/rule_edges.py named ``CODE-CONSTANT`` (as pytest shows them)."""
    return tuple(EDGE_TEST.format(name) for name in names)


EDGES_OUTSIDE = "tests/test_classifier_edges.py"
DECISIONS = "tests/test_decisions.py"

MUTATIONS = (
    # ---- issue 39's spot-check: the bugs that survived the whole suite ----
    Mutation("I007-factor", "ar3cli/lint/rules/inertia.py",
             "IMPLAUSIBLE_FACTOR = 3.0", "IMPLAUSIBLE_FACTOR = 5.0",
             edges("I007-IMPLAUSIBLE_FACTOR"), "I007's factor 3 moved to 5 (the nearest case was at 7.6x)"),
    Mutation("I004-ratio", "ar3cli/lint/rules/inertia.py",
             "NEAR_SINGULAR_RATIO = 1e-9\n", "NEAR_SINGULAR_RATIO = 1e-6\n",
             edges("I009-NEAR_SINGULAR_RATIO", "I006-NEAR_SINGULAR_RATIO"), "the near-singular ratio 1e-9 moved to 1e-6"),
    Mutation("limit-only-pair-never", "ar3cli/collisions/matrix.py",
             "elif collisions == 0 and not hits:", "elif collisions == 0:",
             (DECISIONS,), "a pair touching only at a joint limit classified never, not sometimes"),
    Mutation("diff-type-penalty", "ar3cli/robot_diff/match.py",
             "TYPE_MISMATCH = 10.0", "TYPE_MISMATCH = 0.0",
             (DECISIONS, "tests/test_diff.py"), "robot-diff matching without its joint-type penalty"),
    Mutation("scan-settings-key", "ar3cli/scan/run.py",
             "if known.get(storable(absolute)) != (sha, key):",
             "if known.get(storable(absolute), ('', ''))[0] != sha:",
             (DECISIONS, "tests/test_scan.py"), "scan ignores the settings a row was stored with"),
    Mutation("sarif-warning-level", "ar3cli/output/sarif.py",
             'Severity.WARNING: "warning"', 'Severity.WARNING: "note"',
             (DECISIONS, "tests/test_lint_cli.py"), "SARIF warnings emitted as notes"),
    Mutation("inertia-rotation", "ar3cli/maths/mass_properties.py",
             "rot @ mp.inertia @ rot.T)", "rot.T @ mp.inertia @ rot)",
             (DECISIONS, "tests/test_mass_properties.py"), "R^T I R instead of R I R^T"),
    Mutation("fix-continuous-bytes", "ar3cli/fix/continuous_plan.py",
             "document.remove_element(document.span(limit))",
             "document.splice(document.span(limit).start, document.span(limit).end, b'')",
             ("tests/test_fix_continuous.py",), "the removed <limit> leaves its indentation and line behind"),
    # ---- lint rules: a threshold moved a little, or made inclusive (tests/rule_edges.py) ----
    Mutation("J005-inclusive-720", "ar3cli/lint/rules/joints.py",
             "if not RADIAN_PLAUSIBLE < magnitude <= DEGREE_PLAUSIBLE:",
             "if not RADIAN_PLAUSIBLE < magnitude < DEGREE_PLAUSIBLE:",
             edges("J005-DEGREE_PLAUSIBLE"), "J005 no longer reports exactly 720 (two turns in degrees)"),
    Mutation("J010-unit-tolerance", "ar3cli/lint/rules/joints.py",
             "abs(norm - 1.0) > 1e-3", "abs(norm - 1.0) > 1e-2",
             edges("J010-1e-3"), "J010 tolerates an axis 1 % off unit length"),
    Mutation("J015-turn-slack", "ar3cli/lint/rules/units.py",
             "TURN_SLACK = 0.01", "TURN_SLACK = 0.05",
             edges("J015-FULL_TURN"), "J015's slack above a full turn widened"),
    Mutation("J016-same-speed", "ar3cli/lint/rules/units.py",
             "SAME_SPEED = 0.02", "SAME_SPEED = 0.03",
             edges("J016-SAME_SPEED"), "J016 matches speeds within 3 %, not 2 %"),
    Mutation("I013-max-density", "ar3cli/lint/rules/plausibility.py",
             "MAX_DENSITY = 25_000.0", "MAX_DENSITY = 30_000.0",
             edges("I013-MAX_DENSITY"), "I013's densest material moved above osmium's margin"),
    Mutation("I013-same-material", "ar3cli/lint/rules/plausibility.py",
             "SAME_MATERIAL = 10.0", "SAME_MATERIAL = 20.0",
             edges("I013-SAME_MATERIAL"), "grams said at 20x the robot's typical density"),
    Mutation("I015-mass-ratio", "ar3cli/lint/rules/plausibility.py",
             "MAX_MASS_RATIO = 1000.0", "MAX_MASS_RATIO = 500.0",
             edges("I015-MAX_MASS_RATIO"), "I015 reports 500:1"),
    Mutation("I007-same-shape", "ar3cli/lint/rules/inertia.py",
             "SAME_SHAPE = 5.0", "SAME_SHAPE = 10.0",
             edges("I007-SAME_SHAPE"), "I007 names kg·mm² for a tensor 10x off the typical link"),
    Mutation("G006-scale-mismatch", "ar3cli/lint/rules/geometry.py",
             "SCALE_MISMATCH = (250.0, 4000.0)", "SCALE_MISMATCH = (200.0, 5000.0)",
             edges("G006-SCALE_MISMATCH", "G006-SCALE_MISMATCH-2"), "G006's visual/collision mismatch range widened"),
    Mutation("G008-marker-mass", "ar3cli/lint/rules/geometry.py",
             "MARKER_MASS = 1e-4", "MARKER_MASS = 1e-3",
             edges("G008-MARKER_MASS"), "G008 takes a link of 0.1 % of the robot's mass for a marker"),
    Mutation("G011-stl-size", "ar3cli/urdf/meshinfo.py",
             "if size == 84 + _STL_RECORD * count:", "if size >= 84 + _STL_RECORD * count:",
             edges("G011-84 + 50 x count"), "a binary STL with trailing bytes read as valid"),
    Mutation("G012-hull-volume", "ar3cli/lint/rules/geometry.py",
             "diagonal ** 3", "diagonal ** 2",
             edges("G012-1e-9 of the diagonal cubed"), "G012's hull volume compared with the diagonal squared"),
    Mutation("G013-hull-ratio", "ar3cli/lint/rules/geometry.py",
             "HULL_RATIO = 2.0", "HULL_RATIO = 2.5",
             edges("G013-HULL_RATIO"), "G013 reports hulls 2.5x the volume, not 2x"),
    Mutation("G013-hull-max-bytes", "ar3cli/urdf/meshinfo.py",
             "if stat.st_size > HULL_MAX_BYTES:", "if stat.st_size >= HULL_MAX_BYTES:",
             edges("G013-HULL_MAX_BYTES"), "a mesh of exactly 2 MB no longer examined"),
    Mutation("G014-min-gap", "ar3cli/lint/rules/consistency.py",
             "DETACHED_MIN_GAP = 0.25", "DETACHED_MIN_GAP = 0.3",
             edges("G014-DETACHED_MIN_GAP"), "G014 ignores gaps up to 0.3 m"),
    Mutation("G014-walk", "ar3cli/lint/rules/consistency.py",
             "MAX_WALK = 8", "MAX_WALK = 6",
             edges("G014-MAX_WALK"), "G014 looks through fewer geometry-less links"),
    Mutation("G014-siblings", "ar3cli/lint/rules/consistency.py",
             "MAX_SIBLINGS = 16", "MAX_SIBLINGS = 8",
             edges("G014-MAX_SIBLINGS"), "G014 compares fewer siblings"),
    Mutation("G015-cover", "ar3cli/lint/rules/consistency.py",
             "COVER_MIN = 0.2", "COVER_MIN = 0.25",
             edges("G015-COVER_MIN"), "G015 asks the collision to cover 25 % of the visual"),
    Mutation("G016-axis-min", "ar3cli/lint/rules/consistency.py",
             "AXIS_MIN = 0.1", "AXIS_MIN = 0.15",
             edges("G016-AXIS_MIN"), "G016 ignores axes up to 15 cm off small parts"),
    Mutation("G017-above-one", "ar3cli/lint/rules/units.py",
             "any(v > 1 for v in values[:3])", "any(v >= 1 for v in values[:3])",
             edges("G017-above 1"), "a full-intensity 0-1 colour (1 0 0) taken for 0-255"),
    Mutation("S016-typo-length", "ar3cli/lint/rules/schema.py",
             "TYPO_LENGTH = 2", "TYPO_LENGTH = 3",
             edges("S016-lengths within 2", "S017-lengths within 2"), "misspellings three letters shorter"),
    Mutation("S016-similarity", "ar3cli/lint/rules/schema.py",
             "cutoff=0.6", "cutoff=0.55",
             edges("S016-similarity 0.6", "S017-similarity 0.6"), "misspellings by difflib similarity 0.55"),
    Mutation("F008-candidates", "ar3cli/urdf/macro_library.py",
             "MAX_CANDIDATES = 400", "MAX_CANDIDATES = 300",
             edges("F008-400 files"), "F008 reads fewer files for a library's includer"),
    Mutation("P005-size-fraction", "ar3cli/sim/pass_through.py",
             "SIZE_FRACTION = 0.6", "SIZE_FRACTION = 0.5",
             edges("P005-SIZE_FRACTION"), "P005 reports a pass-through of half the part's size"),
    Mutation("P005-min-depth", "ar3cli/sim/pass_through.py",
             "MIN_NEW_DEPTH = 0.01", "MIN_NEW_DEPTH = 0.02",
             edges("P005-MIN_NEW_DEPTH"), "P005 ignores 2 cm of added depth"),
    Mutation("P005-swept-joints", "ar3cli/sim/pass_through.py",
             "MAX_SWEPT_JOINTS = 64", "MAX_SWEPT_JOINTS = 32",
             edges("P005-MAX_SWEPT_JOINTS"), "P005 sweeps fewer joints"),
    Mutation("P002-penetration", "ar3cli/sim/session.py",
             "PENETRATION_TOLERANCE = 1e-6", "PENETRATION_TOLERANCE = 1e-5",
             edges("P002-1 um"), "P002 ignores overlaps up to 10 µm"),
    Mutation("M003-penetration", "ar3cli/lint/rules/mujoco.py",
             "PENETRATION = 1e-6\n", "PENETRATION = 1e-5\n",
             edges("M003-PENETRATION"), "M003 ignores overlaps up to 10 µm"),
    Mutation("P003-tolerance", "ar3cli/lint/rules/pybullet_sim.py",
             "INERTIA_TOLERANCE = 0.10\n", "INERTIA_TOLERANCE = 0.20\n",
             edges("P003-INERTIA_TOLERANCE-pure"), "P003 tolerates 20 %"),
    Mutation("P004-speed", "ar3cli/lint/rules/pybullet_sim.py",
             "MAX_SETTLE_SPEED = 100.0", "MAX_SETTLE_SPEED = 200.0",
             edges("P004-MAX_SETTLE_SPEED-pure"), "P004 lets a settled joint keep 200 rad/s"),
    # ---- classifiers outside lint (tests/test_classifier_edges.py) ----
    Mutation("never-bound-rule-of-three", "ar3cli/collisions/matrix.py",
             "return 1.0 - (1.0 - confidence) ** (1.0 / trials)", "return 3.0 / trials",
             (EDGES_OUTSIDE,), "the never bound by the rule of three (16 % high at 10 samples)"),
    Mutation("default-self-collision-at-threshold", "ar3cli/collisions/matrix.py",
             "elif key not in adjacent_direct and result.fraction >= always_threshold:",
             "elif key not in adjacent_direct and result.fraction > always_threshold:",
             (EDGES_OUTSIDE,), "the self-collision warning misses a pair at exactly 95 %"),
    Mutation("diff-default-tolerance", "ar3cli/robot_diff/tolerance.py",
             "DEFAULT = 1e-9", "DEFAULT = 1e-8",
             (EDGES_OUTSIDE,), "robot-diff's default tolerance 10x wider"),
    Mutation("diff-cli-default-tolerance", "ar3cli/commands/diff.py",
             "tolerance: ToleranceOption = 1e-9,", "tolerance: ToleranceOption = 1e-8,",
             (EDGES_OUTSIDE,), "the diff command's own default 10x wider"),
    Mutation("fk-verify-reach", "ar3cli/kinematics/verify.py",
             "REACH_EPSILONS = 4.0", "REACH_EPSILONS = 8.0",
             (EDGES_OUTSIDE,), "fk-verify allows 8 float32 epsilons x the reach"),
    Mutation("cross-check-angle", "ar3cli/cross_check/compare.py",
             "ANGLE_FLOOR = 1e-5", "ANGLE_FLOOR = 1e-4",
             (EDGES_OUTSIDE,), "cross-check tolerates 1e-4 rad between the engines' frames"),
    Mutation("cross-check-constraint", "ar3cli/cross_check/compare.py",
             "CONSTRAINT_SHARE = 0.25", "CONSTRAINT_SHARE = 0.5",
             (EDGES_OUTSIDE,), "a joint the probe moved by half the step passes"),
    Mutation("stability-growth", "ar3cli/cross_check/stability.py",
             "GROWTH_SHARE = 0.05", "GROWTH_SHARE = 0.1",
             (EDGES_OUTSIDE,), "a drop may gain 10 % of m g L and stay stable"),
    Mutation("fail-on-inclusive", "ar3cli/lint/engine.py",
             "failing = sum(f.severity >= fail_on for f in findings)",
             "failing = sum(f.severity > fail_on for f in findings)",
             (EDGES_OUTSIDE,), "--fail-on LEVEL fails only above LEVEL"),
    Mutation("keep-max-findings", "ar3cli/scan/keep.py",
             '"max-findings": lambda row: len(row.findings) <= limit',
             '"max-findings": lambda row: len(row.findings) < limit',
             (EDGES_OUTSIDE,), "--keep max-findings=N drops a file with N findings"),
    Mutation("keep-min-dof", "ar3cli/scan/keep.py",
             "row.dof is not None and row.dof >= limit", "row.dof is not None and row.dof > limit",
             (EDGES_OUTSIDE,), "--keep min-dof=N drops a robot of N degrees of freedom"),
    # ---- which candidate wins (tests/test_decisions.py) ----
    Mutation("ros-package-path-order", "ar3cli/urdf/packages.py",
             "for entry in self._ros_paths:", "for entry in reversed(self._ros_paths):",
             (DECISIONS,), "the last ROS_PACKAGE_PATH entry wins"),
    Mutation("ancestor-package-order", "ar3cli/urdf/packages.py",
             "for ancestor in self._ancestors:", "for ancestor in reversed(self._ancestors):",
             (DECISIONS,), "the farthest ancestor package wins"),
    Mutation("pybullet-search-order", "ar3cli/urdf/packages.py",
             "for folder in folders:", "for folder in reversed(folders):",
             (DECISIONS,), "PyBullet's fallback search takes the farthest folder"),
    Mutation("mesh-paths-owner", "ar3cli/fix/mesh_paths_plan.py",
             "return max(owners, key=lambda name: len(folders[name].parts)) if owners else None",
             "return min(owners, key=lambda name: len(folders[name].parts)) if owners else None",
             (DECISIONS,), "fix-mesh-paths gives a file to the outer of two nested packages"),
    Mutation("pyproject-nearest", "ar3cli/lint/config.py",
             "for folder in [start, *start.parents]:", "for folder in [*reversed(start.parents), start]:",
             (DECISIONS,), "the farthest pyproject.toml configures the lint"),
    Mutation("pass-through-parent", "ar3cli/sim/pass_through.py",
             "for joint in model.joints_above(link):", "for joint in reversed(list(model.joints_above(link))):",
             (DECISIONS,), "P005 measures a child against the root, not its nearest ancestor with geometry"),
)


def copy_project(into: Path) -> Path:
    """A copy of the files the suite needs, with ../shared linked beside it where it exists."""
    project = into / "project"
    project.mkdir(parents=True)
    for name in COPIED:
        source = REPO / name
        if source.is_dir():
            shutil.copytree(source, project / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        else:
            shutil.copy2(source, project / name)
    shared = REPO.parent / "shared"
    if shared.is_dir():
        (into / "shared").symlink_to(shared.resolve())
    return project


def mutated(project: Path, mutation: Mutation) -> str:
    """The text of ``mutation.file`` in ``project`` with the mutation applied; exit 2 if it no longer applies."""
    text = (project / mutation.file).read_text(encoding="utf-8")
    count = text.count(mutation.old)
    if count != 1:
        print(f"mutation {mutation.name}: {mutation.old!r} occurs {count} times in {mutation.file}; "
              "update benchmarks/mutations.py", file=sys.stderr)
        raise SystemExit(2)
    return text.replace(mutation.old, mutation.new)


def run_tests(project: Path, tests: tuple[str, ...], timeout: float) -> tuple[bool, str, float]:
    """(passed, the last lines of pytest's output, seconds) for ``tests`` (all when empty) in ``project``."""
    env = {**os.environ, "PYTHONPATH": str(project), "PYTHONDONTWRITEBYTECODE": "1"}
    command = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *tests]
    start = time.perf_counter()
    try:
        done = subprocess.run(command, cwd=project, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return False, f"timed out after {timeout:.0f} s", time.perf_counter() - start
    lines = [line for line in done.stdout.splitlines() if line.strip()]
    failed = [line.removeprefix("FAILED ").split(" - ")[0] for line in lines if line.startswith("FAILED ")]
    summary = lines[-1].strip("= ") if lines else f"pytest exit {done.returncode}"
    return done.returncode == 0, "; ".join([summary, *failed[:1]]), time.perf_counter() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="run only the tests each mutation names")
    parser.add_argument("--only", help="comma-separated mutation names")
    parser.add_argument("--list", action="store_true", help="list the mutations and exit")
    parser.add_argument("--timeout", type=float, default=1800, help="seconds per test run (default 1800)")
    args = parser.parse_args(argv)
    chosen = [m for m in MUTATIONS if not args.only or m.name in args.only.split(",")]
    if args.list or not chosen:
        width = max(len(mutation.name) for mutation in MUTATIONS)
        for mutation in MUTATIONS:
            print(f"{mutation.name:{width}} {mutation.file}: {mutation.why}")
        return 0 if args.list else 2
    with tempfile.TemporaryDirectory(prefix="ar3cli-mutations-") as folder:
        for mutation in chosen:  # every mutation must still apply before anything runs
            mutated(REPO, mutation)
        baseline_tests = tuple(sorted({t for m in chosen for t in m.tests})) if args.quick else ()
        passed, tail, seconds = run_tests(copy_project(Path(folder) / "baseline"), baseline_tests, args.timeout)
        width = max(len(mutation.name) for mutation in chosen)
        print(f"{'unmutated':{width}} {'passes' if passed else 'FAILS':9} {seconds:6.1f} s  {tail}")
        if not passed:
            return 2
        survived = 0
        for mutation in chosen:
            project = copy_project(Path(folder) / mutation.name)
            (project / mutation.file).write_text(mutated(project, mutation), encoding="utf-8")
            passed, tail, seconds = run_tests(project, mutation.tests if args.quick else (), args.timeout)
            survived += passed
            print(f"{mutation.name:{width}} {'SURVIVED' if passed else 'caught':9} {seconds:6.1f} s  {tail}", flush=True)
        print(f"{len(chosen) - survived} of {len(chosen)} mutations caught"
              f" ({'the tests each names' if args.quick else 'the whole suite'})")
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
