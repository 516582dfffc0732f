"""The self-collision matrix: classify link pairs like MoveIt Setup Assistant, with statistics.

Categories, in MoveIt's order of precedence (``compute_default_collisions.cpp``):

1. ``adjacent``: joined by a joint, links without collision geometry being transparent (removed and
   their neighbours joined), so parent and grandchild across a geometry-less link are adjacent
   (:func:`ar3cli.sim.adjacency.adjacent_pairs`, shared with lint-urdf's P002 and render).
2. ``default``: in contact at the home pose (0, or mid-range where 0 is outside the limits).
3. ``always``: in contact in at least ``always_threshold`` (0.95) of the uniform samples.
4. ``never``: never in contact, neither in the uniform samples nor in any limit configuration
   (MoveIt has no limit samples; a pair that only touches at a joint limit stays enabled here).
   Reported with the exact one-sided 95% upper bound on its collision probability,
   ``1 - 0.05 ** (1 / N)`` (about 3/N): "never seen" is not "impossible".
5. ``sometimes``: everything else, with the fraction and a Wilson 95% interval. Kept enabled.

A pair is counted only until its category is decided (:func:`settled`, :mod:`ar3cli.collisions.rounds`):
its :attr:`PairResult.samples` may then be fewer than the run's N, and its fraction and interval are
over those samples only (an estimate; the category is exact).

The first four are the pairs MoveIt disables (``<disable_collisions reason="Adjacent|Default|
Always|Never"/>``, written, merged and compared by :mod:`ar3cli.collisions.srdf_files`) and the pairs to
pass to ``setCollisionFilterPair`` in PyBullet.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from ar3cli.findings import Finding, Severity, listed
from ar3cli.sim.adjacency import direct_parent_child
from ar3cli.urdf.model import Model

__all__ = ["classify", "findings", "pybullet_filter_bytes"]

CATEGORIES = ("adjacent", "default", "always", "never", "sometimes")
DISABLED = ("adjacent", "default", "always", "never")
SRDF_REASONS = {"adjacent": "Adjacent", "default": "Default", "always": "Always", "never": "Never"}
ALWAYS_THRESHOLD = 0.95
"""The default share of samples in contact that makes a pair ``always`` (sample-collisions'
``--always-threshold``, MoveIt Setup Assistant's 95%)."""
Z_95 = 1.959963984540054
ADJACENT_MIN_SAMPLES = 50
"""An adjacent pair is counted over at least this many samples (or all of them) before it is retired:
with ``--always-threshold`` near 1 the first round would otherwise be a sample or two."""


def wilson_interval(successes: int, trials: int, z: float = Z_95) -> tuple[float, float]:
    """Wilson score interval for a binomial proportion (95% by default); (0, 1) with no trials."""
    if trials <= 0:
        return 0.0, 1.0
    phat = successes / trials
    denominator = 1 + z * z / trials
    centre = (phat + z * z / (2 * trials)) / denominator
    half = z * math.sqrt(phat * (1 - phat) / trials + z * z / (4 * trials * trials)) / denominator
    # At 0 (or N) successes the bound is exactly 0 (or 1); computed, it comes out ~1e-17 off.
    low = 0.0 if successes <= 0 else max(0.0, centre - half)
    high = 1.0 if successes >= trials else min(1.0, centre + half)
    return low, high


def zero_success_upper_bound(trials: int, confidence: float = 0.95) -> float:
    """Exact one-sided upper bound on p after ``trials`` clean trials: 1 - (1 - c) ** (1 / N) ~ 3/N."""
    if trials <= 0:
        return 1.0
    return 1.0 - (1.0 - confidence) ** (1.0 / trials)


@dataclass
class PairResult:
    """One pair of links with collision geometry and what the sampling found."""

    link_a: str
    link_b: str
    category: str
    collisions: int
    samples: int
    """Uniform samples the pair was checked in: the run's N, fewer when its category was decided
    earlier (retired), 0 when decided before sampling (touching at home) or never checked."""
    at_home: bool
    limit_hits: list[str] = field(default_factory=list)
    sampled: bool = True
    """False for a link and its direct parent: adjacent, never checked by pybullet (``samples`` is 0)."""
    total: int = 0
    """The run's N (uniform samples drawn); ``samples`` below it: counted only until decided."""

    @property
    def retired(self) -> bool:
        """Checked in fewer than all samples: its fraction and interval are estimates over ``samples``."""
        return self.sampled and self.samples < self.total

    @property
    def fraction(self) -> float:
        return self.collisions / self.samples if self.samples else 0.0

    @property
    def interval(self) -> tuple[float, float]:
        return wilson_interval(self.collisions, self.samples)

    @property
    def upper_bound(self) -> float:
        """95% upper bound on the collision probability: exact when never seen, else Wilson's."""
        if self.collisions == 0:
            return zero_success_upper_bound(self.samples)
        return self.interval[1]

    def to_dict(self) -> dict:
        low, high = self.interval
        return {"link_a": self.link_a, "link_b": self.link_b, "category": self.category,
                "collisions": self.collisions, "fraction": self.fraction, "upper_bound": self.upper_bound,
                "interval_95": [low, high], "at_home": self.at_home, "limit_hits": self.limit_hits,
                "sampled": self.sampled, "samples": self.samples, "retired": self.retired}


def settled(collisions: int, checked: int, samples: int, always_threshold: float, adjacent: bool,
            at_home: bool) -> bool:
    """True when the ``samples - checked`` samples still to come cannot change what the report
    concludes about a pair that collided in ``collisions`` of the ``checked`` so far.

    - Not adjacent and touching at home: ``default`` whatever the samples say (MoveIt does not
      sample such pairs either).
    - Adjacent (its category fixed by the joint tree; the direct parent-child pairs are never
      tested at all): counted only until it has been checked in more than ``(1 - always_threshold)
      x N`` samples (the first round; at least :data:`ADJACENT_MIN_SAMPLES`), for an *estimate* of
      its fraction. That is all the ``pybullet-default-self-collision`` warning uses; it says over
      how many samples. An adjacent pair touching in every configuration (Romeo's body - hip across
      a geometry-less link) costs a contact manifold per configuration: measured, half of Romeo's
      remaining time per configuration.
    - At the ``always`` threshold already (``collisions / samples``): more collisions keep it there.
    - Free in so many samples that even colliding in every remaining one stays below the threshold,
      having collided: ``sometimes`` whatever follows (not always, not never). A pair that has not
      collided yet is not decided: it may be ``never`` (or touch only at a limit).

    Its fraction over the ``checked`` samples is then on the same side of the threshold as over all
    of them (free > N (1 - t) implies collisions / checked < t), so :func:`classify` gives the
    category that counting every sample would give.
    """
    if at_home and not adjacent:
        return True
    if samples <= 0:
        return False
    if adjacent:
        return checked > samples * (1.0 - always_threshold) and checked >= min(samples, ADJACENT_MIN_SAMPLES)
    if collisions / samples >= always_threshold:
        return True
    cannot_reach = (samples - (checked - collisions)) / samples < always_threshold
    return cannot_reach and collisions > 0


def classify(
    links: Sequence[str],
    pairs: Sequence[tuple[int, int]],
    counts: Sequence[int],
    samples: int,
    adjacent: set[frozenset[str]],
    home_hits: set[int],
    limit_hits: dict[int, list[str]],
    always_threshold: float = 0.95,
    unsampled: set[int] | frozenset[int] = frozenset(),
    checked: Sequence[int] | None = None,
) -> list[PairResult]:
    """One :class:`PairResult` per pair, categorised adjacent > default > always > never > sometimes.
    Pairs in ``unsampled`` (a link and its direct parent: adjacent) get ``samples`` 0. ``checked``:
    the samples each pair was counted in (None: all ``samples``); the ``always`` test is over those,
    which for a pair retired by :func:`settled` gives the category all ``samples`` would give."""
    results = []
    for pair_id, (i, j) in enumerate(pairs):
        a, b = links[i], links[j]
        collisions = int(counts[pair_id])
        seen = 0 if pair_id in unsampled else samples if checked is None else int(checked[pair_id])
        hits = limit_hits.get(pair_id, [])
        if frozenset((a, b)) in adjacent:
            category = "adjacent"
        elif pair_id in home_hits:
            category = "default"
        elif seen and collisions / seen >= always_threshold:
            category = "always"
        elif collisions == 0 and not hits:
            category = "never"
        else:
            category = "sometimes"
        results.append(PairResult(a, b, category, collisions, seen, pair_id in home_hits, hits,
                                  sampled=pair_id not in unsampled, total=samples))
    return results


def category_counts(results: Iterable[PairResult]) -> dict[str, int]:
    counts = {category: 0 for category in CATEGORIES}
    for result in results:
        counts[result.category] += 1
    return counts


def findings(model: Model, results: Sequence[PairResult], links: Sequence[str],
             always_threshold: float) -> list[Finding]:
    """What users trip over: visual-only links, contact at home, pairs pybullet's default flag
    checks although they always touch, pairs that touch only at a joint limit."""
    path = str(model.path)
    found: list[Finding] = []
    visual_only = [link for link in model.links if link.visuals and link.name not in links]
    if visual_only:
        names = listed(link.name for link in visual_only)
        found.append(Finding("visual-only-links", Severity.WARNING,
                             f"{len(visual_only)} link(s) have <visual> but no <collision>: {names}; they never "
                             "collide and count as transparent for adjacency", path, visual_only[0].line,
                             hint="add <collision> elements (a primitive around the visual) if they can hit "
                                  "anything"))
    adjacent_direct = direct_parent_child(model)
    for result in results:
        key = frozenset((result.link_a, result.link_b))
        label = pair_label(result.link_a, result.link_b)
        if result.at_home and result.category != "adjacent":
            found.append(Finding("contact-at-home", Severity.WARNING, contact_at_home(result.link_a, result.link_b), path,
                                 hint="usually a modelling error (check the collision origins and sizes); "
                                      "PyBullet's URDF_USE_SELF_COLLISION would report this contact too"))
        elif key not in adjacent_direct and result.fraction >= always_threshold:
            found.append(Finding("pybullet-default-self-collision", Severity.WARNING,
                                 f"{label} are in contact in {result.fraction:.0%} of {_samples(result)} and PyBullet's "
                                 "URDF_USE_SELF_COLLISION checks them (it skips only direct parent-child pairs)",
                                 path, hint="disable the pair with setCollisionFilterPair (see --pybullet-filter)"))
        if result.category == "sometimes" and result.collisions == 0 and result.limit_hits:
            found.append(Finding("contact-only-at-limits", Severity.INFO,
                                 f"{label} never collided in {result.samples} uniform samples but collide in the "
                                 f"limit configuration(s) {listed(result.limit_hits, separator='; ')}; kept enabled (MoveIt "
                                 "would disable the pair)",
                                 path))
    return found


def pair_label(link_a: str, link_b: str) -> str:
    """``a - b``: how a finding names a link pair (its message starts with it)."""
    return f"{link_a} - {link_b}"


def contact_at_home(link_a: str, link_b: str) -> str:
    """The message of the contact-at-home warning about the pair (report's verdict tells its pairs by it)."""
    return f"{pair_label(link_a, link_b)} are in contact at the home pose but not adjacent"


def _samples(result: PairResult) -> str:
    """``samples`` or ``the first 501 samples`` (a pair counted only until its category was decided)."""
    return "samples" if result.samples >= result.total else f"the first {result.samples} samples"


# ---- export -------------------------------------------------------------------------------------
def disabled_pairs(results: Iterable[PairResult]) -> list[PairResult]:
    return [result for result in results if result.category in DISABLED]


def pybullet_filter_bytes(results: Sequence[PairResult], comment: str = "") -> bytes:
    """JSON pair list for ``setCollisionFilterPair(body, body, link_index[a], link_index[b], 0)``."""
    document = {"comment": comment,
                "usage": "for each pair: p.setCollisionFilterPair(body, body, index[link_a], index[link_b], 0)",
                "pairs": [{"link_a": r.link_a, "link_b": r.link_b, "reason": SRDF_REASONS[r.category]}
                          for r in disabled_pairs(results)]}
    return (json.dumps(document, indent=2) + "\n").encode("utf-8")


# ---- heat map -------------------------------------------------------------------------------------
HEAT_STYLES = {"adjacent": "blue", "default": "bold red", "always": "magenta", "never": "green",
               "sometimes": "yellow"}
HEAT_LEGEND = ("A adjacent, D default (touching at home), X always, . never, "
               "1-9 sometimes (tenths of samples, 1 = under 10%), "
               "L only at a joint limit")


def heat_char(result: PairResult) -> str:
    """One character per pair: its category, or the colliding fraction in tenths for 'sometimes'."""
    if result.category == "sometimes":
        return str(min(9, max(1, math.ceil(result.fraction * 10 - 1e-12)))) if result.collisions else "L"
    return {"adjacent": "A", "default": "D", "always": "X", "never": "."}[result.category]


def heat_map(links: Sequence[str], pairs: Sequence[tuple[int, int]], results: Sequence[PairResult]):
    """A lower-triangular link x link grid as rich Text (colour by category; plain chars without colour)."""
    from rich.text import Text

    from ar3cli.output.report import printable

    links = [printable(name) for name in links]  # rich would obey a newline or an escape sequence in a name
    cell = {pair: result for pair, result in zip(pairs, results)}
    width = max((len(name) for name in links), default=0)
    digits = len(str(max(len(links) - 1, 0)))
    text = Text()
    header = " " * (width + digits + 2) + " ".join(str(k % 10) for k in range(len(links)))
    text.append(header + "\n")
    for i, name in enumerate(links):
        text.append(f"{name:>{width}} {i:>{digits}} ")
        for j in range(len(links)):
            if j >= i:
                break
            result = cell[(j, i)]
            text.append(heat_char(result), style=HEAT_STYLES[result.category])
            text.append(" ")
        text.append("\n")
    text.append(HEAT_LEGEND)
    return text
