"""Differential proof for safe xacro: every entry point expands to the same bytes in safe and trusted mode.

Usage::

    PYTHONPATH=. python benchmarks/xacro_differential.py [--erd DIR] [--also DIR ...]

Files: every ``*.xacro`` under example-robot-data's robots (``--erd``; by default where
``sweep_real_robots.py`` installs it, skipped with a note when absent: nothing is downloaded),
pybullet_data, this repository's ``tests/data`` and ``assets``, and each ``--also`` folder.

An **entry point** is a file whose trusted expansion, with no ``--xacro-arg``, is a ``<robot>``
with at least one ``<link>``; a file that expands to no link is a macro library (not counted), and
a file that does not expand alone (it needs arguments or packages) is listed apart, with whether
both modes fail alike. Prints ``N of N entry points byte-identical`` and every difference.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DEFAULT_ERD = Path("~/.cache/ar3cli-sweep/erd/cmeel.prefix/share/example-robot-data/robots").expanduser()


def sources(erd: Path, also: list[Path]) -> list[tuple[str, Path]]:
    """(label, folder) of every folder searched; missing ones are reported and skipped."""
    import pybullet_data

    found = [("erd", erd), ("pybullet_data", Path(pybullet_data.getDataPath())),
             ("tests/data", REPO / "tests" / "data"), ("assets", REPO / "assets"),
             *(("also", folder) for folder in also)]
    for label, folder in found:
        if not folder.is_dir():
            print(f"note: {label} folder {folder} not found, skipped", file=sys.stderr)
    return [(label, folder) for label, folder in found if folder.is_dir()]


def expand(path: Path, trusted: bool) -> tuple[bytes | None, str]:
    """The expansion in one mode (bytes, "") or (None, the one-line error)."""
    from ar3cli.errors import UserError
    from ar3cli.urdf import xacro_expand
    from ar3cli.urdf.packages import PackageResolver
    from ar3cli.urdf.xacro_safe import XacroPolicy

    xacro_expand.set_policy(XacroPolicy(trusted=trusted))
    try:
        return xacro_expand.expand(path, {}, PackageResolver(path.parent, {})), ""
    except UserError as exc:
        return None, exc.message


def has_links(data: bytes) -> bool:
    from lxml import etree

    try:
        root = etree.fromstring(data, etree.XMLParser(resolve_entities=False, no_network=True))
    except etree.XMLSyntaxError:
        return False
    return root.tag == "robot" and root.find("link") is not None


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--erd", type=Path, default=DEFAULT_ERD, help="example-robot-data's robots folder")
    parser.add_argument("--also", type=Path, action="append", default=[], help="another folder of .xacro files")
    args = parser.parse_args()
    from ar3cli.output.report import log  # noqa: F401 - imported so xacro's notes go where ar3cli sends them

    identical, different, libraries, alone = [], [], [], []
    seconds = {True: 0.0, False: 0.0}
    for label, folder in sources(args.erd, args.also):
        for path in sorted(folder.rglob("*.xacro")):
            name = f"{label}:{path.relative_to(folder).as_posix()}"
            results = {}
            for trusted in (True, False):
                start = time.perf_counter()
                results[trusted] = expand(path, trusted)
                seconds[trusted] += time.perf_counter() - start
            (trusted_bytes, trusted_error), (safe_bytes, safe_error) = results[True], results[False]
            if trusted_bytes is None:
                alone.append((name, safe_bytes is None, trusted_error))
            elif not has_links(trusted_bytes):
                libraries.append(name)
            elif safe_bytes == trusted_bytes:
                identical.append(name)
            else:
                different.append((name, safe_error or "different bytes"))
    total = len(identical) + len(different)
    print(f"{len(identical)} of {total} entry points byte-identical in safe and trusted mode")
    for name in identical:
        print(f"  same       {name}")
    for name, why in different:
        print(f"  DIFFERENT  {name}: {why}")
    for name in libraries:
        print(f"  library    {name} (expands to no link; not counted)")
    for name, both_fail, error in alone:
        print(f"  needs args {name}: {'both modes fail' if both_fail else 'SAFE EXPANDS, TRUSTED FAILS'}: {error[:160]}")
    print(f"expansion time, all files: trusted {seconds[True]:.2f} s, safe {seconds[False]:.2f} s")
    return 1 if different or any(not both for _, both, _ in alone) else 0


if __name__ == "__main__":
    raise SystemExit(main())
