"""``ar3cli view`` without a browser: what the viewer computes (inertia boxes, centres of mass and link
frames at a pose, contact pairs per pose, the findings on each link, the geometry), the pybullet child
it keeps alive, the reload that keeps the sliders by joint name and the last good robot, the escaping
of the panel's texts and the command's one-line errors. The browser test is test_view_browser.py."""

from __future__ import annotations

import math
import os
import signal
from pathlib import Path

import numpy as np
import pytest

from ar3cli.analysis.contacts import contacts
from ar3cli.analysis.inertia_boxes import LEAD_DENSITY, inertia_box, inertia_boxes
from ar3cli.analysis.link_findings import place_findings
from ar3cli.analysis.meshes import link_meshes
from ar3cli.analysis.poses import posing
from ar3cli.analysis.robot import RobotAnalysis
from ar3cli.errors import UserError
from ar3cli.maths.mass_properties import box as box_properties
from ar3cli.maths.mass_properties import rpy_to_matrix
from tests.conftest import REPO, run_cli

BOX = '<box size="{size}"/>'


def _link(name: str, inertial: str = "", collision: str = "", visual: str = "") -> str:
    return f'<link name="{name}">{inertial}{visual}{collision}</link>'


def _inertial(mass: float, tensor: tuple[float, ...], xyz: str = "0 0 0", rpy: str = "0 0 0") -> str:
    ixx, ixy, ixz, iyy, iyz, izz = (float(value) for value in tensor)
    return (f'<inertial><origin xyz="{xyz}" rpy="{rpy}"/><mass value="{mass!r}"/><inertia ixx="{ixx!r}" '
            f'ixy="{ixy!r}" ixz="{ixz!r}" iyy="{iyy!r}" iyz="{iyz!r}" izz="{izz!r}"/></inertial>')


def _collision(size: str, xyz: str = "0 0 0") -> str:
    return f'<collision><origin xyz="{xyz}"/><geometry>{BOX.format(size=size)}</geometry></collision>'


def _robot(path: Path, *elements: str) -> Path:
    path.write_text('<?xml version="1.0"?>\n<robot name="r">\n' + "\n".join(elements) + "\n</robot>\n",
                    encoding="utf-8")
    return path


def _analysed(path: Path) -> RobotAnalysis:
    analysis = RobotAnalysis.load(path)
    assert analysis.model is not None, analysis.load_error
    return analysis


# ---- inertia boxes and centres of mass ---------------------------------------------------------------

def _tensor(matrix: np.ndarray) -> tuple[float, ...]:
    return (matrix[0, 0], matrix[0, 1], matrix[0, 2], matrix[1, 1], matrix[1, 2], matrix[2, 2])


@pytest.mark.parametrize("rpy", [(0.0, 0.0, 0.0), (0.3, -0.7, 1.9)])
@pytest.mark.parametrize("in_origin", [False, True])
def test_a_box_s_own_inertia_gives_back_the_box(tmp_path, rpy, in_origin):
    """A solid 0.4 x 0.1 x 0.2 m box of 3 kg (maths.mass_properties.box, the independent computation),
    turned by ``rpy`` either in the tensor (a full tensor, origin rpy 0) or by the inertial origin:
    the equivalent box has the same edges, along the turned axes, and its principal moments rebuild the
    tensor."""
    size, mass = np.array([0.4, 0.1, 0.2]), 3.0
    rotation = rpy_to_matrix(rpy)
    solid = box_properties(size, mass=mass).inertia
    tensor = solid if in_origin else rotation @ solid @ rotation.T
    origin_rpy = " ".join(repr(float(angle)) for angle in rpy) if in_origin else "0 0 0"
    path = _robot(tmp_path / "r.urdf", _link("a", _inertial(mass, _tensor(tensor), "0.1 0.2 0.3", origin_rpy)))
    box = inertia_box(_analysed(path).model.links[0])
    assert box is not None and box.problem is None
    assert sorted(box.size) == pytest.approx(sorted(size), rel=1e-9)
    assert box.centre == pytest.approx((0.1, 0.2, 0.3))
    turned = np.array(box.rotation)
    assert turned.T @ turned == pytest.approx(np.eye(3), abs=1e-12) and np.linalg.det(turned) == pytest.approx(1.0)
    link_frame = rotation @ solid @ rotation.T
    assert turned @ np.diag(box.moments) @ turned.T == pytest.approx(link_frame, abs=1e-12)
    for edge, axis in zip(box.size, turned.T):  # each edge lies along the box's own axis with that length
        along = np.abs(rotation.T @ axis)
        assert size[int(np.argmax(along))] == pytest.approx(edge) and along.max() == pytest.approx(1.0)


def test_a_tensor_no_body_has_is_flagged_and_drawn_flat(tmp_path):
    """Moments 1, 1, 3 break the triangle inequality: the box says so, its imaginary edge is 0."""
    path = _robot(tmp_path / "r.urdf", _link("bad", _inertial(2.0, (1.0, 0, 0, 1.0, 0, 3.0))),
                  _link("flat", _inertial(1.0, (0.0, 0, 0, 0.0, 0, 0.0))))
    boxes = {box.link: box for box in inertia_boxes(_analysed(path))}
    assert "triangle inequality" in boxes["bad"].problem and min(boxes["bad"].size) == 0.0
    assert "not positive definite" in boxes["flat"].problem


def test_links_without_a_usable_inertial_get_no_box(tmp_path):
    path = _robot(tmp_path / "r.urdf", _link("none"), _link("massless", _inertial(0.0, (1, 0, 0, 1, 0, 1))),
                  _link("nan", _inertial(1.0, (float("nan"), 0, 0, 1, 0, 1))),
                  _link("ok", _inertial(1.0, (1, 0, 0, 1, 0, 1))))
    assert [box.link for box in inertia_boxes(_analysed(path))] == ["ok"]


def test_the_centre_of_mass_marker_is_a_lead_sphere_of_the_link_s_mass(tmp_path):
    path = _robot(tmp_path / "r.urdf", _link("a", _inertial(10.0, (1, 0, 0, 1, 0, 1))))
    box = inertia_boxes(_analysed(path))[0]
    assert 4 / 3 * math.pi * box.marker_radius ** 3 * LEAD_DENSITY == pytest.approx(10.0)


def test_link_frames_and_centres_of_mass_match_yourdfpy(pybullet_data_dir):
    """The viewer's forward kinematics against yourdfpy's (an independent URDF FK) on the Panda at
    random poses, its mimic finger following; each centre of mass lands at frame @ inertial origin."""
    yourdfpy = pytest.importorskip("yourdfpy")
    path = pybullet_data_dir / "franka_panda" / "panda.urdf"
    analysis = _analysed(path)
    posed = posing(analysis)
    assert posed.followers == {"panda_finger_joint2": ("panda_finger_joint1", 1.0, 0.0)}
    assert "panda_finger_joint2" not in posed.control_names
    reference = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False,
                                   load_collision_meshes=False)
    rng = np.random.default_rng(3)
    boxes = inertia_boxes(analysis)
    for _ in range(5):
        values = posed.random(rng)
        frames = posed.frames(values)
        reference.update_cfg(posed.joint_values(values))
        for link in analysis.model.links:
            assert frames[link.name] == pytest.approx(reference.get_transform(link.name), abs=1e-9), link.name
        for box in boxes:
            expected = reference.get_transform(box.link) @ np.array([*box.centre, 1.0])
            assert (frames[box.link] @ np.array([*box.centre, 1.0]))[:3] == pytest.approx(expected[:3], abs=1e-9)


def test_controls_follow_the_simulation_s_ranges(tmp_path):
    """Limited joints get their limits and home (mid-range when 0 is outside), continuous and unlimited
    ones -pi..pi (prismatic -1..1); a zero axis is drawn still; a mimic cycle gets sliders of its own."""
    joint = '<joint name="{n}" type="{t}"><parent link="{p}"/><child link="{c}"/><axis xyz="{a}"/>{extra}</joint>'
    path = _robot(tmp_path / "r.urdf", *(_link(name) for name in "abcdefg"),
                  joint.format(n="lim", t="revolute", p="a", c="b", a="0 0 1",
                               extra='<limit lower="0.5" upper="1.5" effort="1" velocity="1"/>'),
                  joint.format(n="cont", t="continuous", p="b", c="c", a="0 0 1", extra=""),
                  joint.format(n="slide", t="prismatic", p="c", c="d", a="1 0 0",
                               extra='<limit lower="1" upper="-1" effort="1" velocity="1"/>'),
                  joint.format(n="zero", t="revolute", p="d", c="e", a="0 0 0",
                               extra='<limit lower="-1" upper="1" effort="1" velocity="1"/>'),
                  joint.format(n="m1", t="continuous", p="e", c="f", a="0 1 0", extra='<mimic joint="m2"/>'),
                  joint.format(n="m2", t="continuous", p="f", c="g", a="0 1 0", extra='<mimic joint="m1"/>'))
    posed = posing(_analysed(path))
    controls = {control.name: control for control in posed.controls}
    assert (controls["lim"].lower, controls["lim"].upper, controls["lim"].home) == (0.5, 1.5, 1.0)
    assert (controls["cont"].lower, controls["cont"].upper) == (-math.pi, math.pi) and not controls["cont"].limited
    assert (controls["slide"].lower, controls["slide"].upper) == (-1.0, 1.0)
    assert "zero" not in controls and any("zero is drawn still" in note for note in posed.notes)
    assert {"m1", "m2"} <= set(controls) and any("form a cycle" in note for note in posed.notes)
    frames = posed.frames({"lim": 1.5, "zero": 1.0})
    assert np.isfinite(np.array(list(frames.values()))).all() and set(frames) == set("abcdefg")


def test_sliders_are_kept_by_joint_name_and_clamped(tmp_path):
    """A reload's home pose takes the earlier values of the joints it still has, within their new range."""
    revolute = '<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/><axis xyz="0 0 1"/>' \
               '<limit lower="-{u}" upper="{u}" effort="1" velocity="1"/></joint>'
    path = _robot(tmp_path / "r.urdf", *(_link(name) for name in "abc"), revolute.format(n="j1", p="a", c="b", u=2),
                  revolute.format(n="j2", p="b", c="c", u=0.5))
    kept = posing(_analysed(path)).kept({"j1": 1.2, "j2": 2.0, "gone": 3.0})
    assert kept == {"j1": 1.2, "j2": 0.5}


# ---- contacts ------------------------------------------------------------------------------------------

def _contact_robot(path: Path) -> Path:
    """base - arm (revolute about y) - wrist (no geometry) - tool, and a post fixed beside the base. At 0
    the arm's box reaches into the post (two children of the base: not adjacent) and into the base
    (adjacent), and the tool's box into the arm (adjacent across the geometry-less wrist: MoveIt's rule)."""
    unit = _inertial(1.0, (0.01, 0, 0, 0.01, 0, 0.01))
    return _robot(path,
                  _link("base", unit, _collision("0.2 0.2 0.1")),
                  _link("post", unit, _collision("0.1 0.1 0.1", "0.3 0 -0.05")),
                  _link("arm", unit, _collision("0.3 0.1 0.1", "0.15 0 0")),
                  _link("wrist", unit),
                  _link("tool", unit, _collision("0.1 0.1 0.1", "-0.05 0 0.06")),
                  '<joint name="fix" type="fixed"><parent link="base"/><child link="post"/></joint>',
                  '<joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>'
                  '<limit lower="-2" upper="2" effort="1" velocity="1"/></joint>',
                  '<joint name="w1" type="fixed"><parent link="arm"/><child link="wrist"/>'
                  '<origin xyz="0.3 0 0"/></joint>',
                  '<joint name="w2" type="fixed"><parent link="wrist"/><child link="tool"/></joint>')


def test_contacts_per_pose_leave_adjacent_pairs_out(tmp_path):
    """At home the arm is in the post (reported) and in the base and the tool (adjacent, the tool
    across the geometry-less wrist: left out, as sample-collisions does); turned up, nothing touches.
    One pybullet child answers both poses, and closing the analysis ends it."""
    analysis = _analysed(_contact_robot(tmp_path / "r.urdf"))
    posed = posing(analysis)
    assert contacts(analysis, posed.joint_values(posed.home())).pairs == [("post", "arm")]
    assert contacts(analysis, posed.joint_values({"shoulder": -1.5})).pairs == []
    assert contacts(analysis, posed.joint_values(posed.home())).pairs == [("post", "arm")]
    child = analysis.keep("contacts", lambda: None)
    pid = child._pid
    analysis.close()
    assert child._pid is None and not _alive(pid)


def test_a_robot_with_one_collision_link_has_no_contacts_to_check(tmp_path):
    path = _robot(tmp_path / "r.urdf", _link("only", collision=_collision("0.1 0.1 0.1")))
    found = contacts(_analysed(path), {})
    assert found.pairs == [] and "only one link" in found.note


def test_a_pybullet_crash_is_one_line_and_stays(tmp_path):
    """The kept child killed by SIGSEGV (as pybullet's C code dies): the question is a one-line
    error naming the file and what it was doing, and every later question raises it at once."""
    analysis = _analysed(_contact_robot(tmp_path / "r.urdf"))
    posed = posing(analysis)
    contacts(analysis, posed.home())
    child = analysis.keep("contacts", lambda: None)
    os.kill(child._pid, signal.SIGSEGV)
    with pytest.raises(UserError) as first:
        contacts(analysis, posed.home())
    assert "pybullet crashed (SIGSEGV) while checking contacts" in first.value.message
    assert str(tmp_path / "r.urdf") in first.value.message and "\n" not in first.value.message
    with pytest.raises(UserError) as again:
        contacts(analysis, posed.home())
    assert again.value is first.value
    analysis.close()


def test_a_link_whose_mesh_is_missing_is_left_out_and_named(tmp_path):
    """One missing mesh stops nothing (issue 36 item 3): the other links are checked, the note names it."""
    path = _robot(tmp_path / "r.urdf", _link("a", collision=_collision("0.1 0.1 0.1")),
                  _link("b", collision='<collision><geometry><mesh filename="missing.stl"/></geometry></collision>'),
                  '<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>')
    found = contacts(_analysed(path), {})
    assert found.pairs == [] and found.unchecked == ["b"] and found.note is None
    from ar3cli.view.describe import contact_pairs

    assert contact_pairs(found) == "none (not checked, their collision mesh does not load: b)"


def _alive(pid: int | None) -> bool:
    if pid is None:
        return False
    try:
        finished, _ = os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return False
    return finished == 0


# ---- findings on links, geometry -------------------------------------------------------------------

def test_findings_land_on_the_link_they_are_about(tmp_path):
    """A link's own finding (I003, mass) and its parent joint's (J009, axis) land on it, an orphan's on
    the orphan; in a one-line file every line belongs to several links: nothing is placed on a guess."""
    from ar3cli.analysis.findings import static_findings

    elements = (_link("a", _inertial(1.0, (1, 0, 0, 1, 0, 1))), _link("b", _inertial(-1.0, (1, 0, 0, 1, 0, 1))),
                _link("c"), '<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 0"/>'
                            '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    analysis = _analysed(_robot(tmp_path / "r.urdf", *elements))
    placed = place_findings(analysis, static_findings(analysis).findings)
    assert {link: [(f.rule, f.line) for f in found] for link, found in placed.by_link.items()} == {
        "b": [("I003", 4), ("J009", 6)], "c": [("S005", 5)]}
    assert placed.unplaced == [] and placed.worst("b").value == "error" and placed.worst("a") is None
    one_line = tmp_path / "one.urdf"
    one_line.write_text('<robot name="r">' + "".join(elements) + "</robot>", encoding="utf-8")
    analysis = _analysed(one_line)
    found = static_findings(analysis).findings
    placed = place_findings(analysis, found)
    assert placed.by_link == {} and placed.unplaced == found and found


def test_geometry_is_in_the_link_frame_with_its_origin_and_scale(tmp_path):
    """A box at its collision origin, a mesh scaled (the U-shaped STL of the fixers' tests) and mirrored
    (negative scale: faces turned so they still face out), a missing mesh noted, not drawn."""
    from tests.test_fix_collision import U_CELLS, voxel_mesh

    voxel_mesh(U_CELLS).export(str(tmp_path / "u.stl"))
    path = _robot(tmp_path / "r.urdf",
                  _link("a", collision=_collision("0.2 0.4 0.6", "1 2 3"),
                        visual='<visual><geometry><mesh filename="u.stl" scale="2 2 -2"/></geometry>'
                               '<material name="m"><color rgba="1 0 0 1"/></material></visual>'
                               '<visual><geometry><mesh filename="gone.stl"/></geometry></visual>'))
    meshes = link_meshes(_analysed(path))
    (box,) = meshes.of("a", "collision")
    assert box.vertices.min(axis=0) == pytest.approx([0.9, 1.8, 2.7]) and box.rgba is None
    (u_shape,) = meshes.of("a", "visual")
    assert u_shape.rgba == (1.0, 0.0, 0.0, 1.0)
    assert np.ptp(u_shape.vertices, axis=0) == pytest.approx([0.14, 0.18, 0.02], abs=1e-6)
    assert u_shape.vertices[:, 2].max() <= 1e-9  # z mirrored
    assert len(meshes.notes) == 1 and "gone.stl" in meshes.notes[0]


# ---- the viewer: reloads, on a real viser server with no browser -----------------------------------

@pytest.fixture
def viser_server():
    viser = pytest.importorskip("viser")
    from ar3cli.view.server import start_server

    assert viser
    server = start_server("127.0.0.1", 0)
    yield server
    server.stop()


def test_a_reload_keeps_sliders_by_name_and_a_broken_file_keeps_the_last_good_robot(tmp_path, viser_server):
    from ar3cli.view.viewer import Viewer

    path = _contact_robot(tmp_path / "r.urdf")
    lines: list[str] = []
    viewer = Viewer(viser_server, RobotAnalysis.load(path), log=lines.append)
    try:
        viewer.move({"shoulder": 0.7})
        assert viewer.panel.sliders["shoulder"].value == pytest.approx(0.7)
        text = path.read_text()
        path.write_text(text.replace('<origin xyz="0.3 0 0"/></joint>', '<origin xyz="0.35 0 0"/></joint>')
                        .replace('name="w1"', 'name="wrist_1"'))
        assert viewer.poll()
        first = viewer.shown
        assert viewer.values == {"shoulder": 0.7} and viewer.panel.sliders["shoulder"].value == pytest.approx(0.7)
        assert viewer.scene.links["tool"].frame.position[0] != 0.0
        assert "reloaded 5 links" in lines[-1]
        path.write_text(text.replace("</robot>", ""))  # no longer parses
        assert viewer.poll()
        assert viewer.shown is first and viewer.latest is not first and viewer.scene is not None
        assert "Does not load" in viewer.panel.status.content and "does not load" in lines[-1]
        assert not viewer.poll()  # nothing changed since
        path.write_text(text)  # fixed: drawn again, the slider where it was
        assert viewer.poll() and viewer.shown is not first and viewer.values == {"shoulder": 0.7}
        assert "Does not load" not in viewer.panel.status.content
        viewer.home()
        assert viewer.values == {"shoulder": 0.0} and viewer.panel.sliders["shoulder"].value == 0.0
    finally:
        viewer.close()


def test_an_included_xacro_or_a_mesh_that_changes_is_redrawn(tmp_path, viser_server):
    """Live reload sees more than the robot file: the xacro file it includes, and a mesh."""
    import shutil

    from ar3cli.analysis.inertia_boxes import inertia_boxes as boxes_of
    from ar3cli.view.viewer import Viewer
    from tests.test_fix_collision import U_CELLS, voxel_mesh

    shutil.copytree(REPO / "tests" / "data" / "xacro", tmp_path / "xacro")
    macros = tmp_path / "xacro" / "macros" / "arm_segment.xacro"
    voxel_mesh(U_CELLS).export(str(tmp_path / "xacro" / "u.stl"))
    top = tmp_path / "xacro" / "arm.urdf.xacro"
    top.write_text(top.read_text().replace('<link name="wrist_link"/>', '<link name="wrist_link"><visual><geometry>'
                                           '<mesh filename="u.stl"/></geometry></visual></link>'), encoding="utf-8")
    lines: list[str] = []
    viewer = Viewer(viser_server, RobotAnalysis.load(top), log=lines.append)
    try:
        def mass(link: str) -> float:
            return next(box.mass for box in boxes_of(viewer.shown) if box.link == link)

        def width() -> float:
            return float(np.ptp(link_meshes(viewer.shown).of("wrist_link")[0].vertices[:, 0]))

        assert mass("shoulder_link") == 0.5 and width() == pytest.approx(0.07)
        macros.write_text(macros.read_text().replace('value="0.5"', 'value="0.75"'), encoding="utf-8")
        assert viewer.poll() and mass("shoulder_link") == 0.75 and "arm_segment.xacro changed" in lines[-1]
        voxel_mesh([(x, 0, 0) for x in range(10)]).export(str(tmp_path / "xacro" / "u.stl"))
        assert viewer.poll() and width() == pytest.approx(0.1) and "u.stl changed" in lines[-1]
        assert "inertia" in viewer.scene.links["shoulder_link"].extras
    finally:
        viewer.close()


def test_random_poses_follow_the_seed(tmp_path, viser_server):
    from ar3cli.view.viewer import Viewer

    path = _contact_robot(tmp_path / "r.urdf")
    poses = []
    for _ in range(2):
        viewer = Viewer(viser_server, RobotAnalysis.load(path), seed=5, log=lambda line: None)
        try:
            viewer.random_pose()
            viewer.random_pose()
            poses.append(dict(viewer.values))
        finally:
            viewer.close()
    assert poses[0] == poses[1] and -2 <= poses[0]["shoulder"] <= 2


FORK_WHILE_WRITING = """
import io, os, sys, threading, time
from ar3cli.view.streams import fork_safe_streams
read_end, write_end = os.pipe()
sys.stderr = io.TextIOWrapper(io.BufferedWriter(io.FileIO(write_end, "w")))
with fork_safe_streams():
    threading.Thread(target=lambda: sys.stderr.write("x" * (1 << 20)), daemon=True).start()
    time.sleep(0.3)  # that thread is inside its write now: the pipe holds 64 KB
    threading.Thread(target=lambda: (time.sleep(0.5), [os.read(read_end, 1 << 16) for _ in range(16)]),
                     daemon=True).start()
    pid = os.fork()
    if pid == 0:
        sys.stderr.flush()  # what every pybullet child does first (sim.capture.capture_fds)
        os._exit(0)
    for _ in range(50):
        if os.waitpid(pid, os.WNOHANG)[0]:
            print("ended", file=sys.__stdout__)
            break
        time.sleep(0.1)
    else:
        os.kill(pid, 9)
        print("hung", file=sys.__stdout__)
os._exit(0)
"""


def test_a_child_forked_while_another_thread_writes_can_still_write():
    """The viewer forks pybullet children while its threads write to stderr: a child forked in the middle
    of a write inherited stderr's lock locked and waited forever (the simulated lint timed out after
    120 s). With the streams guarded, the fork waits for the write and the child flushes at once."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", FORK_WHILE_WRITING], capture_output=True, text=True, timeout=60,
                          env={**os.environ, "PYTHONPATH": str(REPO)})
    assert done.stdout.strip() == "ended", done.stdout + done.stderr


# ---- texts and the command ---------------------------------------------------------------------

def test_robot_strings_cannot_become_markup():
    from ar3cli.view.text import literal

    hostile = '<img src=x onerror="alert(1)">![t](http://x/y.png) [l](javascript:alert(1)) **b** `c`\n# h &amp;'
    shown = literal(hostile)
    assert "\n" not in shown
    unescaped = [char for index, char in enumerate(shown) if char in "<>[]()!*`#&" and shown[index - 1] != "\\"]
    assert unescaped == []
    assert literal("x" * 1000).endswith("\u2026") and len(literal("\x1b[31m")) > 4


def test_view_without_viser_names_the_pip_command(tmp_path):
    fake = tmp_path / "site" / "viser"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('No module named viser')\n")
    robot = _contact_robot(tmp_path / "r.urdf")
    done = run_cli("view", str(robot), env={"PYTHONPATH": f"{fake.parent}{os.pathsep}{REPO}"})
    assert done.code == 2
    assert done.stderr.strip().splitlines() == [
        "ar3cli: error: the viewer needs viser, which is not installed (No module named viser); "
        "run: pip install 'ar3cli[view]'"]


def test_view_refuses_a_missing_file_and_a_busy_port(tmp_path):
    pytest.importorskip("viser")
    import socket

    done = run_cli("view", str(tmp_path / "nothing.urdf"))
    assert done.code == 2 and done.stderr.strip() == f"ar3cli: error: {tmp_path / 'nothing.urdf'}: no such file"
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        robot = _contact_robot(tmp_path / "r.urdf")
        done = run_cli("view", str(robot), "--port", str(port))
    assert done.code == 2 and f"127.0.0.1 port {port} is in use" in done.stderr, done.stderr
    done = run_cli("view", str(robot), "--host", "192.0.2.1")  # TEST-NET-1: never this machine's
    assert done.code == 2 and "192.0.2.1 port 8080 cannot be listened on" in done.stderr, done.stderr
    assert "warning: listening on 192.0.2.1" in done.stderr


def test_json_output_is_the_url_document_alone(tmp_path):
    """``--format json``: stdout holds ``{"url", "path"}`` alone, printed once the robot is drawn."""
    pytest.importorskip("viser")
    import json
    import subprocess
    import sys

    robot = _contact_robot(tmp_path / "r.urdf")
    process = subprocess.Popen([sys.executable, "-m", "ar3cli", "view", str(robot), "--port", "0", "--format", "json"],
                               env={**os.environ, "PYTHONPATH": str(REPO)}, stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL, text=True)
    try:
        text = ""
        while not text.rstrip().endswith("}"):
            line = process.stdout.readline()
            assert line, "stdout ended without a JSON document"
            text += line
        document = json.loads(text)
        assert set(document) == {"url", "path"} and document["path"] == str(robot)
        assert document["url"].startswith("http://127.0.0.1:")
        process.send_signal(signal.SIGTERM)
        assert process.wait(60) == 143 and process.stdout.read() == ""
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()


SWALLOWED_SIGTERM = """
import os, signal, sys, time
import ar3cli.view.viewer as viewer

polls = []
original = viewer.Viewer.poll

def poll(self):
    if not polls:
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            deadline = time.monotonic() + 2
            while time.monotonic() < deadline:  # Python code running when the handler raises
                pass
        except BaseException:  # as trimesh does around its optional imports and in some methods
            pass
    polls.append(1)
    return original(self)

viewer.Viewer.poll = poll
sys.argv = ["ar3cli", "view", sys.argv[1], "--port", "0"]
from ar3cli.cli import run
run()
"""


def test_a_sigterm_that_library_code_swallows_still_stops_the_viewer(tmp_path):
    """Only the first SIGTERM is raised, and trimesh catches BaseException: a SIGTERM 1.2 s after the
    start, during ``import trimesh``, left the viewer running and deaf to every later SIGTERM. The poll
    loop now checks whether one came and raises it."""
    pytest.importorskip("viser")
    import subprocess
    import sys

    robot = _contact_robot(tmp_path / "r.urdf")
    done = subprocess.run([sys.executable, "-c", SWALLOWED_SIGTERM, str(robot)], capture_output=True, text=True,
                          timeout=120, env={**os.environ, "PYTHONPATH": str(REPO)}, cwd=tmp_path)
    assert done.returncode == 143, done.stderr
    assert done.stderr.strip().endswith("ar3cli: terminated")


def test_the_panel_shows_a_hostile_robot_s_names_as_text(tmp_path):
    """The output boundary (issue 34) for the viewer: the panel texts of a robot whose names hold a
    newline with a workflow command, ESC, C1, a bidi override, Markdown images and links and a
    <script> render (as the browser's Markdown renders them) to plain text, every name shown."""
    from ar3cli.analysis.findings import static_findings
    from ar3cli.view.describe import findings_list, link_card
    from tests.test_output_boundary import RAW, SHOWN, _rendered, robot

    (tmp_path / "meshes").mkdir()
    path = tmp_path / "hostile.urdf"
    path.write_text(robot())
    analysis = RobotAnalysis.load(path)
    placed = place_findings(analysis, static_findings(analysis).findings)
    pages = [findings_list(placed, analysis.shown_path)]
    pages += [link_card(analysis, link.name, placed.by_link.get(link.name, []), [], analysis.shown_path)
              for link in analysis.require_model().links]
    for page in pages:
        parsed = _rendered(page)
        assert {tag for tag, _ in parsed.tags} <= {"p", "ul", "li", "strong", "br"}, (page, parsed.tags)
        assert not any(character in page for character in RAW), page
    assert all(part in "".join(_rendered(pages[0]).text) for part in SHOWN[:2])  # the names are there, as text
