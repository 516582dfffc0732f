"""Bounded work on hostile input (issue 22, item 2): near-linear rules, one capped non-blocking reader.

Each test is a reproducer of the issue on small generated files. No test asserts a time: growth is
tested by counting the work (how often an index is built, how often a tree is walked), or by inputs
large enough that the old quadratic code would not have finished in a test run.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from ar3cli.errors import UserError

pytestmark = pytest.mark.filterwarnings("ignore")
FIFO = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are a POSIX feature")


def _robot(links: int, shape: str = "chain", joint_type: str = "revolute", extra: str = "",
           link_body: str = "") -> str:
    """``links`` links; each one's parent is the previous link (chain) or the root (star)."""
    lines = ['<?xml version="1.0"?>', '<robot name="r">', f'<link name="l0">{link_body}</link>']
    for index in range(1, links):
        parent = f"l{index - 1}" if shape == "chain" else "l0"
        lines.append(f'<link name="l{index}">{link_body}</link>')
        lines.append(f'<joint name="j{index}" type="{joint_type}"><parent link="{parent}"/><child link="l{index}"/>'
                     '<axis xyz="0 0 1"/></joint>')
    lines += [extra, "</robot>"]
    return "\n".join(lines) + "\n"


def _lint(path: Path, select: list[str] | None = None):
    from ar3cli.lint.engine import LintOptions, lint_file
    from ar3cli.lint.rules import RULES

    rules = [rule for rule in RULES if not rule.needs_sim and (select is None or rule.code in select)]
    return lint_file(path, rules, LintOptions())


# ---- near-linear rules ----------------------------------------------------------------------------


def test_a_long_chain_with_a_cycle_at_its_end_reports_the_cycle_once(tmp_path):
    """S006 used a list for the links seen on each walk and walked from every link to the root: a
    3,000-link chain took 47 s. Each link is now walked once."""
    cycle = '<joint name="back" type="fixed"><parent link="l2999"/><child link="l0"/></joint>'
    path = tmp_path / "chain.urdf"
    path.write_text(_robot(3000, extra=cycle))  # the root hangs from the last link: one 3,000-link loop
    (finding,) = _lint(path, ["S006"]).findings
    assert finding.message.startswith("joints form a cycle through links l1 -> l0 -> l2999 -> l2998")
    assert finding.message.endswith("-> l2992 and 2,991 more")  # a message names 10 links, then counts the rest


def test_inline_ignores_are_gathered_once_per_tree(tmp_path, monkeypatch):
    """A 20,000-link star: suppression walked every sibling of the root for every finding (35 s).
    The ignore comments are now indexed once per file, and still honoured."""
    from ar3cli.lint import engine

    built = []
    original = engine.InlineIgnores.__init__

    def counting(self, root):
        built.append(root)
        original(self, root)

    monkeypatch.setattr(engine.InlineIgnores, "__init__", counting)
    body = "<!-- ar3cli: ignore[J001] -->"
    path = tmp_path / "star.urdf"
    path.write_text(_robot(20000, "star").replace('<joint name="j7" type="revolute">',
                                                  f'<joint name="j7" type="revolute">{body}'))
    result = _lint(path, ["J001"])
    assert len(result.findings) == 20000 - 2  # one per joint without <limit>, but the suppressed one
    assert len(built) == 1


def test_j011_counts_below_each_link_once(tmp_path, monkeypatch):
    """J011 counted the moving joints below every continuous joint by walking the subtree, with a
    scan of every joint per step: a chain of continuous joints was cubic (>120 s for 2,000 links)."""
    from ar3cli.urdf.model import Model

    calls = []
    original = Model.child_joints

    def counting(self, name):
        calls.append(name)
        return original(self, name)

    monkeypatch.setattr(Model, "child_joints", counting)
    path = tmp_path / "continuous.urdf"
    path.write_text(_robot(2000, joint_type="continuous", link_body='<visual><geometry><box size="1 1 1"/></geometry></visual>'))
    result = _lint(path, ["J011"])
    assert len(result.findings) == 2000 - 2  # every continuous joint but the last carries another
    assert len(calls) <= 2 * 2000 + 10


def test_model_parent_and_child_joint_lookups_are_indexed(tmp_path):
    from ar3cli.urdf.model import load_model

    path = tmp_path / "r.urdf"
    path.write_text(_robot(5, "star"))
    model = load_model(path)
    assert model.parent_joint("l3").name == "j3" and model.parent_joint("l0") is None
    assert [j.name for j in model.child_joints("l0")] == ["j1", "j2", "j3", "j4"]
    model.child_joints("l0").clear()  # a caller's list is its own
    assert len(model.child_joints("l0")) == 4 and model.child_joints("nothing") == []


def test_growth_benchmark_generates_the_robots_it_times(tmp_path):
    import subprocess
    import sys

    from conftest import REPO

    done = subprocess.run([sys.executable, str(REPO / "benchmarks" / "bench_growth.py"), "--max-links", "1000",
                           "--write-only", str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["chain_1000.urdf", "star_1000.urdf"]
    assert _lint(tmp_path / "star_1000.urdf").loaded


# ---- the capped, non-blocking reader --------------------------------------------------------------


def test_read_bytes_keeps_its_one_argument_form_and_takes_a_limit(tmp_path):
    from ar3cli.infra.safe_read import read_bytes, read_head

    path = tmp_path / "x.bin"
    path.write_bytes(b"0123456789")
    assert read_bytes(path) == b"0123456789" and read_head(path, 4) == b"0123"
    assert read_bytes(path, limit=10, what="a mesh") == b"0123456789"
    with pytest.raises(UserError, match="limit for meshes; is this really a mesh"):
        read_bytes(path, limit=9, what="a mesh")
    with pytest.raises(UserError, match="limit for robot descriptions"):
        read_bytes(path, limit=9)
    with pytest.raises(UserError, match="is a directory, expected a mesh"):
        read_bytes(tmp_path, what="a mesh")
    with pytest.raises(UserError, match="no such file"):
        read_head(tmp_path / "missing", 4)


@FIFO
def test_fifos_and_devices_are_refused_by_every_reader(tmp_path):
    from ar3cli.infra.safe_read import read_bytes, read_head
    from ar3cli.urdf.meshinfo import mesh_bounds, mesh_content, mesh_loadable, read_mesh

    fifo = tmp_path / "part.stl"
    os.mkfifo(fifo)
    for device in (fifo, Path("/dev/zero")):
        for read in (read_bytes, read_mesh, lambda p: read_head(p, 10)):
            with pytest.raises(UserError, match="not a regular file"):
                read(device)
        assert not mesh_loadable(device)
    assert mesh_content(fifo) == ("not-a-file", None, None)
    assert mesh_bounds(fifo) is None


@pytest.mark.parametrize("command", ["fix-continuous", "fk-verify"])
@pytest.mark.parametrize("kind", ["fifo", "zero", "brackets", "deep", "huge"])
def test_yaml_inputs_are_capped_and_never_block(cli, tmp_path, command, kind):
    """``--limits-from`` / ``--dh`` given a FIFO or /dev/zero hung or grew without bound; 100,000
    nested brackets were exit 3 (RecursionError). Each is now one line and exit 2."""
    urdf = tmp_path / "r.urdf"
    urdf.write_text(_robot(3, joint_type="continuous"))
    yaml_path = tmp_path / "in.yaml"
    if kind == "fifo":
        if not hasattr(os, "mkfifo"):
            pytest.skip("named pipes are a POSIX feature")
        os.mkfifo(yaml_path)
    elif kind == "zero":
        yaml_path = Path("/dev/zero")
    elif kind == "brackets":
        yaml_path.write_text("[" * 100_000 + "]" * 100_000)
    elif kind == "deep":
        yaml_path.write_text("a: " + "[" * 100 + "]" * 100 + "\n")
    else:
        with yaml_path.open("wb") as handle:
            handle.truncate(5 * 1024 * 1024)  # sparse: no disk used
    option = "--limits-from" if command == "fix-continuous" else "--dh"
    result = cli(command, str(urdf), option, str(yaml_path), "--format", "json", timeout=120)
    assert result.code == 2, result.stderr
    assert result.stderr.startswith("ar3cli: error: ") and result.stderr.count("\n") == 1, result.stderr
    assert "Traceback" not in result.stderr and result.stdout == ""
    expected = {"fifo": "not a regular file", "zero": "not a regular file", "brackets": "nest",
                "deep": "nested more than 64 levels", "huge": "MB limit"}[kind]
    assert expected in result.stderr


def test_load_yaml_reads_ordinary_documents(tmp_path):
    from ar3cli.urdf.yamlfile import load_yaml

    path = tmp_path / "limits.yaml"
    path.write_text("joint_limits:\n  j1: {has_position_limits: true, min_position: -1, max_position: 1}\n")
    assert load_yaml(path, "joint limits file")["joint_limits"]["j1"]["max_position"] == 1
    with pytest.raises(UserError, match="joint limits file not found"):
        load_yaml(tmp_path / "missing.yaml", "joint limits file")


def test_an_ancestor_package_xml_is_read_only_at_its_head(tmp_path):
    """A 3 GB package.xml above the robot was read whole; only its first 64 KB are read now (sparse file)."""
    from ar3cli.urdf.packages import _package_xml_name

    package = tmp_path / "big_pkg"
    package.mkdir()
    manifest = package / "package.xml"
    with manifest.open("wb") as handle:
        handle.write(b"<package format='2'><name>big_pkg</name>")
        handle.truncate(3 * 1024 ** 3)
    assert _package_xml_name(package) == "big_pkg"
    assert _package_xml_name(tmp_path) is None


@FIFO
def test_a_fifo_package_xml_or_srdf_is_refused(cli, tmp_path):
    from ar3cli.urdf.packages import _package_xml_name

    os.mkfifo(tmp_path / "package.xml")
    assert _package_xml_name(tmp_path) is None
    urdf = tmp_path / "r.urdf"
    urdf.write_text(_robot(2))
    os.mkfifo(tmp_path / "r.srdf")
    result = cli("lint-urdf", str(urdf), "--sim", "--srdf", str(tmp_path / "r.srdf"), timeout=60)
    assert result.code == 2 and result.stderr.count("\n") == 1 and "not a regular file" in result.stderr


# ---- meshes: bounded by the cap -------------------------------------------------------------------


def _sparse(path: Path, size: int, head: bytes = b"") -> Path:
    with path.open("wb") as handle:
        handle.write(head)
        handle.truncate(size)
    return path


def _mesh_robot(tmp_path: Path, mesh: str) -> Path:
    body = (f'<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
            f'</inertial><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>'
            f'<collision><geometry><mesh filename="{mesh}"/></geometry></collision>')
    path = tmp_path / "r.urdf"
    path.write_text(_robot(2, link_body=body))
    return path


def test_a_mesh_over_the_cap_is_a_finding_not_a_load(tmp_path, monkeypatch):
    """A 199 MB OBJ took 6 GB in a static lint: a mesh over the cap is never read, G011 names it and the cap."""
    from ar3cli.urdf import meshinfo

    _sparse(tmp_path / "huge.obj", meshinfo.MAX_MESH_BYTES + 1, b"v 0 0 0\nv 1 1 1\nv 0 1 0\nf 1 2 3\n")
    read = []
    monkeypatch.setattr(meshinfo, "read_mesh", lambda path: read.append(path))
    result = _lint(_mesh_robot(tmp_path, "huge.obj"))
    g011 = [f for f in result.findings if f.rule == "G011"]
    assert len(g011) == 2 and all("huge.obj" in f.message and "64 MB limit" in f.message for f in g011)
    assert read == []  # never read, not even to box it (G006)
    assert meshinfo.mesh_bounds(tmp_path / "huge.obj") is None


def test_text_meshes_are_boxed_piece_by_piece(tmp_path, monkeypatch):
    """OBJ and ASCII STL vertices are parsed a piece at a time (memory bounded), with the same box."""
    from ar3cli.urdf import meshinfo

    monkeypatch.setattr(meshinfo, "TEXT_CHUNK_BYTES", 64)
    rows = [f"v {i} {-i} {i * 0.5}" for i in range(200)]
    obj = ("\n".join(rows) + "\nf 1 2 3\n").encode()
    stl = ("solid x\n" + "".join(f"facet normal 0 0 1\nouter loop\nvertex {i} {-i} {2 * i}\nendloop\nendfacet\n"
                                 for i in range(100)) + "endsolid x\n").encode()
    assert meshinfo._text_bounds(obj, meshinfo._obj_columns) == ((0.0, -199.0, 0.0), (199.0, 0.0, 99.5))
    assert meshinfo._text_bounds(stl, meshinfo._stl_text_columns) == ((0.0, -99.0, 0.0), (99.0, 0.0, 198.0))


def test_sim_copy_leaves_out_a_mesh_over_the_cap(tmp_path):
    """A 2 GB sparse STL with a valid header took > 8 GB under --sim: pybullet is never handed it."""
    import struct

    from ar3cli.sim.loadable_copy import loadable_document
    from ar3cli.urdf import meshinfo
    from ar3cli.urdf.model import load_model

    count = (meshinfo.MAX_MESH_BYTES // 50) + 1
    _sparse(tmp_path / "huge.stl", 84 + 50 * count, b"\0" * 80 + struct.pack("<I", count))
    _sparse(tmp_path / "small.stl", 84 + 50, b"\0" * 80 + struct.pack("<I", 1))
    assert not meshinfo.mesh_loadable(tmp_path / "huge.stl") and meshinfo.mesh_loadable(tmp_path / "small.stl")
    assert "64 MB limit for meshes" in meshinfo.mesh_refusal(tmp_path / "huge.stl")
    model = load_model(_mesh_robot(tmp_path, "huge.stl"))
    document = loadable_document(model)
    assert b"huge.stl" not in document and b"<collision" not in document and b"<visual" in document
    kept = loadable_document(load_model(_mesh_robot(tmp_path, "small.stl")))
    assert kept.count(b"<collision") == 2 and str(tmp_path / "small.stl").encode() in kept


@FIFO
def test_a_fifo_mesh_is_never_handed_on(tmp_path):
    """A FIFO as a mesh path hung ``--sim``: it is not found by the resolver, refused by every mesh
    reader, and the copy for pybullet would leave it out even if it appeared after resolving."""
    from lxml import etree

    from ar3cli.urdf.meshinfo import leave_out_unloadable_mesh

    os.mkfifo(tmp_path / "part.stl")
    result = _lint(_mesh_robot(tmp_path, "part.stl"))
    assert {f.rule for f in result.findings} >= {"G001"}
    root = etree.fromstring(b'<link><collision><geometry><mesh filename="x"/></geometry></collision></link>')
    assert leave_out_unloadable_mesh(root.find(".//mesh"), tmp_path / "part.stl")
    assert root.find("collision") is None


def test_fix_inertia_mesh_mass_goes_through_the_cap(tmp_path):
    from ar3cli.fix.geometry_mass import GeometryError, load_welded_mesh
    from ar3cli.urdf import meshinfo

    _sparse(tmp_path / "huge.obj", meshinfo.MAX_MESH_BYTES + 1)
    with pytest.raises(GeometryError, match="64 MB limit"):
        load_welded_mesh(tmp_path / "huge.obj")
