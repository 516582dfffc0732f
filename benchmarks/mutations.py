"""Does the test suite catch small, realistic bugs? Apply one-line mutations, one at a time, to a copy
of the project and report which the suite catches.

Each mutation is a bug that once survived the whole suite (issue 39's spot-check) or guards a
decision worth keeping: a threshold moved, a candidate ignored, a mapping value swapped. A mutation
is *caught* when at least one test fails on the mutated copy; it *survives* when every test passes.
The copy is made in a temporary folder (``ar3cli/``, ``tests/``, ``assets/``, ``pyproject.toml``, with
``shared/`` linked beside it as in CI), so the working tree is never touched.

Usage (inside the project's venv)::

    python benchmarks/mutations.py                  # every mutation, the whole suite each (-x: stops at the first failure)
    python benchmarks/mutations.py --quick          # only the tests each mutation names: a minute in all
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


MUTATIONS = (
    Mutation("I007-factor", "ar3cli/lint/rules/inertia.py",
             "IMPLAUSIBLE_FACTOR = 3.0", "IMPLAUSIBLE_FACTOR = 5.0",
             ("tests/test_rule_edges.py",), "I007's factor 3 moved to 5 (the nearest case was at 7.6x)"),
    Mutation("I004-ratio", "ar3cli/lint/rules/inertia.py",
             "NEAR_SINGULAR_RATIO = 1e-9", "NEAR_SINGULAR_RATIO = 1e-6",
             ("tests/test_rule_edges.py",), "I004's near-singular ratio 1e-9 moved to 1e-6"),
    Mutation("limit-only-pair-never", "ar3cli/collisions/matrix.py",
             "elif collisions == 0 and not hits:", "elif collisions == 0:",
             ("tests/test_decisions.py",), "a pair touching only at a joint limit classified never, not sometimes"),
    Mutation("diff-type-penalty", "ar3cli/robot_diff/match.py",
             "TYPE_MISMATCH = 10.0", "TYPE_MISMATCH = 0.0",
             ("tests/test_decisions.py", "tests/test_diff.py"), "robot-diff matching without its joint-type penalty"),
    Mutation("scan-settings-key", "ar3cli/scan/run.py",
             "if known.get(absolute) != (sha, key):", "if known.get(absolute, ('', ''))[0] != sha:",
             ("tests/test_decisions.py", "tests/test_scan.py"), "scan ignores the settings a row was stored with"),
    Mutation("sarif-warning-level", "ar3cli/output/sarif.py",
             'Severity.WARNING: "warning"', 'Severity.WARNING: "note"',
             ("tests/test_decisions.py", "tests/test_lint_cli.py"), "SARIF warnings emitted as notes"),
    Mutation("inertia-rotation", "ar3cli/maths/mass_properties.py",
             "rot @ mp.inertia @ rot.T)", "rot.T @ mp.inertia @ rot)",
             ("tests/test_decisions.py", "tests/test_mass_properties.py"), "R^T I R instead of R I R^T"),
    Mutation("fix-continuous-bytes", "ar3cli/fix/continuous_plan.py",
             "document.remove_element(document.span(limit))",
             "document.splice(document.span(limit).start, document.span(limit).end, b'')",
             ("tests/test_fix_continuous.py",), "the removed <limit> leaves its indentation and line behind"),
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
        for mutation in MUTATIONS:
            print(f"{mutation.name:24} {mutation.file}: {mutation.why}")
        return 0 if args.list else 2
    with tempfile.TemporaryDirectory(prefix="ar3cli-mutations-") as folder:
        for mutation in chosen:  # every mutation must still apply before anything runs
            mutated(REPO, mutation)
        baseline_tests = tuple(sorted({t for m in chosen for t in m.tests})) if args.quick else ()
        passed, tail, seconds = run_tests(copy_project(Path(folder) / "baseline"), baseline_tests, args.timeout)
        print(f"{'unmutated':24} {'passes' if passed else 'FAILS':9} {seconds:6.1f} s  {tail}")
        if not passed:
            return 2
        survived = 0
        for mutation in chosen:
            project = copy_project(Path(folder) / mutation.name)
            (project / mutation.file).write_text(mutated(project, mutation), encoding="utf-8")
            passed, tail, seconds = run_tests(project, mutation.tests if args.quick else (), args.timeout)
            survived += passed
            print(f"{mutation.name:24} {'SURVIVED' if passed else 'caught':9} {seconds:6.1f} s  {tail}", flush=True)
        print(f"{len(chosen) - survived} of {len(chosen)} mutations caught"
              f" ({'the tests each names' if args.quick else 'the whole suite'})")
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
