"""Which link pairs are in contact at one pose: sample-collisions' own check, in a pybullet child kept
alive while a viewer moves the joints.

The check is the one ``sample-collisions`` counts with (:class:`ar3cli.collisions.checker.Checker`:
pybullet's self-collision flag, manifold points that never go stale, a pair *in contact* when it
penetrates deeper than :data:`~ar3cli.sim.session.PENETRATION_TOLERANCE`), and the pairs it reports
are the ones sample-collisions would call ``default`` at that pose: MoveIt's adjacent pairs (joined by
a joint, looking through links without collision geometry: :func:`ar3cli.sim.adjacency.adjacent_pairs`)
are left out, as they touch by construction. At the home pose these are the pairs the pictures and
``lint-urdf --sim`` (P002) draw and report.

The checker is loaded once per analysis, in a :class:`~ar3cli.sim.kept_child.KeptChild` opened with
:meth:`~ar3cli.analysis.robot.RobotAnalysis.keep` (closed with the analysis); each pose is then one
question to it (about a millisecond). A crash of pybullet is a one-line UserError, raised again for
every later pose of that analysis: a viewer shows it and goes on drawing.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ar3cli.analysis.robot import RobotAnalysis

if TYPE_CHECKING:
    from ar3cli.collisions.checker import Checker
    from ar3cli.sim.kept_child import KeptChild
    from ar3cli.urdf.model import Model

CHECKER = "contacts"
"""The :meth:`RobotAnalysis.keep` key of the kept checker."""


@dataclass(frozen=True)
class Contacts:
    """The pairs in contact at one pose (link names, each pair in pybullet link order, sorted)."""

    pairs: list[tuple[str, str]] = field(default_factory=list)
    note: str | None = None
    """Why nothing could be in contact (fewer than two links with collision geometry), else None."""
    unchecked: list[str] = field(default_factory=list)
    """Links left out of the check: pybullet cannot load their collision mesh (as sample-collisions)."""

    def links(self) -> set[str]:
        return {link for pair in self.pairs for link in pair}


def contacts(analysis: RobotAnalysis, values: Mapping[str, float]) -> Contacts:
    """The non-adjacent link pairs in contact at the configuration ``values`` (every 1-DOF joint's
    value by name, mimic joints included: :meth:`ar3cli.analysis.poses.Posing.joint_values`; a joint
    left out is at 0). UserError when pybullet cannot load the robot or crashed; a link whose
    collision mesh it cannot load is left out (``unchecked``)."""
    from ar3cli.collisions.run import no_pairs_message
    from ar3cli.sim.adjacency import collision_links, unloadable_collision_links

    model = analysis.require_model()
    if len(collision_links(model)) < 2:
        return Contacts(note=no_pairs_message(model).removeprefix(f"{model.path}: "))
    child: KeptChild = analysis.keep(CHECKER, lambda: open_checker(model))
    return Contacts([tuple(pair) for pair in child.ask(dict(values))],  # type: ignore[misc]
                    unchecked=unloadable_collision_links(model))


def open_checker(model: Model) -> KeptChild:
    """A kept pybullet child holding sample-collisions' checker of ``model``."""
    from ar3cli.sim.kept_child import KeptChild
    from ar3cli.sim.session import known_crash_cause

    return KeptChild(lambda: _Loaded(model), _in_contact, str(model.path), cause=lambda: known_crash_cause(model),
                     asking="checking contacts")


class _Loaded:
    """In the child: the checker and the pair ids that are adjacent (never reported)."""

    def __init__(self, model: Model) -> None:
        from ar3cli.collisions.checker import Checker
        from ar3cli.sim.adjacency import adjacent_pairs

        self.checker: Checker = Checker(model)
        links, pairs = self.checker.links, self.checker.pairs
        adjacent = adjacent_pairs(model, links)
        self.adjacent = {pair_id for pair_id, (i, j) in enumerate(pairs) if frozenset((links[i], links[j])) in adjacent}
        self.order = [joint.name for joint in self.checker.body.actuated_joints]

    def close(self) -> None:
        self.checker.close()


def _in_contact(loaded: _Loaded, values: Mapping[str, float]) -> list[tuple[str, str]]:
    """In the child: the non-adjacent pairs in contact at ``values``."""
    checker = loaded.checker
    q = [float(values.get(name, 0.0)) for name in loaded.order]
    return [(checker.links[checker.pairs[pair_id][0]], checker.links[checker.pairs[pair_id][1]])
            for pair_id in checker.colliding(q) if pair_id not in loaded.adjacent]
