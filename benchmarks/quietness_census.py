"""Count two false-alarm classes of docs/quietness.md over ALL findings of a quietness run, not a sample.

The sample of ``benchmarks/quietness.py`` judges up to 25 findings per rule; for the two largest
false classes its estimate is coarse, so this script counts them in every finding of a run saved
with ``--json-out``:

* **G008 on markers and placeholders**: the link's only visuals are boxes or spheres of 1 cm or
  less (a zero-size ``<box size="0 0 0"/>``, a 5 mm sphere drawn at a tool or fingertip frame);
* **J008 on mimic followers**: the joint named by the finding has a ``<mimic>``.

Each robot file is read the way ar3cli reads it (xacro in safe mode, packages found beside it);
a file it cannot read is counted as skipped. Usage (in the project's venv)::

    python benchmarks/quietness.py --json-out run.json
    python benchmarks/quietness_census.py run.json
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections import Counter
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_CACHE = Path("~/.cache/ar3cli-quiet").expanduser()
MARKER_SIZE = 0.01
"""A visual no larger than this (m: box side, sphere radius) draws a frame, not a part."""


def is_marker_link(link) -> bool:
    """The link's only visuals are boxes or spheres of at most MARKER_SIZE."""
    geometries = [visual.find("geometry") for visual in link.findall("visual")]
    shapes = [shape for geometry in geometries if geometry is not None for shape in geometry]
    if not shapes or any(shape.tag not in ("box", "sphere") for shape in shapes):
        return False
    sizes = [float(value) for shape in shapes for value in (shape.get("size") or shape.get("radius") or "1").split()]
    return max(sizes) <= MARKER_SIZE


def census(run: dict, cache: Path) -> Counter[str]:
    sys.path.insert(0, str(REPO))
    from ar3cli.errors import UserError
    from ar3cli.urdf.loading import load_with_specs

    roots: dict[str, object] = {}
    counts: Counter[str] = Counter()
    for finding in run["findings"]:
        if finding["rule"] not in ("G008", "J008"):
            continue
        entry = finding["entry"]
        if entry not in roots:
            try:
                roots[entry] = load_with_specs(cache / "pkgs" / entry, None, None).root
            except UserError:
                roots[entry] = None
        root = roots[entry]
        rule = finding["rule"]
        if root is None:
            counts[f"{rule} skipped"] += 1
            continue
        name = re.search(r"'([^']+)'", finding["message"]).group(1)
        tag = "link" if rule == "G008" else "joint"
        element = next((e for e in root.iter(tag) if e.get("name") == name), None)
        counts[f"{rule} read"] += 1
        if element is None:
            continue
        if rule == "G008" and is_marker_link(element):
            counts["G008 marker"] += 1
        if rule == "J008" and element.find("mimic") is not None:
            counts["J008 follower"] += 1
    return counts


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("run", type=Path, help="a file written by quietness.py --json-out")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="quietness.py's --cache")
    args = parser.parse_args(argv)
    counts = census(json.loads(args.run.read_text(encoding="utf-8")), args.cache.expanduser())
    print(f"G008: {counts['G008 marker']} of {counts['G008 read']} findings ({counts['G008 skipped']} in files "
          f"that could not be read) are on links whose only visuals are boxes/spheres of {MARKER_SIZE * 100:g} cm or less")
    print(f"J008: {counts['J008 follower']} of {counts['J008 read']} findings ({counts['J008 skipped']} in files "
          "that could not be read) are on <mimic> followers")
    return 0


if __name__ == "__main__":
    sys.exit(main())
