"""Recall of the unit and reference rules on real robots: inject each mistake, see whether it is found.

Every class of ``tests/unit_injection.py`` (an rpy in degrees, a mass in grams, a tensor in kg·mm² or
g·mm², a velocity in deg/s, a colour in 0-255, a centre of mass in millimetres, soft limits in degrees,
a collision mesh scaled twice, a quat_xyzw under the pybullet target) is injected into every robot
file of example-robot-data (``~/.cache/ar3cli-sweep/erd``, as ``sweep_real_robots.py`` installs it)
and pybullet_data that has a place for it, one mistake at a time; the robot is linted with the rule
that should report it, which must point at the changed element and name the unit. Prints, per class,
the robots injected and found, and every miss. Each robot unmodified is also linted: any finding of
the unit rules on it is listed as a false alarm.

Usage (inside the project's venv, from the repository)::

    python benchmarks/inject_units.py                   # example-robot-data and pybullet_data
    python benchmarks/inject_units.py --source pybullet_data

Exit status: 0 when every injection is found and no unmodified robot gets a unit finding, 1 otherwise.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))  # this checkout's ar3cli and tests/, whatever is installed

from ar3cli.errors import UserError  # noqa: E402
from ar3cli.lint.engine import LintOptions, lint_file  # noqa: E402
from ar3cli.urdf.model import load_model  # noqa: E402
from tests.unit_injection import KINDS, found_at_its_element, inject  # noqa: E402

ERD = Path("~/.cache/ar3cli-sweep/erd/cmeel.prefix/share/example-robot-data").expanduser()
UNIT_RULES = ("J015", "J016", "J017", "I016", "G017", "T009")


def robots(source: str) -> list[Path]:
    found: list[Path] = []
    if source in ("erd", "all") and ERD.is_dir():
        found += sorted(ERD.rglob("*.urdf"))
    if source in ("pybullet_data", "all"):
        import pybullet_data

        root = Path(pybullet_data.getDataPath())
        found += sorted(path for path in root.rglob("*.urdf") if "random_urdfs" not in path.relative_to(root).parts)
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--source", choices=("erd", "pybullet_data", "all"), default="all")
    args = parser.parse_args()
    paths = robots(args.source)
    tally = {kind: [0, 0] for kind in KINDS}
    misses: list[str] = []
    false_alarms: list[str] = []
    quiet = LintOptions(select=[*UNIT_RULES, "I013", "I007", "G006"])
    for path in paths:
        try:
            model = load_model(path)
        except UserError:
            continue
        for finding in lint_file(path, quiet.rules(), quiet).findings:
            if finding.rule in UNIT_RULES or "looks" in finding.message:
                false_alarms.append(f"{path}:{finding.line}: {finding.rule} {finding.message}")
        for kind in KINDS:
            injection = inject(kind, model)
            if injection is None:
                continue
            tally[kind][0] += 1
            found, what = found_at_its_element(path, injection)
            tally[kind][1] += found
            if not found:
                misses.append(f"{kind}: {path}: {what}")
    print(f"{len(paths)} robot files")
    print(f"{'mistake':10} {'injected':>8} {'found':>6}")
    for kind, (injected, found) in tally.items():
        print(f"{kind:10} {injected:8} {found:6}")
    for line in misses:
        print("missed:", line)
    for line in false_alarms:
        print("false alarm on the unmodified robot:", line)
    print(f"{len(false_alarms)} unit findings on the unmodified robots")
    return 1 if misses or false_alarms else 0


if __name__ == "__main__":
    sys.exit(main())
