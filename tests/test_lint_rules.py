"""Every rule against its documented failing and passing example, plus extra failing snippets.

The examples are the ones printed in docs/rules.md (they live in the registry), so a rule whose
documentation example stops failing (or whose passing example starts failing) breaks this test.
"""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from ar3cli.findings import Severity
from ar3cli.lint.engine import LintOptions, lint_file
from ar3cli.lint.rules import FAMILY_ORDER, REGISTRY, RULES
from ar3cli.lint.rules.base import LINK_INERTIAL, arm, robot

LFS_POINTER = (b"version https://git-lfs.github.com/spec/v1\n"
               b"oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\nsize 12345\n")


def box_stl(size: float) -> bytes:
    """A binary STL of an axis-aligned cube with edge ``size`` (12 triangles)."""
    s = size
    corners = [(x, y, z) for x in (0, s) for y in (0, s) for z in (0, s)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    data = bytearray(b"\0" * 80) + struct.pack("<I", len(faces))
    for face in faces:
        data += struct.pack("<3f", 0, 0, 0)
        for index in face:
            data += struct.pack("<3f", *corners[index])
        data += b"\0\0"
    return bytes(data)


def write_fixture(folder: Path, text: str, files: dict[str, bytes] | None = None) -> Path:
    """Write ``text`` as a robot file with meshes/base.stl (0.1 m) and meshes/base_mm.stl (100 mm)."""
    (folder / "meshes").mkdir(parents=True, exist_ok=True)
    (folder / "meshes" / "base.stl").write_bytes(box_stl(0.1))
    (folder / "meshes" / "base_mm.stl").write_bytes(box_stl(100.0))
    for name, data in (files or {}).items():
        (folder / name).write_bytes(data)
    path = folder / ("robot.urdf.xacro" if "xmlns:xacro" in text else "robot.urdf")
    path.write_text(text, encoding="utf-8")
    return path


def codes_for(path: Path, code: str) -> list:
    rule = REGISTRY[code]
    # naming the code runs an opt-in rule; alone, because with both engines P002 and M003 on one pair are one finding
    targets = LintOptions().targets
    if rule.target_bound and not set(rule.engines) & set(targets):
        targets = rule.engines  # a rule about MuJoCo only (G018) is linted for MuJoCo, where it has its severity
    options = LintOptions(sim=rule.needs_sim, select=[code], targets=targets)
    return [f for f in lint_file(path, options.rules(), options).findings if f.rule == code]


def test_opt_in_rules_run_only_when_named():
    opt_in = {rule.code for rule in RULES if rule.opt_in}
    assert opt_in == {"G012", "G013"}
    assert not opt_in & {rule.code for rule in LintOptions().rules()}
    assert not opt_in & {rule.code for rule in LintOptions(select=["G"]).rules()}
    assert {rule.code for rule in LintOptions(select=["G013"]).rules()} == {"G013"}


def binary_stl(triangles, header: bytes = b"ar3cli test fixture") -> bytes:
    """A binary STL of ``triangles`` (each three (x, y, z) corners)."""
    data = bytearray(header.ljust(80, b" ")[:80]) + struct.pack("<I", len(triangles))
    for triangle in triangles:
        data += struct.pack("<3f", 0, 0, 0)
        for corner in triangle:
            data += struct.pack("<3f", *corner)
        data += b"\0\0"
    return bytes(data)


TETRAHEDRON = (((0, 0, 0), (0, 0.1, 0), (0.1, 0, 0)), ((0, 0, 0), (0.1, 0, 0), (0, 0, 0.1)),
               ((0, 0, 0), (0, 0, 0.1), (0, 0.1, 0)), ((0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1)))
"""A closed, outward-wound 10 cm tetrahedron."""


def ascii_stl(triangles=TETRAHEDRON) -> bytes:
    """The same triangles as an ASCII STL (PyBullet and MuJoCo cannot read it)."""
    facets = "".join("  facet normal 0 0 0\n    outer loop\n"
                     + "".join(f"      vertex {x:g} {y:g} {z:g}\n" for x, y, z in triangle)
                     + "    endloop\n  endfacet\n" for triangle in triangles)
    return f"solid part\n{facets}endsolid part\n".encode()


def u_shape_stl() -> bytes:
    """A closed U-shaped prism, 5 x 4 x 1 cm with 0.5 cm walls: its convex hull is 3.3x its volume.

    The caps are made of quads whose corners are all outline vertices, so the surface is closed
    without T-junctions."""
    outline = [(0, 0), (0.5, 0), (4.5, 0), (5, 0), (5, 0.5), (5, 4), (4.5, 4), (4.5, 0.5), (0.5, 0.5), (0.5, 4),
               (0, 4), (0, 0.5)]
    quads = [[(0, 0), (0.5, 0), (0.5, 0.5), (0, 0.5)], [(0.5, 0), (4.5, 0), (4.5, 0.5), (0.5, 0.5)],
             [(4.5, 0), (5, 0), (5, 0.5), (4.5, 0.5)], [(0, 0.5), (0.5, 0.5), (0.5, 4), (0, 4)],
             [(4.5, 0.5), (5, 0.5), (5, 4), (4.5, 4)]]

    def corner(point, z):
        return point[0] / 100, point[1] / 100, z / 100

    triangles = []
    for a, b, c, d in quads:
        triangles += [(corner(a, 1), corner(b, 1), corner(c, 1)), (corner(a, 1), corner(c, 1), corner(d, 1)),
                      (corner(a, 0), corner(c, 0), corner(b, 0)), (corner(a, 0), corner(d, 0), corner(c, 0))]
    for i, p in enumerate(outline):
        q = outline[(i + 1) % len(outline)]
        triangles += [(corner(p, 0), corner(q, 0), corner(q, 1)), (corner(p, 0), corner(q, 1), corner(p, 1))]
    return binary_stl(triangles)


MESHES = Path(__file__).parent / "data" / "meshes"
"""Small OBJ and COLLADA fixtures (tests/data/meshes/README.md); STL fixtures are made above, as the
repository keeps no .stl file (tests/test_assets.py)."""
EXTRA_FILES = {
    ("G005", "bad"): {"meshes/base.stl": LFS_POINTER},
    ("G011", "bad"): {"meshes/part.stl": ascii_stl()},
    ("G012", "bad"): {"meshes/flat.obj": (MESHES / "flat.obj").read_bytes()},
    ("G013", "bad"): {"meshes/u_shape.stl": u_shape_stl()},
    ("M002", "bad"): {"part.dae": (MESHES / "cube_inches.dae").read_bytes()},  # found: a missing one is G001's
}
"""Files a documented example needs beyond the standard meshes."""

EXTRA_FAILING = [
    ("F002", "", {}),
    ("F002", "\x00\x01\x02binary junk\xff", {}),
    ("F002", '<?xml version="1.0"?>\n<robot name="r">\n  <link name="base">\n', {}),
    ("F005", '\n\n<?xml version="1.0"?>\n<robot name="r"><link name="base"/></robot>\n', {}),
    ("F005", '<?xml version="1.0"?>\n<robot name="r"><link name="base"/></robot>\n\x00\x00\x00', {}),
    ("F006", robot('<link name="${prefix}base"/>'), {}),
    ("F007", arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 nan"/>'), {}),
    ("F007", arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="1,0,0"/>'), {}),
    ("F007", arm(joint_extra='<limit lower="-1" upper="inf" effort="10" velocity="1"/>'), {}),
    ("F007", robot('<link name="b"><visual><geometry><box size="1 1"/></geometry></visual></link>'), {}),
    ("F007", robot('<link name="b"><visual><geometry><mesh filename="meshes/base.stl" scale="1 1"/></geometry></visual></link>'), {}),
    ("S004", robot('<link name="a"/><joint name="j" type="fixed"><parent link="a"/></joint>'), {}),
    ("S005", robot("""<link name="a"/><link name="b"/><link name="c"/><link name="d"/>
        <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
        <joint name="j2" type="fixed"><parent link="c"/><child link="d"/></joint>"""), {}),
    ("S006", robot("""<link name="a"/><link name="b"/><link name="c"/>
        <joint name="j1" type="fixed"><parent link="a"/><child link="c"/></joint>
        <joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>"""), {}),
    ("S007", arm() .replace("</robot>", '  <transmission name="t"><joint name="nope"/></transmission>\n</robot>'), {}),
    ("J005", arm(joint_extra='<limit lower="0" upper="180" effort="10" velocity="1"/>'), {}),
    ("J008", arm(joint_extra='<limit lower="-1" upper="1" effort="-5" velocity="1"/>'), {}),
    ("I001", arm(joint_type="prismatic", link_extra=""), {}),
    ("I001", arm(joint_type="spherical", joint_extra="", link_extra=""), {}),  # PyBullet moves ball joints
    ("I003", arm(joint_type="spherical", joint_extra="",
                 link_extra='<inertial><mass value="0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'), {}),
    ("I003", arm(link_extra='<inertial><mass value="-2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'), {}),
    ("I004", arm(link_extra='<inertial><mass value="1"/><inertia ixx="0.01" ixy="0.02" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'), {}),
    ("I006", arm(link_extra='<inertial><mass value="1"/></inertial>'), {}),
    ("G003", robot(f'<link name="b">{LINK_INERTIAL}<collision><geometry><mesh filename="file:///tmp/x.stl"/></geometry></collision></link>'), {}),
    ("G006", robot(f'<link name="b">{LINK_INERTIAL}<collision><geometry><mesh filename="meshes/base.stl" scale="0.001 0.001 0.001"/></geometry></collision></link>'), {}),
]


@pytest.mark.parametrize("rule", RULES, ids=lambda r: r.code)
def test_documented_failing_example_triggers_the_rule(rule, tmp_path):
    if rule.code == "F001":
        path = tmp_path / "does_not_exist.urdf"
    else:
        path = write_fixture(tmp_path, rule.bad, EXTRA_FILES.get((rule.code, "bad")))
    found = codes_for(path, rule.code)
    assert found, f"{rule.code} did not fire on its failing example"
    assert all(f.severity == rule.severity and f.message and f.hint for f in found)


@pytest.mark.parametrize("rule", RULES, ids=lambda r: r.code)
def test_documented_passing_example_is_clean_for_the_rule(rule, tmp_path):
    path = write_fixture(tmp_path, rule.good, EXTRA_FILES.get((rule.code, "good")))
    assert codes_for(path, rule.code) == []


@pytest.mark.parametrize("code,text,files", EXTRA_FAILING, ids=[f"{c}-{i}" for i, (c, _, _) in enumerate(EXTRA_FAILING)])
def test_extra_failing_snippets(code, text, files, tmp_path):
    path = write_fixture(tmp_path, text, files)
    assert codes_for(path, code), f"{code} did not fire"


def test_every_rule_has_a_failing_fixture_and_complete_docs():
    for rule in RULES:
        assert rule.bad.strip() and rule.good.strip() and rule.why and rule.fix and rule.title, rule.code
        assert rule.code[0] in FAMILY_ORDER and len(rule.code) == 4
        assert isinstance(rule.severity, Severity)
    assert {code for code, _, _ in EXTRA_FAILING} <= set(REGISTRY)


def test_messages_name_the_element_and_report_numbers(tmp_path):
    bad = arm(link_extra='<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.05"/></inertial>')
    (finding,) = codes_for(write_fixture(tmp_path, bad), "I005")
    assert "link 'arm'" in finding.message and "(0.01, 0.01, 0.05)" in finding.message
    (degrees,) = codes_for(write_fixture(tmp_path, arm(joint_extra='<limit lower="-90" upper="90" effort="1" velocity="1"/>')), "J005")
    assert "-1.5708" in degrees.hint and "1.5708" in degrees.hint


def test_mesh_not_found_says_where_it_looked(tmp_path):
    found = codes_for(write_fixture(tmp_path, REGISTRY["G001"].bad), "G001")
    assert len(found) == 2  # the visual and the collision mesh
    finding = found[0]
    assert str(tmp_path / "meshes" / "missing.stl") in finding.message


def test_mesh_units_exempts_ground_planes(tmp_path):
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "plane.obj").write_text("v 0 0 0\nv 100 0 0\nv 100 100 0\nv 0 100 0\nf 1 2 3\nf 1 3 4\n")
    text = robot(f'<link name="plane">{LINK_INERTIAL}<collision><geometry><mesh filename="meshes/plane.obj"/></geometry></collision></link>')
    path = write_fixture(tmp_path, text)
    assert codes_for(path, "G006") == []
    (tmp_path / "meshes" / "plane.obj").write_text("v 0 0 0\nv 100 0 0\nv 100 100 50\nf 1 2 3\n")
    assert codes_for(path, "G006"), "a 100 x 100 x 50 mesh is not flat and must be flagged"


def test_xacro_findings_point_into_the_xacro_source(tmp_path):
    text = ('<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
            '  <xacro:property name="e" value="0"/>\n'
            '  <link name="base"/>\n  <link name="arm"/>\n'
            '  <joint name="j1" type="revolute">\n    <parent link="base"/><child link="arm"/>\n'
            '    <limit lower="-1" upper="1" effort="${e}" velocity="1"/>\n  </joint>\n</robot>\n')
    (finding,) = codes_for(write_fixture(tmp_path, text), "J008")
    assert finding.path.endswith("robot.urdf.xacro") and (finding.line, finding.column) == (8, 5)  # the <limit>
