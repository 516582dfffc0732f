"""fix-collision's comparison of the original and the fixed robot in PyBullet.

A convex decomposition is meant to collide *less* than the mesh's hull, yet its parts are hulls of
a voxelised approximation and can reach past the original surface: on a humanoid, a decomposed
torso touched both shoulder links at the home pose, and ``sample-collisions`` then called those
pairs "default", so an SRDF made after the fix disabled checks between parts that really collide.
Static lint cannot see that; this module can. It runs the self-collision matrix of
:mod:`ar3cli.collisions` (home pose, joint limits, a ``--seed``-ed sample of configurations, one
process) on the original robot and on the candidate fix, and refuses every replacement on a link
of a pair that is worse after it: touching at home where it did not, or a category further up
``never < sometimes < always < default``. Pairs that collide less are the fix working. Refusing
is repeated until no worse pair is left that a replacement could cause; what was compared is kept
for the verification table.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ar3cli.errors import UserError
from ar3cli.findings import listed

CATEGORY_RANK = {"never": 0, "sometimes": 1, "always": 2, "default": 3}
"""Pair categories by how much collision they say; a move up the ranks means the fix added contacts
(``adjacent`` depends on the joints alone and cannot change)."""
ALWAYS_THRESHOLD = 0.95
"""sample-collisions' default: a pair colliding in at least this share of samples is 'always'."""


def accept_replacements(model: Any, target: Path, pending: list, inserts: list, plan: Any, options: Any) -> list:
    """The replacements of ``pending`` that make no pair worse; the others get ``refused_because``.

    ``inserts`` (``--from-visual`` additions) are part of every candidate; ``target`` is where the
    fixed URDF will be, so relative part URIs resolve as they will after the write.
    """
    from ar3cli.urdf.model import load_model

    try:
        before = pair_states(model, options.samples, options.seed)
    except UserError as exc:
        plan.context["comparison"] = {"error": exc.message.removeprefix(f"{model.path}: ")}
        return list(pending)
    accepted = list(pending)
    while True:
        data = candidate_bytes(model, inserts, accepted)
        try:
            after = pair_states(load_model(target, model.resolver.package_paths, source=data), options.samples,
                                options.seed)
        except UserError as exc:
            plan.context["comparison"] = {"error": f"the fixed robot: {exc.message}"}
            return accepted
        worse = worse_pairs(before, after)
        blamed = [r for r in accepted if any(r.link in pair for pair in worse)]
        if not blamed:
            break
        for replacement in blamed:
            replacement.refused_because = listed((worse[pair] for pair in worse if replacement.link in pair),
                                                 separator="; ")
            accepted.remove(replacement)
    plan.context["comparison"] = {
        "samples": options.samples, "seed": options.seed, "pairs": len(before),
        "home_before": sum(state[1] for state in before.values()),
        "home_after": sum(state[1] for state in after.values()),
        "less": sorted(f"{a}/{b}: {before[(a, b)][0]} -> {after[(a, b)][0]}" for a, b in after
                       if (a, b) in before and _rank(after[(a, b)][0]) < _rank(before[(a, b)][0])),
        "worse": sorted(worse.values()),
        "refused": [r.link for r in pending if r not in accepted]}
    return accepted


def candidate_bytes(model: Any, inserts: list, replacements: list) -> bytes:
    """The original bytes with the ``--from-visual`` insertions and ``replacements`` applied."""
    from ar3cli.urdf.edits import Document

    scratch = Document(model.source_bytes)
    scratch.bind(model.root)
    for insert in inserts:
        insert(scratch)
    for replacement in replacements:
        scratch.splice(*replacement.splice)
    return scratch.apply()


def pair_states(model: Any, samples: int, seed: int) -> dict[tuple[str, str], tuple[str, bool]]:
    """Each sampled pair's (category, touching at home), from the self-collision matrix."""
    from ar3cli.collisions.run import sample_matrix

    run = sample_matrix(model, samples, seed, 1, ALWAYS_THRESHOLD)
    return {tuple(sorted((r.link_a, r.link_b))): (r.category, r.at_home) for r in run.results if r.sampled}


def worse_pairs(before: dict, after: dict) -> dict[tuple[str, str], str]:
    """Pairs that collide more after the fix, each with a phrase saying how."""
    worse = {}
    for pair, (category, home) in after.items():
        if pair not in before:
            continue  # a link that had no collision before (--from-visual): nothing to compare with
        old_category, old_home = before[pair]
        if home and not old_home:
            worse[pair] = f"{pair[0]} and {pair[1]} touch at the home pose (the original meshes do not)"
        elif _rank(category) > _rank(old_category):
            worse[pair] = f"{pair[0]} and {pair[1]} go from '{old_category}' to '{category}'"
    return worse


def comparison_rows(comparison: dict | None) -> list[dict[str, str]]:
    """The verification table's rows saying what was compared, original against fixed."""
    from ar3cli.fix.driver import check_row

    if not comparison:
        return []
    if "error" in comparison:
        return [check_row("(robot)", "original vs fixed in PyBullet", False, f"not compared: {comparison['error']}")]
    worse = comparison["worse"]
    home = check_row("(robot)", "home contacts, original vs fixed", not worse,
                     f"{comparison['home_before']} pair(s) touching at home before, {comparison['home_after']} after")
    less = comparison["less"]
    detail = (f"{comparison['pairs']} pair(s), {comparison['samples']} samples, seed {comparison['seed']}: "
              f"{len(less)} collide less" + (f" ({', '.join(less[:3])}{', ...' if len(less) > 3 else ''})" if less else "")
              + (f"; worse: {listed(worse, separator='; ')}" if worse else ", none more"))
    rows = [home, check_row("(robot)", "pair categories, original vs fixed", not worse, detail)]
    return rows


def _rank(category: str) -> int:
    return CATEGORY_RANK.get(category, -1)
