"""One meaning of "links in collision at home" across lint-urdf --sim (P002), render and sample-collisions.

Adjacent is MoveIt's rule (links without collision geometry are transparent), and a pair collides
when it penetrates deeper than sim.PENETRATION_TOLERANCE. render and sample-collisions show every such
pair; P002, a warning to fix, leaves out the contacts a robot is built with (pybullet_sim.built_touching:
the Panda's fingers, two branches touching by 2.2 mm).
"""

from __future__ import annotations

import json

from ar3cli.sim.adjacency import adjacent_pairs, nonadjacent_collisions
from ar3cli.sim.session import Session
from ar3cli.urdf.model import load_model

FINGERS = frozenset(("panda_leftfinger", "panda_rightfinger"))
PANDA_AT_HOME = {frozenset(("panda_link5", "panda_link7")), frozenset(("panda_link5", "panda_hand")), FINGERS}
"""Measured: 7.6 mm, 43.4 mm and 2.2 mm deep. panda_link7 - panda_hand (25 mm) is adjacent through the
geometry-less panda_link8."""


def test_adjacency_looks_through_links_without_geometry(pybullet_data_dir):
    model = load_model(pybullet_data_dir / "franka_panda" / "panda.urdf")
    adjacent = adjacent_pairs(model)
    assert frozenset(("panda_link7", "panda_hand")) in adjacent
    assert frozenset(("panda_link7", "panda_link8")) not in adjacent  # link8 has no collision geometry
    with Session() as session:
        body = session.load(model, self_collision="all-pairs")
        found = nonadjacent_collisions(body)
    assert {frozenset((a, b)) for a, b, _ in found} == PANDA_AT_HOME


def test_p002_render_and_sample_collisions_agree_on_panda(cli, pybullet_data_dir, tmp_path):
    path = str(pybullet_data_dir / "franka_panda" / "panda.urdf")
    lint = cli("lint-urdf", "--sim", "--select", "P002", path, "--format", "json")
    p002 = set()
    for finding in json.loads(lint.stdout)["findings"]:
        names = finding["message"].split("'")
        p002.add(frozenset((names[1], names[3])))
    render = cli("render", path, "-o", str(tmp_path / "p.png"), "--width", "32", "--height", "32", "--format", "json")
    assert render.code == 0, render.stderr
    drawn = {frozenset((c["link_a"], c["link_b"])) for c in json.loads(render.stdout)["contacts"]}
    matrix = cli("sample-collisions", path, "-n", "50", "--format", "json")
    assert matrix.code == 0, matrix.stderr
    default = {frozenset((p["link_a"], p["link_b"])) for p in json.loads(matrix.stdout)["pairs"]
               if p["category"] == "default"}
    assert drawn == default == PANDA_AT_HOME
    assert p002 == PANDA_AT_HOME - {FINGERS}  # built touching: not a finding, still drawn


def test_p002_looks_through_a_link_without_geometry(write_urdf):
    """base - mid (no collision) - tip overlapping base: adjacent for MoveIt, so no P002 (it used to warn)."""
    from ar3cli.lint.engine import LintOptions, lint_file
    from ar3cli.lint.rules.base import LINK_INERTIAL, robot

    box = '<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>'
    text = robot(f"""
        <link name="base">{LINK_INERTIAL}{box}</link><link name="mid">{LINK_INERTIAL}</link>
        <link name="tip">{LINK_INERTIAL}{box}</link>
        <joint name="j1" type="revolute"><parent link="base"/><child link="mid"/><origin xyz="0 0 0.05"/>
          <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
        <joint name="j2" type="revolute"><parent link="mid"/><child link="tip"/><origin xyz="0 0 0.05"/>
          <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>""")
    options = LintOptions(sim=True)
    findings = lint_file(write_urdf(text), options.rules(), options).findings
    assert not [f for f in findings if f.rule == "P002"]


def test_p002_reports_a_shallow_overlap_in_micrometres(write_urdf):
    """5 um deep is above the 1 um tolerance (resting faces are ~1e-16 m) and is printed in um, not '0.0 mm'."""
    from ar3cli.lint.engine import LintOptions, lint_file
    from ar3cli.lint.rules import REGISTRY

    text = REGISTRY["P002"].bad.replace('<origin xyz="0 0 -0.25"/>', '<origin xyz="0 0 -0.100005"/>')
    options = LintOptions(sim=True)
    (finding,) = [f for f in lint_file(write_urdf(text), options.rules(), options).findings if f.rule == "P002"]
    assert "'base' and 'tip'" in finding.message and "by 5.0 µm" in finding.message


def test_p002_is_quiet_about_links_joined_only_by_fixed_joints(write_urdf):
    """base - plate (fixed) - cover (fixed) with cover overlapping base: one rigid part, never apart, so no P002;
    an arm link overlapping the same base through a revolute joint chain is still reported."""
    from ar3cli.lint.engine import LintOptions, lint_file
    from ar3cli.lint.rules.base import LINK_INERTIAL, robot

    box = '<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>'
    small = '<collision><geometry><box size="0.02 0.02 0.02"/></geometry></collision>'
    text = robot(f"""
        <link name="base">{LINK_INERTIAL}{box}</link><link name="plate">{LINK_INERTIAL}{small}</link>
        <link name="cover">{LINK_INERTIAL}{box}</link>
        <link name="arm">{LINK_INERTIAL}{small}</link><link name="hand">{LINK_INERTIAL}{box}</link>
        <joint name="f1" type="fixed"><parent link="base"/><child link="plate"/><origin xyz="0 0 0.3"/></joint>
        <joint name="f2" type="fixed"><parent link="plate"/><child link="cover"/><origin xyz="0 0 -0.2"/></joint>
        <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0.3 0"/>
          <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
        <joint name="j2" type="revolute"><parent link="arm"/><child link="hand"/><origin xyz="0 -0.2 0"/>
          <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>""")
    options = LintOptions(sim=True)
    messages = [f.message for f in lint_file(write_urdf(text), options.rules(), options).findings if f.rule == "P002"]
    assert not [m for m in messages if "'cover'" in m and "'base'" in m]
    assert [m for m in messages if "'base'" in m and "'hand'" in m]
