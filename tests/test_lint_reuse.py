"""An editor's keystroke: the model made from the earlier one, and lint's work reused, with the findings of
a full check.

- :func:`ar3cli.urdf.model_edit.edited` takes exactly one attribute value of one link or joint changed, and
  its model is the one a parse of the new text gives; everything else is refused (a full load follows).
- Every rule of :data:`ar3cli.lint.reuse.ITEM_LOCAL` is item-local on every test robot: its hits on a file
  are the hits on each item checked alone.
- Typed keystrokes checked the editor's way give lint-urdf's JSON document of a full check, byte for
  byte (``benchmarks/reuse_differential.py``, which runs the same on real robots).
"""

from __future__ import annotations

import importlib.util
import sys
from collections import Counter
from pathlib import Path

import pytest
from lxml import etree

from ar3cli.lint.context import Context
from ar3cli.lint.reuse import ITEM_LOCAL, item_hits, item_model
from ar3cli.lint.rules import RULES
from ar3cli.urdf.model import load_model
from ar3cli.urdf.model_edit import edited
from tests.conftest import ASSETS, REPO

DATA = REPO / "tests" / "data"
ARM = """<?xml version="1.0"?>
<robot name="arm">
  <!-- <joint name="ghost"><limit lower="-1" upper="1.57"/></joint> -->
  <link name="base"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
  </inertial><collision><geometry><cylinder radius="0.03" length="0.3"/></geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <limit lower="-1.57" upper="1.57" effort="10" velocity="1"/></joint>
  <material name="red"><color rgba="1 0 0 1"/></material>
</robot>
"""


def _differential():
    spec = importlib.util.spec_from_file_location("reuse_differential", REPO / "benchmarks" / "reuse_differential.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("reuse_differential", module)
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def _load(tmp_path: Path, text: str, name: str = "arm.urdf"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path, load_model(path)


def _same_as_a_parse(model, path: Path) -> None:
    """``model`` is what loading its text gives: the same tree, source lines, links and joints."""
    fresh = load_model(path, source=model.source_bytes)
    assert etree.tostring(model.root) == etree.tostring(fresh.root)
    assert [node.sourceline for node in model.root.iter()] == [node.sourceline for node in fresh.root.iter()]

    def facts(thing) -> str:
        return repr({key: value for key, value in vars(thing).items() if key not in ("element", "parts")})

    def parsed(one) -> list:
        """What the load read of each link and joint, element objects left out."""
        return [(link.name, link.inertial and (link.inertial.mass, link.inertial.tensor),
                 [(shape.geometry.kind, dict(shape.geometry.params)) for shape in (*link.visuals, *link.collisions)])
                for link in one.links] + \
               [(joint.name, joint.type, joint.parent, joint.child, joint.limit and facts(joint.limit), joint.axis)
                for joint in one.joints]

    assert parsed(model) == parsed(fresh)


# ---- the edit ------------------------------------------------------------------------------------
TAKEN = [
    ('upper="1.57" effort', 'upper="1.5" effort'),            # a keystroke deleting a digit
    ('upper="1.57" effort', 'upper="1.579" effort'),          # typing one
    ('upper="1.57" effort', 'upper="" effort'),               # deleting the whole value
    ('type="revolute"', 'type="fixed"'),                       # pasting a word
    ('<child link="arm"/>', '<child link="base"/>'),           # a name another element uses
    ('<link name="arm">', '<link name="arm2">'),               # the link's own name
    ('<mass value="1"/>', '<mass value="1é"/>'),               # a character of two bytes
    ('radius="0.03"', 'radius="0.0300"'),                      # an attribute in a start tag spread over lines
    # the same elements, the text parsed again:
    ('</link>\n  <joint', '</link>\n\n  <joint'),              # a line break between two items
    ('  <material', '    <material'),                          # an indent
    ('<inertial><mass', '<inertial>\n    <mass'),              # a line break inside an item
    ('lower="-1.57" upper="1.57"', 'lower="-1.5" upper="1.5"'),  # two values at once
    ('velocity="1"/>', 'velocity="1" acceleration="2"/>'),   # an attribute added
    ('upper="1.57" effort', 'upper="1.5\n" effort'),           # a line break in a value (read as a space)
    ('upper="1.57" effort', 'upper="1.5&amp;" effort'),        # an entity in a value
    ('upper="1.57"/></joint> -->', 'upper="1.5"/></joint> -->'),  # inside a comment
    ('rgba="1 0 0 1"', 'rgba="1 0 0 0"'),                     # an item that is no link or joint
]


@pytest.mark.parametrize("old, new", TAKEN)
def test_an_edit_that_keeps_the_elements_makes_the_model_a_load_gives(tmp_path, old, new):
    path, model = _load(tmp_path, ARM)
    links, joints = list(model.links), list(model.joints)
    assert old in ARM
    source = ARM.replace(old, new, 1).encode("utf-8")
    edit = edited(model, source)
    assert edit is not None
    assert model.edited_away and not edit.model.edited_away
    assert all(item.getparent() is model.root for item in edit.items)
    assert edit.model.root is model.root  # the same tree, changed in place
    untouched = [thing for thing in (*links, *joints) if all(thing is not other for other in edit.before)]
    assert all(any(thing is other for other in (*edit.model.links, *edit.model.joints)) for thing in untouched)
    _same_as_a_parse(edit.model, path)
    assert edited(model, source) is None  # the earlier model is consumed: never the base of another edit


def test_an_edit_in_a_multi_line_start_tag_and_a_second_keystroke(tmp_path):
    text = ARM.replace('<limit lower="-1.57" upper="1.57"', '<limit\n      lower="-1.57"\n      upper="1.57"')
    path, model = _load(tmp_path, text)
    first = edited(model, text.replace('lower="-1.57"', 'lower="-1.5"').encode())
    assert first is not None
    second = edited(first.model, text.replace('lower="-1.57"', 'lower="-1.5"').replace('      upper="1.57"',
                                                                                       '      upper="1.5"').encode())
    assert second is not None and second.items == first.items
    _same_as_a_parse(second.model, path)


@pytest.mark.parametrize("old, new, why", [
    ('upper="1.57" effort', 'upper="1.5<" effort', "markup typed: the text does not parse"),
    ('upper="1.57" effort', 'upper="1.5"" effort', "a quote typed: the text does not parse"),
    ('<robot name="arm">', '<robot name="arms">', "an attribute of <robot>"),
    ('<parent link="base"/>', '<parent link="base"/><axis xyz="0 0 1"/>', "an element added"),
    ('<box size="0.1 0.1 0.1"/>', '<sphere radius="0.1"/>', "another element"),
    ('<cylinder radius="0.03" length="0.3"/>', '<mesh filename="a.stl"/>', "a mesh file name"),
    ('<?xml version="1.0"?>', '<?xml version="1.0"?>\n<!-- header -->', "a comment before <robot>"),
])
def test_anything_else_is_a_full_load(tmp_path, old, new, why):
    _path, model = _load(tmp_path, ARM)
    assert old in ARM, why
    assert edited(model, ARM.replace(old, new, 1).encode("utf-8")) is None, why
    assert not model.edited_away, why


@pytest.mark.parametrize("text, old, new, why", [
    (ARM.replace('<link name="base">', '<link name="base"><visual name="x a:b"/>'), 'name="x a:b"', 'name="x a:b="',
     "a value the load reads as a namespace prefix (a:b=): it declares xmlns:a and says so (F005)"),
    (ARM.replace('<?xml version="1.0"?>', '<?xml version="1.0" encoding="us-ascii"?>'), 'name="shoulder"',
     'name="shoulderé"', "a character the declared encoding lacks: the parser refuses the file"),
    ('<?xml version="1.0"?>\n<robot name="r">\n  <link name="base"><visual name="v"><geometry><box size="1 1 1"/>'
     '</geometry></visual></link>\n</robot>\n', 'name="v"', 'name="' + "x" * 10_000_001 + '"',
     "a value libxml2 refuses here without huge_tree (over 10,000,000 bytes)"),
    (ARM.replace('<robot name="arm">\n', '<robot name="arm"><link name="x"><robot name="arm"/></link>'),
     '<robot name="arm"><link', '<robot name="arms"><link', "<robot>'s start tag, with an element alike on its line"),
])
def test_edits_a_load_reads_otherwise_are_full_loads(tmp_path, text, old, new, why):
    """Found by a review: each was taken as an edit and gave another model or other findings than a load."""
    _path, model = _load(tmp_path, text)
    assert old in text, why
    assert edited(model, text.replace(old, new, 1).encode("utf-8")) is None, why
    assert not model.edited_away, why


def test_elements_alike_on_one_line_are_told_apart_by_a_parse_and_files_with_quirks_are_full_loads(tmp_path):
    limit = '<limit lower="-1.57" upper="1.57" effort="10" velocity="1"/>'
    twins = ARM.replace(limit, limit + limit.replace("-1.57", "-2"))
    path, model = _load(tmp_path, twins)
    edit = edited(model, twins.replace(limit, limit.replace('upper="1.57"', 'upper="1.5"')).encode())
    assert edit is not None  # which <limit> the bytes changed, the value alone cannot say: the parse can
    _same_as_a_parse(edit.model, path)
    _path, crlf = _load(tmp_path, ARM.replace("\n", "\r\n"), "crlf.urdf")
    assert edited(crlf, ARM.replace("\n", "\r\n").replace('upper="1.57" effort', 'upper="1.5" effort').encode()) is None


# ---- the rules ----------------------------------------------------------------------------------
def _robots() -> list[Path]:
    found = sorted(DATA.rglob("*.urdf")) + sorted(ASSETS.rglob("*.urdf"))
    return [path for path in found if path.stat().st_size < 400_000]


def _path_key(element, root) -> tuple:
    path = []
    while element is not root:
        parent = element.getparent()
        path.append(parent.index(element))
        element = parent
    return tuple(reversed(path))


def _models(tmp_path: Path):
    """The test robots and every rule's two examples (its bad one triggers it), loaded."""
    for path in _robots():
        try:
            yield path, load_model(path)
        except Exception:  # noqa: BLE001 - a fixture that does not load has nothing to compare
            continue
    for rule in RULES:
        for kind, text in (("bad", rule.bad), ("good", rule.good)):
            path = tmp_path / f"{rule.code}_{kind}.urdf"
            try:
                yield path, load_model(path, source=text.encode("utf-8"))
            except Exception:  # noqa: BLE001 - an example of a file that does not load (F rules)
                continue


def test_item_local_rules_find_on_each_item_alone_what_they_find_on_the_file(tmp_path):
    rules = [rule for rule in RULES if rule.code in ITEM_LOCAL]
    assert {rule.code for rule in rules} == ITEM_LOCAL and all(not rule.needs_sim for rule in rules)
    checked, fired = 0, Counter()
    for path, model in _models(tmp_path):
        if model.is_xacro:
            continue
        items = [child for child in model.root if isinstance(child.tag, str)]
        alone = {id(item): item_model(model, item) for item in items}
        for rule in rules:
            found = list(rule.check(Context(model)))
            assert all(hit.element is not None for hit in found), f"{rule.code} on {path}: a hit on a line"
            whole = Counter((hit.message, hit.hint, _path_key(hit.element, model.root)) for hit in found)
            fired[rule.code] += bool(found)
            parts: Counter = Counter()
            for item in items:
                hits = item_hits(rule, alone[id(item)], Context(alone[id(item)][0]), item)
                assert hits is not None, f"{rule.code} on {path}: a hit outside the item"
                parts.update((hit.message, hit.hint, _path_key(hit.element, model.root)) for hit in hits)
            assert whole == parts, f"{rule.code} is not item-local on {path}"
        checked += 1
    assert checked > 150
    assert set(fired) == ITEM_LOCAL  # each fired somewhere


# ---- keystrokes ---------------------------------------------------------------------------------
def test_typed_keystrokes_give_the_findings_of_a_full_check():
    differential = _differential()
    robots = [path for path in _robots() if "quiet" in path.parts or "urdf12" in path.parts or "ar3" in path.parts]
    assert len(robots) > 20
    fast = full = 0
    for index, path in enumerate(robots):
        one_fast, one_full, differences = differential.session(path, 12, index)
        assert differences == []
        fast, full = fast + one_fast, full + one_full
    assert fast > 100 and full > 20  # both paths ran


def test_two_links_of_one_name_are_each_judged_on_their_own_shapes(tmp_path):
    """A link's box was known by its name: the second of two links named alike (S002) was judged on the
    first one's shapes, in a full check, and on its own in a check after a keystroke that gave it the name."""
    heavy = '<inertial><mass value="0.01"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>'
    text = f"""<robot name="twins">
  <link name="a">{heavy}<collision><geometry><box size="0.5 0.5 0.5"/></geometry></collision></link>
  <link name="a">{heavy}<collision><geometry><box size="0.02 0.02 0.02"/></geometry></collision></link>
</robot>
"""
    path, model = _load(tmp_path, text)
    found = [hit.message for hit in next(rule for rule in RULES if rule.code == "I007").check(Context(model))]
    assert len(found) == 1 and "half-diagonal 0.0173 m" in found[0]  # the small one; the first was judged plausible


def test_findings_at_one_place_come_in_one_order_after_a_keystroke(tmp_path):
    """Two links on one line share their <inertia>'s column (the first on the line): the edited one's finding
    is found last after a keystroke, first in a full check; the message orders them both the same way."""
    from ar3cli.analysis.findings import static_findings
    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.analysis.settings import AnalysisSettings

    flat = '<inertial><mass value="1"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="{}"/></inertial>'
    text = (f'<robot name="r">\n  <link name="a">{flat.format(1)}</link><link name="b">{flat.format(0.5)}</link>\n'
            '  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>\n</robot>\n')
    path = tmp_path / "r.urdf"
    settings = AnalysisSettings()
    earlier = RobotAnalysis.load(path, settings, text, editing=True)
    static_findings(earlier)
    typed = text.replace('izz="1"', 'izz="2"')
    edited_check = RobotAnalysis.load(path, settings, typed, earlier=earlier, editing=True)
    assert edited_check.edit is not None
    found = [(finding.line, finding.column, finding.rule, finding.message) for finding in static_findings(edited_check).findings]
    assert found == [(finding.line, finding.column, finding.rule, finding.message)
                     for finding in static_findings(RobotAnalysis.load(path, settings, typed)).findings]
    assert [message for _line, _column, rule, message in found if rule == "I005"] == sorted(
        message for _line, _column, rule, message in found if rule == "I005") and len(found) >= 2


def test_a_bug_in_the_shortcut_costs_its_speed_never_the_findings(tmp_path, monkeypatch):
    from ar3cli.analysis.findings import static_findings
    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.analysis.settings import AnalysisSettings
    from ar3cli.lint import reuse
    from ar3cli.urdf import model_edit

    path, settings = tmp_path / "arm.urdf", AnalysisSettings()
    typed = ARM.replace('upper="1.57" effort', 'upper="-2" effort')  # J003: inverted

    def broken(*_args, **_kwargs):
        raise RuntimeError("a bug")

    expected = static_findings(RobotAnalysis.load(path, settings, typed)).document
    for target, name in ((reuse.Reuse, "hits"), (model_edit, "_same_elements"), (model_edit, "_one_value")):
        earlier = RobotAnalysis.load(path, settings, ARM, editing=True)
        static_findings(earlier)
        with monkeypatch.context() as patched:
            patched.setattr(target, name, broken)
            analysis = RobotAnalysis.load(path, settings, typed, earlier=earlier, editing=True)
            document = static_findings(analysis).document
        assert document == expected, name
        assert any(finding["rule"] == "J003" for finding in document["findings"])
