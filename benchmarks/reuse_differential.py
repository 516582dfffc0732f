"""An editor's check after each keystroke against a full check of the same text, on real robots.

``ar3cli server`` checks the buffer again on every keystroke, and when the keystroke changed one attribute
value of one link or joint it reuses the earlier check's work (``ar3cli/urdf/model_edit.py``,
``ar3cli/lint/reuse.py``). That must never change a finding. This script types random keystrokes into
each robot, as an editor session would (each keystroke on the text the last one left), checks each text
the way the server does (``RobotAnalysis.load(..., earlier=..., editing=True)``, then lint-urdf's static
rules) and the way ``lint-urdf`` does (a fresh load), and compares lint-urdf's whole JSON document
(findings with every field, suppressed counts, errors). A keystroke:

- deletes one character of an attribute value, or types one (a digit, ``.``, ``-``, ``e``, a letter, a
  space, and now and then ``<``, ``"``, ``&`` or a line break, which the fast path refuses), or pastes a
  new value over a whole one: a number, a word, or (one keystroke in seven) the value another element
  of the file gives the same attribute (another link's name, which makes a duplicate; another joint's
  type or parent), the edits whose effect reaches beyond the edited element;
- in any attribute of the file: a joint limit, an origin, a mass, a mesh filename, a link or joint name,
  a joint type, a material colour, a ``<robot>`` attribute;
- or, one keystroke in five, between elements (Enter, an indent, a tab, or a line break or space deleted:
  every element below moves), and one in twenty inside a comment.

Per corpus: the files, the keystrokes, how many took the fast path (the model made from the earlier one),
how many a full load, and the keystrokes whose findings differ (each one printed, with the edit).

Usage (inside the project's venv)::

    python benchmarks/reuse_differential.py                      # example-robot-data, pybullet_data, tests/data, assets
    python benchmarks/reuse_differential.py --keystrokes 100 --seed 7 --corpus quiet=~/.cache/ar3cli-quiet/pkgs

Exit status: 1 when any keystroke's findings differ, 0 otherwise.
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import random
import re
import sys
import time
from collections.abc import Iterator
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

ATTRIBUTE_VALUE = re.compile(r"""\s([\w:.\-]+)\s*=\s*(?:"([^"]*)"|'([^']*)')""")
TYPED = "0123456789.-e" + "0123456789" + "abcxyz_ " + "<\"&\n"
BETWEEN = re.compile(r">(\s)")
COMMENT = re.compile(r"<!--()")
PASTED = ("0", "1.5707963", "-3.14", "1e-3", "0.001 0 0", "0 0 1", "10", "nan", "base_link", "fixed", "revolute",
          "continuous", "prismatic", "world", "package://nowhere/x.stl", "", "1 1 1 1", "255 128 0 1")


def keystrokes(text: str, count: int, seed: int) -> Iterator[tuple[str, str]]:
    """``count`` texts typed from ``text`` one keystroke at a time (each on the text the last one left),
    with a few words saying what each keystroke did."""
    chooser = random.Random(seed)
    for _ in range(count):
        values = [(match.group(1), match.start(group), match.end(group)) for match in ATTRIBUTE_VALUE.finditer(text)
                  for group in (2 if match.group(2) is not None else 3,)]
        if not values:
            return
        name, start, end = chooser.choice(values)
        line = text.count("\n", 0, start) + 1
        action = chooser.random()
        between = [match.start(1) for match in BETWEEN.finditer(text)]
        if action < 0.2 and between:  # Enter, an indent, a line joined: between elements
            at = chooser.choice(between)
            line = text.count("\n", 0, at) + 1
            if chooser.random() < 0.5:
                typed = chooser.choice(("\n", "  ", "\t", "\n    "))
                text, what = text[:at] + typed + text[at:], f"line {line}: typed {typed!r} between elements"
            else:
                text, what = text[:at] + text[at + 1:], f"line {line}: deleted {text[at]!r} between elements"
            yield text, what
            continue
        comments = [match.start(1) for match in COMMENT.finditer(text)]
        if action < 0.25 and comments:
            at = chooser.choice(comments)
            text, what = text[:at] + "x" + text[at:], f"line {text.count(chr(10), 0, at) + 1}: typed 'x' in a comment"
            yield text, what
            continue
        action = chooser.random()
        if action < 0.15:  # another element's value of this attribute: a duplicate name, another link, a type
            pasted = chooser.choice([text[a:b] for other, a, b in values if other == name])
            text, what = text[:start] + pasted + text[end:], f"line {line}: pasted {pasted!r} over {text[start:end]!r}"
        elif action < 0.5 and end > start:
            at = chooser.randrange(start, end)
            text, what = text[:at] + text[at + 1:], f"line {line}: deleted {text[at]!r} of {text[start:end]!r}"
        elif action < 0.9:
            at = chooser.randrange(start, end + 1)
            typed = chooser.choice(TYPED)
            text, what = text[:at] + typed + text[at:], f"line {line}: typed {typed!r} into {text[start:end]!r}"
        else:
            pasted = chooser.choice(PASTED)
            text, what = text[:start] + pasted + text[end:], f"line {line}: pasted {pasted!r} over {text[start:end]!r}"
        yield text, what


def lint_document(analysis) -> str:
    """lint-urdf's JSON document of an analysis' static findings, as text (what must not change)."""
    from ar3cli.analysis.findings import static_findings

    return json.dumps(static_findings(analysis).document, sort_keys=True)


def session(path: Path, count: int, seed: int) -> tuple[int, int, list[str]]:
    """Type ``count`` keystrokes into ``path``'s text: (fast-path checks, full loads, differences)."""
    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.analysis.settings import AnalysisSettings

    settings = AnalysisSettings()
    text = path.read_text(encoding="utf-8", errors="replace")
    earlier = RobotAnalysis.load(path, settings, text, editing=True)
    lint_document(earlier)
    fast = full = 0
    differences = []
    for typed, what in keystrokes(text, count, seed):
        analysis = RobotAnalysis.load(path, settings, typed, earlier=earlier, editing=True)
        fast += analysis.edit is not None
        full += analysis.edit is None
        if lint_document(analysis) != lint_document(RobotAnalysis.load(path, settings, typed)):
            differences.append(f"{path}: {what}")
        earlier = analysis
    return fast, full, differences


def robots(folder: Path) -> list[Path]:
    return sorted(Path(name) for name in glob.glob(str(folder / "**" / "*.urdf"), recursive=True))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--keystrokes", type=int, default=40, help="keystrokes per robot file")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--corpus", action="append", default=[], metavar="NAME=FOLDER",
                        help="a folder of robots (default: example-robot-data, pybullet_data, tests/data, assets)")
    args = parser.parse_args()
    corpora = [tuple(item.split("=", 1)) for item in args.corpus] or default_corpora()
    print("| corpus | files | keystrokes | fast path | full load | findings differ |\n|---|---:|---:|---:|---:|---:|")
    started, failed = time.perf_counter(), []
    for name, folder in corpora:
        files = robots(Path(os.path.expanduser(folder)))
        fast = full = 0
        before = len(failed)
        for index, path in enumerate(files):
            one_fast, one_full, differences = session(path, args.keystrokes, args.seed + index)
            fast, full = fast + one_fast, full + one_full
            failed += differences
        print(f"| {name} | {len(files)} | {fast + full} | {fast} | {full} | {len(failed) - before} |", flush=True)
    for line in failed:
        print(f"- DIFFERENT: {line}")
    print(f"\n{time.perf_counter() - started:.0f} s, seed {args.seed}, {args.keystrokes} keystrokes per file")
    return 1 if failed else 0


def default_corpora() -> list[tuple[str, str]]:
    import pybullet_data

    erd = os.path.expanduser("~/.cache/ar3cli-sweep/erd/cmeel.prefix/share/example-robot-data/robots")
    found = [("example-robot-data", erd)] if os.path.isdir(erd) else []
    return found + [("pybullet_data", pybullet_data.getDataPath()), ("tests/data", str(REPO / "tests" / "data")),
                    ("assets", str(REPO / "assets"))]


if __name__ == "__main__":
    sys.exit(main())
