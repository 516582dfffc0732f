"""Write ``ar3/ar3_dh.yaml``: the AR3's standard DH table, derived numerically from ``ar3/ar3.urdf``.

Run from the repository root: ``python assets/make_ar3_dh.py``. The numbers come from
:func:`ar3cli.kinematics.dh.derive_standard` (joint axes of the URDF at the zero pose, common normals), with
the axis signs (-1, 1, 1, 1, -1, 1) chosen so that frame 0 is the base link frame (z up) and the
table looks like Annin Robotics' published one (alpha -90, 0, -90, -90, 90, 0 deg; d1, d4, d6 > 0).
``tests/test_fk_verify.py`` checks that the committed file still equals this derivation.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
SIGNS = [-1, 1, 1, 1, -1, 1]
HEADER = """\
# AR3 standard DH table for assets/ar3/ar3.urdf, written by assets/make_ar3_dh.py (do not edit).
# Derived from the URDF's joint origins and axes (the real ar3_description numbers), not typed
# from the Annin Robotics manual: that table (d1 169.77 mm, d4 222.63 mm, d6 36.25 mm) describes
# the physical arm, and the URDF's SolidWorks export differs from it by fractions of a millimetre
# (d1 169.525 mm, d4 222.25 mm, a 0.29 mm offset d5, d3 -6.75 mm). Frame 0 is base_link; the chain
# ends on link_6's frame, so base_offset and tool are the identity. Check: ar3cli fk-verify
# assets/ar3/ar3.urdf --dh assets/ar3/ar3_dh.yaml
"""


def table_text() -> str:
    """The YAML text of the table (full double precision, so it matches to ~1e-15)."""
    sys.path.insert(0, str(HERE.parent))
    from ar3cli.kinematics import dh
    from ar3cli.urdf.model import load_model

    doc = dh.derive_standard(load_model(HERE / "ar3" / "ar3.urdf"), "base_link", "link_6", SIGNS)

    def numbers(values) -> str:
        return "[" + ", ".join(_clean(v) for v in values) + "]"

    lines = [HEADER.rstrip("\n"), f"convention: {doc['convention']}", f"base: {doc['base']}", f"tip: {doc['tip']}",
             "units: {length: m, angle: rad}",
             f"base_offset: {{xyz: {numbers(doc['base_offset']['xyz'])}, rpy: {numbers(doc['base_offset']['rpy'])}}}",
             f"tool: {{xyz: {numbers(doc['tool']['xyz'])}, rpy: {numbers(doc['tool']['rpy'])}}}", "joints:"]
    for row in doc["joints"]:
        lines.append(f"  - {{joint: {row['joint']}, a: {_clean(row['a'])}, alpha: {_clean(row['alpha'])}, "
                     f"d: {_clean(row['d'])}, theta_offset: {_clean(row['theta_offset'])}, sign: {row['sign']}}}")
    return "\n".join(lines) + "\n"


def _clean(value: float) -> str:
    """repr of a float, with round-off below 1e-12 written as 0."""
    return "0.0" if abs(value) < 1e-12 else repr(float(value))


def main(argv: list[str] | None = None) -> int:
    (HERE / "ar3" / "ar3_dh.yaml").write_text(table_text(), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
