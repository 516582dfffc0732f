"""Reuse one check's work in the next when an edit changed one link or joint (an editor's keystroke).

A language server checks the buffer again on every keystroke, and a keystroke changes one attribute
of one element (:func:`~ar3cli.urdf.model_edit.edited` makes the new model from the earlier one,
sharing every object the edit did not touch). Two things of the earlier check stay true:

- **Item-local rules** (:data:`ITEM_LOCAL`): a rule whose findings on each child of ``<robot>`` (an
  "item": a link, a joint, a material, a transmission...) depend on that item's own elements alone.
  Its hits on the items the edit did not touch are the earlier check's; on the edited item, the rule
  runs on a document of ``<robot>`` holding a copy of that item alone (:func:`item_model`), and its hits
  are taken back to the real elements. The rules that read anything beyond the item (another link's
  name, the robot's median link, the joint above a link, the file's quirks) run in full.
- **Answers about single links and shapes** (their boxes, radius of gyration, density bounds):
  the new :class:`~ar3cli.lint.context.Context` inherits them for the links the edit did not touch
  (:meth:`~ar3cli.lint.context.Context.inherit`), so the rules that run in full do not compute them
  again.

The findings are those of a full check, byte for byte: ``tests/test_lint_reuse.py`` holds every rule of
:data:`ITEM_LOCAL` to its definition on every test robot and compares edited checks with full ones, and
``benchmarks/reuse_differential.py`` does the same on real robots with random keystrokes.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

from ar3cli.lint.context import Context
from ar3cli.lint.rules.base import Hit
from ar3cli.urdf.model import read_joint, read_link
from ar3cli.urdf.model_edit import item_of

if TYPE_CHECKING:
    from ar3cli.lint.rules.base import Rule
    from ar3cli.urdf.model import Model
    from ar3cli.urdf.model_edit import Edit

ITEM_LOCAL = frozenset({
    "F007", "S009", "S010", "S014", "S016", "S017", "S018", "S020",
    "J001", "J002", "J003", "J004", "J006", "J007", "J008", "J009", "J010", "J013", "J014", "J015", "J017",
    "I004", "I005", "I011",
    "G002", "G003", "G004", "G005", "G007", "G009", "G010", "G011", "G012", "G013", "G017", "G018",
    "T001", "T002", "T004", "T006", "T008", "T009",
})
"""Rules whose hits on each item of ``<robot>`` depend on that item's elements alone (and on the robot's own
attributes, the options and the mesh files the item names): the hits of a whole file are those of each
item checked in a document of its own. A rule not named here runs in full on every check; name one only
with the test's word for it (``tests/test_lint_reuse.py`` checks the definition on every test robot)."""


def options_key(rules: list[Rule], options: Any) -> tuple:
    """What, besides the model, decides the static rules' hits: the rules, the targets, the SRDF's pairs."""
    return tuple(rule.code for rule in rules), tuple(options.targets), id(options.srdf_disabled)


@dataclass
class Carry:
    """What a run of the static rules leaves for the check after an edit: the model and context it ran on,
    and each item-local rule's hits per item (a rule with a hit on no item, ``<robot>`` itself or a line,
    is not kept: it runs in full next time)."""

    key: tuple
    model: Model
    context: Context
    hits: dict[str, dict[Any, list[Hit]]] = field(default_factory=dict)

    def record(self, rule: Rule, hits: list[Hit]) -> None:
        """Keep ``rule``'s hits of this run by item, when it is item-local and each hit is on an item."""
        if rule.code not in ITEM_LOCAL:
            return
        by_item: dict[Any, list[Hit]] = {}
        root = self.model.root
        for hit in hits:
            item = item_of(hit.element, root)
            if item is None:
                return
            by_item.setdefault(item, []).append(hit)
        self.hits[rule.code] = by_item


@dataclass
class Reuse:
    """The earlier check's :class:`Carry` and the :class:`~ar3cli.urdf.model_edit.Edit` since: what a run
    of the static rules on the edit's model may take from it (:meth:`hits`, :meth:`prepare`)."""

    carry: Carry
    edit: Edit
    _alone: dict[int, tuple[tuple[Model, Any], Context]] = field(default_factory=dict)

    def usable(self, model: Model, key: tuple) -> bool:
        """Whether this reuse belongs to a run on ``model`` with rules and options ``key``."""
        return self.edit.model is model and self.carry.key == key

    def prepare(self, context: Context) -> None:
        """Give ``context`` the earlier context's answers about the links the edit did not touch."""
        edit = self.edit
        read_again = {id(thing) for thing in edit.after}
        context.inherit(self.carry.context, [link for link in edit.model.links if id(link) not in read_again])

    def hits(self, rule: Rule) -> list[Hit] | None:
        """``rule``'s hits on the edited model from the earlier ones and a check of each changed item alone;
        None when the rule must run in full (not item-local, not kept, or a hit of an item's check that is
        not inside the item)."""
        earlier = self.carry.hits.get(rule.code)
        if earlier is None or rule.check is None:
            return None
        changed = {id(item) for item in self.edit.items}
        found = [hit for element, hits in earlier.items() if id(element) not in changed for hit in hits]
        for item in self.edit.items:
            if id(item) not in self._alone:
                alone = item_model(self.edit.model, item)
                self._alone[id(item)] = (alone, Context(alone[0], self.carry.context.srdf_disabled,
                                                        self.carry.context.targets))
            alone, context = self._alone[id(item)]
            own = item_hits(rule, alone, context, item)
            if own is None:
                return None
            found += own
        return found


def item_hits(rule: Rule, alone: tuple[Model, Any], context: Context, item: Any) -> list[Hit] | None:
    """``rule``'s hits on ``item`` by its definition for an item-local rule: checked in ``alone``
    (:func:`item_model` of the item; ``context`` on its model), each hit taken to the same element of ``item``.
    None when a hit is not inside the copy (on ``<robot>``, or a line)."""
    _model, copied = alone
    mapped = []
    for hit in rule.check(context):  # type: ignore[misc]
        path = _path_in(hit.element, copied) if hit.element is not None else None
        if path is None:
            return None
        mapped.append(replace(hit, element=_follow(item, path)))
    return mapped


def item_model(model: Model, item: Any) -> tuple[Model, Any]:
    """A model of a ``<robot>`` (with ``model``'s root attributes and namespaces) holding a copy of ``item``
    alone, and the copy: what an item-local rule's hits on ``item`` are defined by."""
    from lxml import etree

    root = model.root
    alone = etree.Element(root.tag, attrib=dict(root.attrib), nsmap=root.nsmap)
    copied = copy.deepcopy(item)
    copied.tail = None
    alone.append(copied)
    read: dict[Any, list[tuple[Any, Any]]] = {}
    links = [read_link(element, model.resolver, read) for element in alone.findall("link")]
    joints = [read_joint(element, read) for element in alone.findall("joint")]
    return replace(model, root=alone, links=links, joints=joints, read_children=read, quirks=[],
                   edited_away=False), copied


def _path_in(element: Any, top: Any) -> tuple[int, ...] | None:
    """The child indexes from ``top`` down to ``element``, or None when ``element`` is not inside ``top``."""
    path = []
    while element is not top:
        parent = element.getparent()
        if parent is None:
            return None
        path.append(parent.index(element))
        element = parent
    return tuple(reversed(path))


def _follow(top: Any, path: tuple[int, ...]) -> Any:
    for index in path:
        top = top[index]
    return top
