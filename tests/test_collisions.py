"""sample-collisions: counts against an independent brute force, classification, determinism, exports."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from lxml import etree

from ar3cli.collisions import matrix as cm
from ar3cli.collisions.checker import Checker, count_collisions
from ar3cli.sim.adjacency import adjacent_pairs, direct_parent_child
from ar3cli.sim.sampling import limit_configurations, sample_configurations
from ar3cli.sim.session import PENETRATION_TOLERANCE, Session
from ar3cli.urdf.model import load_model
from tests.conftest import ASSETS

ROBOTS = {
    "panda": ("franka_panda/panda.urdf", None),
    "kuka_iiwa": ("kuka_iiwa/model.urdf", None),
    "ar3": (None, ASSETS / "ar3" / "ar3.urdf"),
}


def robot_path(name, pybullet_data_dir):
    relative, absolute = ROBOTS[name]
    return absolute if absolute is not None else pybullet_data_dir / relative


BORDERLINE = 1e-3
"""m: the two narrowphase paths (persistent-manifold contacts vs one-shot contactPairTest) may disagree
about a pair whose surfaces are this close. Measured: on the AR3, 1 of 2,016 configurations differs
(base_link-gripper_base: -0.09 mm by getContactPoints, +0.57 mm by getClosestPoints); panda and
kuka_iiwa agree exactly over 2,018 and 2,017 configurations."""


def brute_force(model, configs) -> list[dict[frozenset, float]]:
    """Independent check: a fresh client, the body loaded WITHOUT self-collision flags (so no contact
    manifolds), joints set one by one with resetJointState, and a one-shot getClosestPoints query per
    pair of links that pybullet itself says has collision shapes. Per configuration: pair -> distance.

    The query distance is 5 mm, not 0: measured on the AR3 at "all joints at upper", getClosestPoints
    with distance=0 returns NO point for base_link-link_4 although they penetrate by 15 mm (with 1 mm
    it returns the -15 mm point)."""
    found = []
    with Session() as session:
        p, client = session.p, session.client
        body = session.load(model)
        indices = [-1, *range(p.getNumJoints(body.id, physicsClientId=client))]
        solid = [i for i in indices if p.getCollisionShapeData(body.id, i, physicsClientId=client)]
        names = {index: name for name, index in body.link_index.items()}
        movable = [joint.index for joint in body.actuated_joints]
        for q in configs:
            for index, value in zip(movable, q):
                p.resetJointState(body.id, index, float(value), physicsClientId=client)
            distances = {}
            for k, a in enumerate(solid):
                for b in solid[k + 1:]:
                    points = p.getClosestPoints(body.id, body.id, 0.005, a, b, physicsClientId=client)
                    if points:
                        distances[frozenset((names[a], names[b]))] = min(point[8] for point in points)
            found.append(distances)
    return found


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_counts_match_independent_brute_force(name, pybullet_data_dir):
    path = robot_path(name, pybullet_data_dir)
    model = load_model(path)
    with Checker(model) as checker:
        space = checker.joint_space()
        configs = np.vstack([sample_configurations(space, 150, seed=7),
                             np.array([q for _, q in limit_configurations(space)])])
        counts = count_collisions(checker, configs)
        label = {pair_id: frozenset((checker.links[i], checker.links[j]))
                 for pair_id, (i, j) in enumerate(checker.pairs)}
        ours = [{label[pair_id] for pair_id in checker.colliding(q)} for q in configs]
        assert all(counts[pair_id] == 0 for pair_id in checker.unsampled)
    assert sum(counts) == sum(len(hits) for hits in ours) > 0
    theirs = brute_force(model, configs)
    direct = direct_parent_child(model)  # a link and its direct parent: adjacent, never sampled
    differing = 0
    for hits, distances in zip(ours, theirs):
        expected = {pair for pair, distance in distances.items() if distance < -PENETRATION_TOLERANCE} - direct
        for pair in hits ^ expected:
            assert abs(distances.get(pair, 1.0)) < BORDERLINE, (sorted(pair), distances.get(pair))
        differing += hits != expected
    assert differing <= len(configs) // 100  # measured: 0 for these seeds


def test_same_seed_same_matrix_for_any_jobs(pybullet_data_dir):
    path = pybullet_data_dir / "franka_panda" / "panda.urdf"
    with Checker(load_model(path)) as checker:
        space = checker.joint_space()
        configs = sample_configurations(space, 300, seed=3)
        assert np.array_equal(configs, sample_configurations(space, 300, seed=3))
        assert not np.array_equal(configs, sample_configurations(space, 300, seed=4))
        one = count_collisions(checker, configs, jobs=1)
        two = count_collisions(checker, configs, jobs=2)
        three = count_collisions(checker, configs, jobs=3)
    assert one.sum() > 0
    assert np.array_equal(one, two) and np.array_equal(one, three)


def test_cli_panda_srdf_and_pybullet_filter(cli, pybullet_data_dir, tmp_path):
    path = pybullet_data_dir / "franka_panda" / "panda.urdf"
    srdf, filt = tmp_path / "panda.srdf", tmp_path / "filter.json"
    result = cli("sample-collisions", str(path), "--samples", "300", "--seed", "5", "--srdf", str(srdf),
                 "--pybullet-filter", str(filt), "--format", "json")
    assert result.code == 0, result.stderr
    doc = json.loads(result.stdout)
    assert doc["samples"] == 300 and doc["seed"] == 5 and len(doc["pairs"]) == 55  # 11 links with geometry
    by_pair = {frozenset((p["link_a"], p["link_b"])): p for p in doc["pairs"]}
    hand = by_pair[frozenset(("panda_link7", "panda_hand"))]
    assert hand["category"] == "adjacent" and hand["fraction"] == 1.0  # through the geometry-less link8
    assert any(w["rule"] == "pybullet-default-self-collision" and "panda_hand" in w["message"]
               for w in doc["warnings"])
    never = [p for p in doc["pairs"] if p["category"] == "never"]
    assert never and all(p["upper_bound"] == pytest.approx(1 - 0.05 ** (1 / 300)) for p in never)
    tree = etree.parse(str(srdf))
    entries = {frozenset((e.get("link1"), e.get("link2"))): e.get("reason")
               for e in tree.getroot().iter("disable_collisions")}
    expected = {key: p["category"].capitalize() for key, p in by_pair.items() if p["category"] != "sometimes"}
    assert entries == expected
    assert entries[frozenset(("panda_link7", "panda_hand"))] == "Adjacent"
    assert "Never" in entries.values() and "Adjacent" in entries.values()
    # the filter file really silences what it lists under PyBullet's default self-collision flag
    pairs = json.loads(filt.read_text())["pairs"]
    assert {frozenset((p["link_a"], p["link_b"])) for p in pairs} == set(expected)
    with Session() as session:
        p = session.p
        body = session.load(load_model(path), flags=p.URDF_USE_SELF_COLLISION)
        assert body.contacts()  # link7-hand touch at home with the default flag
        for pair in pairs:
            p.setCollisionFilterPair(body.id, body.id, body.link_index[pair["link_a"]],
                                     body.link_index[pair["link_b"]], 0, physicsClientId=session.client)
        remaining = {frozenset(c[:2]) for c in body.contacts()}
        assert not remaining & set(expected)


def test_cli_ar3_text_and_jobs(cli):
    path = ASSETS / "ar3" / "ar3.urdf"
    one = cli("sample-collisions", str(path), "-n", "300", "--format", "json")
    two = cli("sample-collisions", str(path), "-n", "300", "--jobs", "2", "--format", "json")
    assert one.code == 0 and two.code == 0, one.stderr + two.stderr
    assert json.loads(one.stdout)["pairs"] == json.loads(two.stdout)["pairs"]
    categories = json.loads(one.stdout)["categories"]
    assert sum(categories.values()) == math.comb(10, 2)  # 10 AR3 links have collision geometry
    text = cli("sample-collisions", str(path), "-n", "200", "--seed", "9")
    assert text.code == 0, text.stderr
    assert "seed 9: 200 uniform samples" in text.stdout
    assert "finger_left" in text.stdout and "A adjacent" in text.stdout  # table and heat map legend


def test_png_heat_map(cli, tmp_path):
    from PIL import Image

    out = tmp_path / "matrix.png"
    result = cli("sample-collisions", str(ASSETS / "ar3" / "ar3.urdf"), "-n", "200", "--png", str(out))
    assert result.code == 0, result.stderr
    image = Image.open(out).convert("RGB")
    assert image.width > 200 and image.height > 200
    colours = {colour for _, colour in image.getcolors(maxcolors=1 << 16)}
    from ar3cli.collisions.heatmap_png import CATEGORY_COLOURS

    assert CATEGORY_COLOURS["adjacent"] in colours and CATEGORY_COLOURS["never"] in colours
    srdf = tmp_path / "a.srdf"
    for bad, message in [(tmp_path / "nodir" / "m.png", "does not exist"), (tmp_path / "m.gif", "must end in .png")]:
        refused = cli("sample-collisions", str(ASSETS / "ar3" / "ar3.urdf"), "-n", "10", "--srdf", str(srdf),
                      "--png", str(bad))
        assert refused.code == 2 and message in refused.stderr and not srdf.exists()  # nothing written


TRANSPARENT = """<?xml version="1.0"?>
<robot name="chain">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="hub"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
    <visual><geometry><sphere radius="0.01"/></geometry></visual></link>
  <link name="arm"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
    <collision><origin xyz="0.15 0 0"/><geometry><box size="0.3 0.04 0.04"/></geometry></collision></link>
  <link name="tip"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
    <collision><origin xyz="0 0 -0.15"/><geometry><box size="0.04 0.04 0.2"/></geometry></collision></link>
  <joint name="j1" type="continuous"><parent link="base"/><child link="hub"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="revolute"><parent link="hub"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>
  <joint name="j3" type="fixed"><parent link="arm"/><child link="tip"/><origin xyz="0.3 0 0"/></joint>
</robot>
"""


def test_classification_on_a_small_chain(cli, write_urdf):
    """base -(continuous)- hub (visual only) -(revolute)- arm -(fixed)- tip: base-arm adjacent through
    the hub; tip hangs down into the base's reach only when j2 tilts the arm: 'sometimes'."""
    path = write_urdf(TRANSPARENT)
    result = cli("sample-collisions", str(path), "-n", "300", "--format", "json")
    assert result.code == 0, result.stderr
    doc = json.loads(result.stdout)
    category = {frozenset((p["link_a"], p["link_b"])): p["category"] for p in doc["pairs"]}
    assert category[frozenset(("base", "arm"))] == "adjacent"  # through the geometry-less hub
    assert category[frozenset(("arm", "tip"))] == "adjacent"
    assert any(w["rule"] == "visual-only-links" and "hub" in w["message"] for w in doc["warnings"])
    model = load_model(path)
    assert adjacent_pairs(model, ["base", "arm", "tip"]) == {frozenset(("base", "arm")),
                                                                  frozenset(("arm", "tip"))}
    with Checker(model) as checker:
        space = checker.joint_space()
    assert space.continuous == (True, False)
    configs = sample_configurations(space, 2000, seed=1)
    assert configs[:, 0].min() < -3.0 and configs[:, 0].max() > 3.0  # [-pi, pi), not getJointInfo's (0, -1)
    assert configs[:, 1].min() >= -0.5 and configs[:, 1].max() <= 0.5
    labels = [label for label, _ in limit_configurations(space)]
    assert labels[0] == "home" and "j2 at lower" in labels and not any(label.startswith("j1") for label in labels)


def test_statistics():
    low, high = cm.wilson_interval(5, 10)
    assert (low, high) == pytest.approx((0.2366, 0.7634), abs=1e-4)  # textbook Wilson values
    assert cm.wilson_interval(0, 10)[1] == pytest.approx(0.2775, abs=1e-4)
    assert cm.wilson_interval(0, 50)[0] == 0.0 and cm.wilson_interval(50, 50)[1] == 1.0  # not 6.9e-18 off
    assert cm.zero_success_upper_bound(10_000) == pytest.approx(2.995e-4, rel=1e-3)  # ~3/N


def test_only_visual_geometry_is_a_clear_error(cli, write_urdf):
    text = TRANSPARENT.replace("<collision>", "<visual>").replace("</collision>", "</visual>")
    result = cli("sample-collisions", str(write_urdf(text)), "-n", "10")
    assert result.code == 2
    assert "no link has <collision> geometry" in result.stderr and "only <visual>" in result.stderr
    assert "Traceback" not in result.stderr and result.stderr.count("\n") == 1


def test_a_missing_mesh_leaves_its_link_out_of_the_matrix(cli, write_urdf):
    text = TRANSPARENT.replace('<box size="0.3 0.04 0.04"/>', '<mesh filename="missing_arm.stl"/>')
    result = cli("sample-collisions", str(write_urdf(text)), "-n", "10", "--format", "json")
    assert result.code == 0 and "Traceback" not in result.stderr
    data = json.loads(result.stdout)
    assert data["unchecked_links"] and data["warnings"][0]["rule"] == "collision-left-out"
    assert "missing_arm.stl" in data["warnings"][0]["message"]


RIGID = """<robot name="rigid">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="bracket"/>
  <link name="cover"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="arm"><collision><origin xyz="0 0 0.25"/><geometry><box size="0.3 0.05 0.4"/></geometry></collision></link>
  <link name="lamp"><collision><origin xyz="0 0 0.1"/><geometry><sphere radius="0.02"/></geometry></collision></link>
  <joint name="to_bracket" type="fixed"><parent link="base"/><child link="bracket"/></joint>
  <joint name="to_cover" type="fixed"><parent link="bracket"/><child link="cover"/>
    <origin xyz="0.1 0 0"/></joint>
  <joint name="swing" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="1 0 0"/>
    <limit lower="-2.5" upper="2.5" effort="1" velocity="1"/></joint>
  <joint name="to_lamp" type="fixed"><parent link="cover"/><child link="lamp"/></joint>
</robot>
"""


def test_pairs_joined_only_by_fixed_joints_are_settled_once(write_urdf):
    """base-cover overlap through the geometry-less bracket (fixed, fixed): in every configuration;
    cover-lamp is rigid too but direct (never tested); the lamp pokes into the base: base-lamp is
    constant and colliding; the arm swings through the lamp only in some configurations."""
    model = load_model(write_urdf(RIGID))
    with Checker(model) as checker:
        names = {pair_id: frozenset((checker.links[i], checker.links[j])) for pair_id, (i, j) in enumerate(checker.pairs)}
        constant = {names[pair_id] for pair_id in checker.constant}
        assert constant == {frozenset(("base", "cover")), frozenset(("base", "lamp"))}
        configs = sample_configurations(checker.joint_space(), 400, seed=2)
        counts = count_collisions(checker, configs)
        by_name = {names[pair_id]: int(count) for pair_id, count in enumerate(counts)}
        assert by_name[frozenset(("base", "cover"))] == by_name[frozenset(("base", "lamp"))] == 400
        assert 0 < by_name[frozenset(("arm", "lamp"))] < 400
        assert {names[pair_id] for pair_id in checker.colliding(configs[0])} >= constant
        assert checker.count(configs[:0]).sum() == 0
        # pybullet itself no longer reports them: the time they took per configuration is saved
        reported = {pair for a, b, _ in checker.body.contacts(min_depth=PENETRATION_TOLERANCE)
                    for pair in [frozenset((a, b))]}
        assert not reported & constant
        ours = [{names[pair_id] for pair_id in checker.colliding(q)} for q in configs[:60]]
    direct = direct_parent_child(model)
    theirs = [{pair for pair, distance in distances.items() if distance < -PENETRATION_TOLERANCE} - direct
              for distances in brute_force(model, configs[:60])]
    assert ours == theirs


def test_round_bounds_cover_the_samples_and_start_where_a_pair_can_first_be_decided():
    from ar3cli.collisions.rounds import round_bounds

    for total, threshold in [(1, 0.95), (7, 0.95), (1000, 0.95), (100_000, 0.95), (500, 0.01), (300, 1.0)]:
        bounds = round_bounds(total, threshold)
        assert bounds[0][0] == 0 and bounds[-1][1] == total
        assert all(stop > start for start, stop in bounds)
        assert all(a[1] == b[0] for a, b in zip(bounds, bounds[1:]))
        assert bounds[0][1] > total * (1 - threshold) or bounds[0][1] == total
    assert round_bounds(0, 0.95) == []
    assert len(round_bounds(100_000, 0.95)) <= 10


def test_settled_rule():
    """A pair is retired only when the samples still to come cannot change its verdict."""
    n, t = 1000, 0.95
    assert cm.settled(0, 0, n, t, adjacent=False, at_home=True)  # default, whatever the samples say
    assert not cm.settled(0, 0, n, t, adjacent=True, at_home=True)  # adjacent: counted for the warning
    assert not cm.settled(20, 50, n, t, adjacent=True, at_home=False)
    assert cm.settled(20, 51, n, t, adjacent=True, at_home=False)  # past the first ~5% of samples
    assert not cm.settled(1, 1, n, 1.0, adjacent=True, at_home=False)  # at least 50 samples, whatever t
    assert cm.settled(3, 3, 3, 1.0, adjacent=True, at_home=False)  # or all of them
    assert not cm.settled(0, 999, n, t, adjacent=False, at_home=False)  # may still be 'never'
    assert not cm.settled(1, 51, n, t, adjacent=False, at_home=False)  # free 50: could still reach 95%
    assert cm.settled(1, 52, n, t, adjacent=False, at_home=False)  # free 51: 'sometimes' whatever follows
    assert cm.settled(950, 950, n, t, adjacent=False, at_home=False)  # 'always' already


def test_retiring_decided_pairs_keeps_every_category(pybullet_data_dir):
    """Counting in rounds (decided pairs filtered out) against counting every pair in every sample: the
    same categories, the same counts for the pairs counted to the end, for any number of jobs."""
    from ar3cli.collisions.rounds import count_in_rounds

    path = pybullet_data_dir / "franka_panda" / "panda.urdf"
    samples, threshold = 600, 0.95
    model = load_model(path)
    with Checker(model) as checker:
        space = checker.joint_space()
        home = set(checker.colliding(space.home))
        links, pairs = checker.links, checker.pairs
        adjacent = adjacent_pairs(model, links)
        adjacent_ids = {k for k, (i, j) in enumerate(pairs) if frozenset((links[i], links[j])) in adjacent}
        configs = sample_configurations(space, samples, seed=4)
        full = count_collisions(checker, configs, jobs=1)

        def settled(pair_id, collisions, checked):
            return cm.settled(collisions, checked, samples, threshold, pair_id in adjacent_ids, pair_id in home)

        counts, checked, _ = count_in_rounds(checker, configs, settled, threshold, jobs=1)
    with Checker(model) as checker:
        again = count_in_rounds(checker, configs, settled, threshold, jobs=2)
    assert np.array_equal(counts, again[0]) and np.array_equal(checked, again[1])
    assert (checked < samples).sum() > 10  # most 'sometimes' pairs, the default and adjacent ones retired
    whole = cm.classify(links, pairs, full, samples, adjacent, home, {}, threshold, checker.unsampled)
    rounds = cm.classify(links, pairs, counts, samples, adjacent, home, {}, threshold, checker.unsampled, checked)
    assert [r.category for r in whole] == [r.category for r in rounds]
    for pair_id, result in enumerate(rounds):
        if result.sampled and not result.retired:
            assert counts[pair_id] == full[pair_id]
        elif result.retired:
            assert result.samples == checked[pair_id] < samples and result.to_dict()["retired"]
