"""Geometry rules (G): geometry outside the spec, unreadable, flat and over-hulled meshes, COLLADA
units, and the mesh facts (meshinfo) behind them.

Each case is a small robot written to tmp_path; tests/test_lint_pybullet_data.py keeps the real-robot
counts honest.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from ar3cli.findings import Severity
from ar3cli.lint.rules.base import LINK_INERTIAL, robot
from ar3cli.urdf import meshinfo
from tests.lint_helpers import findings, mesh_link, tensor
from tests.test_lint_rules import MESHES, TETRAHEDRON, ascii_stl, binary_stl, codes_for, u_shape_stl, write_fixture

# ---- G010: geometry outside the spec ---------------------------------------------------------------------

@pytest.mark.parametrize("geometry,says", [
    ('<capsule radius="0.05" length="0.2"/>', "urdfdom refuses the whole file"),
    ('<plane normal="0 0 1"/>', "only PyBullet reads it"),
    ('<cdf filename="box.cdf"/>', "only PyBullet reads it"),
    ('<mesh filename="meshes/body.vtk"/>', "Drake reads .vtk"),
    ('<cone radius="1" length="1"/>', "no engine"),
])
def test_non_spec_geometry(tmp_path, geometry, says):
    text = robot(f'<link name="b">{LINK_INERTIAL}<collision><geometry>{geometry}</geometry></collision></link>')
    path = write_fixture(tmp_path, text, {"meshes/body.vtk": b"# vtk DataFile Version 2.0\n"})
    (finding,) = codes_for(path, "G010")
    assert says in finding.message
    assert codes_for(path, "G004") == []  # PyBullet accepts the .vtk name: not "cannot load"


def test_drake_extension_is_named_with_its_prefix(tmp_path):
    text = robot(f'''<link name="b">{LINK_INERTIAL}<collision><geometry><drake:capsule radius="0.1" length="0.2"/>
        </geometry></collision></link>''').replace('<robot name="r">', '<robot name="r" xmlns:drake="http://drake.mit.edu">')
    (finding,) = codes_for(write_fixture(tmp_path, text), "G010")
    assert "<drake:capsule> is not URDF: only Drake reads it" in finding.message


# ---- G011: meshes engines cannot read, by content --------------------------------------------------------

@pytest.mark.parametrize("name,data,says", [
    ("part.stl", ascii_stl(), "ASCII STL"),
    ("part.STL", ascii_stl(), "ASCII STL"),
    ("part.stl", binary_stl(TETRAHEDRON)[:-50], "neither a binary STL"),
    ("part.stl", binary_stl([]), "no triangles"),
    ("part.obj", (MESHES / "points.obj").read_bytes(), "no faces"),
])
def test_unreadable_meshes(tmp_path, name, data, says):
    path = write_fixture(tmp_path, mesh_link(f"meshes/{name}", "visual"), {f"meshes/{name}": data})
    (finding,) = codes_for(path, "G011")
    assert says in finding.message


def test_lfs_pointers_are_g005s_not_g011s(tmp_path):
    from tests.test_lint_rules import LFS_POINTER

    path = write_fixture(tmp_path, mesh_link("meshes/part.stl"), {"meshes/part.stl": LFS_POINTER})
    assert codes_for(path, "G005") and codes_for(path, "G011") == []


def test_binary_stl_whose_header_starts_with_solid_is_readable(tmp_path):
    data = binary_stl(TETRAHEDRON, header=b"solid exported by a CAD tool")
    path = write_fixture(tmp_path, mesh_link("meshes/part.stl"), {"meshes/part.stl": data})
    assert codes_for(path, "G011") == []


# ---- G012: flat collision meshes --------------------------------------------------------------------------

def test_flat_collision_meshes(tmp_path):
    files = {f"meshes/{n}": (MESHES / n).read_bytes() for n in ("flat.obj", "tilted_flat.obj")}
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/flat.obj"), files), "G012")
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/tilted_flat.obj"), files), "G012")
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/flat.obj", "visual"), files), "G012") == []
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/base.stl")), "G012") == []


# ---- G013: hull much larger than the mesh -----------------------------------------------------------------

def test_hull_ratio(tmp_path):
    files = {"meshes/u.stl": u_shape_stl()}
    (finding,) = codes_for(write_fixture(tmp_path, mesh_link("meshes/u.stl"), files), "G013")
    assert "3.3x" in finding.message and finding.severity == Severity.INFO
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/u.stl", "visual"), files), "G013") == []
    concave = mesh_link("meshes/u.stl", extra=' concave="yes"')
    assert codes_for(write_fixture(tmp_path, concave, files), "G013") == []
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/base.stl")), "G013") == []


def test_decomposed_obj_is_one_hull_per_object(tmp_path):
    def cube(offset: float, first: int) -> str:
        corners = [(x + offset, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
        faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
                 (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
        return ("".join(f"v {x} {y} {z}\n" for x, y, z in corners)
                + "".join(f"f {a + first} {b + first} {c + first}\n" for a, b, c in faces))

    two_parts = cube(0, 1) + cube(4, 9)  # one object: PyBullet makes one hull over both cubes
    decomposed = "o a\n" + cube(0, 1) + "o b\n" + cube(4, 9)  # two objects: a hull each
    files = {"meshes/one.obj": two_parts.encode(), "meshes/two.obj": decomposed.encode()}
    (finding,) = codes_for(write_fixture(tmp_path, mesh_link("meshes/one.obj"), files), "G013")
    assert "2.5x" in finding.message
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/two.obj"), files), "G013") == []


# ---- G006: COLLADA units -----------------------------------------------------------------------------------

def test_collada_in_inches_is_not_millimetres(tmp_path):
    inches = (MESHES / "cube_inches.dae").read_bytes()
    files = {"meshes/cube.dae": inches, "meshes/cube_m.dae": inches.replace(b'meter="0.0254"', b'meter="1"')}
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/cube.dae"), files), "G006") == []
    (finding,) = codes_for(write_fixture(tmp_path, mesh_link("meshes/cube_m.dae"), files), "G006")
    assert "6 x 6 x 6 m" in finding.message


# ---- mesh facts ----------------------------------------------------------------------------------------

def test_mesh_content_and_units(tmp_path):
    cases = {"a.stl": ascii_stl(), "b.stl": binary_stl(TETRAHEDRON), "t.stl": binary_stl(TETRAHEDRON)[:-1],
             "e.stl": binary_stl([]), "p.obj": (MESHES / "points.obj").read_bytes(),
             "f.obj": (MESHES / "flat.obj").read_bytes()}
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
    kinds = {name: meshinfo.mesh_content(tmp_path / name) for name in cases}
    assert kinds == {"a.stl": ("stl-ascii", None, None), "b.stl": ("stl-binary", 4, None),
                     "t.stl": ("stl-broken", None, None), "e.stl": ("stl-binary", 0, None),
                     "p.obj": ("obj", 0, 0), "f.obj": ("obj", 2, 1)}
    assert meshinfo.collada_unit(MESHES / "cube_inches.dae") == 0.0254
    (tmp_path / "nounit.dae").write_text('<COLLADA><asset><up_axis>Z_UP</up_axis></asset></COLLADA>')
    assert meshinfo.collada_unit(tmp_path / "nounit.dae") == 1.0
    (tmp_path / "bad.dae").write_text('<COLLADA><asset><unit meter="-1"/></asset></COLLADA>')
    assert meshinfo.collada_unit(tmp_path / "bad.dae") is None


def test_hull_facts(tmp_path):
    (tmp_path / "u.stl").write_bytes(u_shape_stl())
    facts = meshinfo.hull_facts(tmp_path / "u.stl")
    assert facts["closed"] and facts["hull_volume"] / facts["volume"] == pytest.approx(20 / 6, rel=1e-4)
    (tmp_path / "open.stl").write_bytes(binary_stl(TETRAHEDRON[:3]))  # a missing face: not closed
    assert meshinfo.hull_facts(tmp_path / "open.stl")["closed"] is False
    (tmp_path / "flipped.stl").write_bytes(binary_stl([TETRAHEDRON[0][::-1], *TETRAHEDRON[1:]]))
    assert meshinfo.hull_facts(tmp_path / "flipped.stl")["closed"] is False  # inconsistent winding
    (tmp_path / "big.stl").write_bytes(binary_stl(TETRAHEDRON) + b"\0" * meshinfo.HULL_MAX_BYTES)
    assert meshinfo.hull_facts(tmp_path / "big.stl") is None


def test_plain_python_and_numpy_hull_paths_agree(tmp_path):
    for data in (u_shape_stl(), binary_stl(TETRAHEDRON), binary_stl(TETRAHEDRON[:3])):
        (tmp_path / "m.stl").write_bytes(data)
        corners = meshinfo._corners(tmp_path / "m.stl", "stl-binary")
        plain, fast = meshinfo._closed_volume_and_hull(corners), meshinfo._numpy_closed_volume_and_hull(corners)
        assert plain["closed"] == fast["closed"]
        assert plain["volume"] == pytest.approx(fast["volume"], rel=1e-9)
        assert plain["hull_volume"] == pytest.approx(fast["hull_volume"], rel=0.05)


def test_hull_volume_is_exact_for_a_box_and_zero_for_a_plane():
    box = [(x, y, z) for x in (0, 2) for y in (0, 3) for z in (0, 4)] + [(1, 1, 1), (1, 1.5, 4)]
    assert meshinfo._hull_volume(box, 10) == pytest.approx(24, rel=1e-5)
    assert meshinfo._hull_volume([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0.5, 0.5, 0)], 2) == 0.0


# ---- COLLADA <unit meter> in the boxes every size rule uses (issue 30 item 16) ----------------------

def _inch_cube_link(tmp_path: Path, inertial: str) -> Path:
    """A link whose collision is tests/data/meshes/cube_inches.dae: 6 units of 0.0254 m, a 15.24 cm cube."""
    return write_fixture(tmp_path, robot(f'<link name="part">{inertial}<collision><geometry>'
                                         '<mesh filename="cube_inches.dae"/></geometry></collision></link>'),
                         files={"cube_inches.dae": (MESHES / "cube_inches.dae").read_bytes()})


def test_collada_unit_is_applied_to_link_bounds(tmp_path):
    from ar3cli.urdf.bounds import link_bounds, scaled_mesh_bounds
    from ar3cli.urdf.model import load_model

    link = load_model(_inch_cube_link(tmp_path, LINK_INERTIAL)).link("part")
    low, high = link_bounds(link)
    assert low == (0.0, 0.0, 0.0) and high == pytest.approx((0.1524,) * 3, rel=1e-9)
    assert scaled_mesh_bounds(link.collisions[0].geometry)[1] == pytest.approx((6.0,) * 3)  # file units, for G006


def test_implausible_inertia_is_judged_in_metres_for_an_inch_mesh(tmp_path):
    """I = 1 kg·m² on 1 kg: a radius of gyration of 1 m, 7x a 15 cm cube (but not 6 m, the size in file units)."""
    (finding,) = codes_for(_inch_cube_link(tmp_path, tensor(1, 1, 1)), "I007")
    assert "half-diagonal 0.132 m" in finding.message


# ---- G014 leaves a link whose collision alone is off to G015 (alex_nub_hands.urdf, example-robot-data) ----

def test_a_collision_off_its_visual_is_not_blamed_on_the_joint(tmp_path):
    """alex_nub_hands.urdf's nubs write ``<origin xyz="0 1.57 0" rpy="0 0 0"/>`` in <collision> (rpy typed
    into xyz): G015 names the collision; G014 blamed the joint's origin, which is right."""
    part = '<geometry><box size="0.04 0.04 0.04"/></geometry>'
    path = tmp_path / "nub.urdf"
    path.write_text(robot(f"""
        <link name="gripper">{LINK_INERTIAL}<collision><geometry><box size="0.1 0.1 0.15"/></geometry></collision></link>
        <link name="nub">{LINK_INERTIAL}<visual>{part}</visual>
          <collision><origin xyz="0 1.57 0" rpy="0 0 0"/>{part}</collision></link>
        <joint name="attach" type="fixed"><parent link="gripper"/><child link="nub"/><origin xyz="0 0 -0.1"/></joint>"""))
    rules = [f.rule for f in findings(path) if f.rule in ("G014", "G015")]
    assert rules == ["G015"]
