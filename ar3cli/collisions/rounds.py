"""Counting in rounds: a pair whose category the remaining samples cannot change stops being tested.

Most of a humanoid's sampling time goes to pairs whose answer is known long before the last sample:
a pair touching at home is ``default`` whatever the samples say, and a pair seen colliding that has
also been free in more than ``(1 - always_threshold) x N`` samples is ``sometimes`` whatever follows
(it can no longer reach the ``always`` threshold, and it is not ``never``). Such a pair is *retired*:
:meth:`~ar3cli.collisions.checker.Checker.retire` filters it with ``setCollisionFilterPair``, so the
configurations that follow cost no narrowphase work for it (Romeo, 2,000 samples, measured in-process:
5.2 s with every pair tested, 1.7 s with only the ``never`` pairs left). Its count and the number of
samples it was checked in are kept: the report gives its fraction and interval over those samples,
an estimate, and says so.

Which pairs are decided is asked only at the round boundaries of :func:`round_bounds`, which depend
on N and the threshold alone, and the counts of a round are exact for any number of processes
(:func:`~ar3cli.collisions.checker.count_collisions`): so the output is the same for any ``--jobs``,
and the same seed gives the same output. Every category equals the one that counting every pair in
every sample gives (:func:`ar3cli.collisions.matrix.settled` says why).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ar3cli.collisions.checker import Checker, count_collisions, default_workers

__all__ = ["count_in_rounds", "round_bounds"]

GROWTH = 1.5
"""Each round is this much longer than the samples before it: a pair is retired at most ~1.5x later
than it could have been, and 100,000 samples take 8 rounds (8 forks per worker: milliseconds)."""

Settled = Callable[[int, int, int], bool]
"""``settled(pair_id, collisions, checked)``: True when more samples cannot change the pair's verdict."""


def round_bounds(total: int, always_threshold: float) -> list[tuple[int, int]]:
    """Contiguous [start, stop) rounds covering ``total`` samples. The first ends just after
    ``(1 - always_threshold) x total`` samples, where a 'sometimes' pair can first be decided; each
    next one ends :data:`GROWTH` times further."""
    if total <= 0:
        return []
    stop = min(total, max(1, math.floor(total * (1.0 - always_threshold)) + 1))
    bounds, start = [], 0
    while start < total:
        bounds.append((start, stop))
        start, stop = stop, min(total, max(stop + 1, math.ceil(stop * GROWTH)))
    return bounds


def count_in_rounds(checker: Checker, configs: np.ndarray, settled: Settled, always_threshold: float,
                    jobs: int | None = None, progress: Callable[[int], None] | None = None
                    ) -> tuple[np.ndarray, np.ndarray, int]:
    """Per-pair (collision counts, samples checked) over ``configs`` and the number of processes used.

    Between rounds the pairs ``settled`` calls decided are retired: their counts and checked samples
    stop growing. Pairs never tested (:attr:`~ar3cli.collisions.checker.Checker.unsampled`) have 0
    and 0. The result is the same for any ``jobs``.
    """
    total, count = len(configs), len(checker.pairs)
    counts = np.zeros(count, dtype=np.int64)
    checked = np.zeros(count, dtype=np.int64)
    active = np.ones(count, dtype=bool)
    active[list(checker.unsampled)] = False
    workers = default_workers(jobs, total, checker.sampled_pairs)

    def retire_settled() -> None:
        decided = [int(pair_id) for pair_id in np.flatnonzero(active)
                   if settled(int(pair_id), int(counts[pair_id]), int(checked[pair_id]))]
        checker.retire(decided)
        active[decided] = False

    retire_settled()
    rounds = round_bounds(total, always_threshold)
    for index, (start, stop) in enumerate(rounds):
        part = count_collisions(checker, configs[start:stop], workers, progress)
        counts[active] += part[active]
        checked[active] += stop - start
        if index + 1 < len(rounds):  # nothing is tested after the last round: its filters (measured
            # ~0.1 ms per setCollisionFilterPair on talos_reduced, 2-35 pairs there) would be wasted
            retire_settled()
    return counts, checked, workers
