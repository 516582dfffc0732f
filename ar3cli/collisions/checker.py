"""Self-collision sampling: which link pairs touch, in how many joint configurations.

The fast path per configuration is ``resetJointStatesMultiDof`` + ``performCollisionDetection`` +
one ``getContactPoints(body, body)``, on a body loaded with pybullet's own self-collision flag
(``URDF_USE_SELF_COLLISION``): every pair is checked except a link and its direct parent. Those
pairs are adjacent by definition (MoveIt disables them a priori), always touch at the joint, and
checking them was most of the work (their contact points every configuration): they are reported
as adjacent without being sampled (:attr:`Checker.unsampled`). Pairs joined only through joints
that no configuration moves (fixed joints: panda_link7 - panda_hand through the geometry-less
panda_link8; talos_reduced's 72 such pairs) keep their relative pose, so they are tested once at
load and then filtered out with ``setCollisionFilterPair`` (:attr:`Checker.constant`): their count is
every configuration or none, exactly what testing them every time gives, at no cost per
configuration (measured in-process: 36 -> 24 us per configuration on the panda, 900 -> 675 us on
talos_reduced). How often a pair adjacent across a geometry-less link touches is what the
``pybullet-default-self-collision`` warning reports.
Whole-process timings against the plain script a user would write are in ``benchmarks/``.

Two measured facts shape this module:

- Teleporting joints leaves stale points in Bullet's persistent contact manifolds: a point is
  re-measured along the *previous* configuration's contact normal and is only dropped when it drifts
  more than the contact breaking threshold (0.02 m by default). On the AR3's gripper (fingers resting
  flat on the gripper base) that made ~1% of configurations report a 1-2 mm penetration that a
  one-shot ``getClosestPoints`` test does not find, and made results depend on the previous
  configuration. :data:`CONTACT_BREAKING_THRESHOLD` = 10 um drops every stale point; with it the
  counts match an independent per-pair ``getClosestPoints`` check exactly (panda, kuka_iiwa, AR3,
  2,000 configs each) and each configuration's result no longer depends on the one before, which is
  what makes the merged counts identical for any number of jobs.
- ``getContactPoints`` also reports points at small positive distance (up to ~4 mm on the panda) and
  faces that rest exactly on each other (distance ~1e-17). A pair counts as *colliding* only when it
  penetrates deeper than :data:`~ar3cli.sim.session.PENETRATION_TOLERANCE` (1 um), the threshold
  lint-urdf's P002 and render use too.

Configurations are generated up front by :mod:`ar3cli.sim.sampling` (only the driving joints are
drawn from ``numpy.random.default_rng(seed)``; ``<mimic>`` joints follow), split into chunks and
counted by forked copies of the loaded checker (:mod:`ar3cli.infra.process_pool`, the project's one
pool): the counts are exact and independent of the number of jobs.
"""

from __future__ import annotations

import gc
import math
import os
from collections.abc import Callable, Iterable, Sequence

import numpy as np

from ar3cli.sim.adjacency import collision_links, direct_parent_child, rigid_groups, unloadable_collision_links
from ar3cli.sim.sampling import JointSpace, joint_space
from ar3cli.sim.session import PENETRATION_TOLERANCE, SELF_COLLISION_DEFAULT
from ar3cli.urdf.model import Model

__all__ = ["Checker", "count_collisions", "default_workers"]

CONTACT_BREAKING_THRESHOLD = 1e-5
"""m: Bullet drops manifold points that drifted more than this; small, so teleports leave no stale points."""


class Checker:
    """One PyBullet client with the model loaded for self-collision; counts colliding pairs.

    ``pairs`` are the unordered pairs of :attr:`links` (links with collision geometry, in pybullet
    order, base first; not the :attr:`unchecked` ones), as (i, j) with i < j; counts are indexed like ``pairs``. The pairs in
    :attr:`unsampled` (a link and its direct parent) are never checked: their count stays 0. The
    pairs in :attr:`constant` (joined only through joints no configuration moves) are checked once,
    at load: their count is every configuration or none.
    """

    def __init__(self, model: Model) -> None:
        from ar3cli.sim.session import Session

        self.session = Session()
        try:
            p, client = self.session.p, self.session.client
            p.setPhysicsEngineParameter(contactBreakingThreshold=CONTACT_BREAKING_THRESHOLD,
                                        physicsClientId=client)
            self.body = self.session.load(model, self_collision=SELF_COLLISION_DEFAULT, visuals=False,
                                          leave_out_unloadable=True)
        except BaseException:
            self.session.close()
            raise
        self.unchecked: list[str] = unloadable_collision_links(model)
        with_geometry = set(collision_links(model)) - set(self.unchecked)
        self.links: list[str] = [name for name in self.body.link_names if name in with_geometry]
        self.pairs: list[tuple[int, int]] = [(i, j) for i in range(len(self.links))
                                             for j in range(i + 1, len(self.links))]
        # lookup[a + 1][b + 1] -> pair id for pybullet link indices a, b (base is -1); -1 = not a pair
        size = len(self.body.link_names) + 1
        self._lookup = [[-1] * size for _ in range(size)]
        for pair_id, (i, j) in enumerate(self.pairs):
            a, b = self.body.link_index[self.links[i]] + 1, self.body.link_index[self.links[j]] + 1
            self._lookup[a][b] = self._lookup[b][a] = pair_id
        self._joint_indices = [joint.index for joint in self.body.actuated_joints]
        direct = direct_parent_child(model)
        self.unsampled: set[int] = {pair_id for pair_id, (i, j) in enumerate(self.pairs)
                                    if frozenset((self.links[i], self.links[j])) in direct}
        group = rigid_groups(model, (joint.name for joint in self.body.actuated_joints))
        self.constant: set[int] = {pair_id for pair_id, (i, j) in enumerate(self.pairs)
                                   if pair_id not in self.unsampled and group[self.links[i]] == group[self.links[j]]}
        self._constant_hits = self._settle_constant_pairs()

    @property
    def sampled_pairs(self) -> int:
        """How many pairs each configuration tests: all but :attr:`unsampled` and :attr:`constant`."""
        return len(self.pairs) - len(self.unsampled) - len(self.constant)

    def _settle_constant_pairs(self) -> set[int]:
        """Test the :attr:`constant` pairs once, at the pose just loaded, then stop pybullet testing them.

        A pair joined only through joints that no configuration moves keeps its relative pose, so it
        collides in every configuration or in none (the panda's link7-hand, fixed through the
        geometry-less link8; talos_reduced's 72 pairs joined by fixed joints).
        """
        p, client, body = self.session.p, self.session.client, self.body.id
        hits = self._hits() if self.constant else set()
        for pair_id in self.constant:
            i, j = self.pairs[pair_id]
            p.setCollisionFilterPair(body, body, self.body.link_index[self.links[i]],
                                     self.body.link_index[self.links[j]], 0, physicsClientId=client)
        return hits & self.constant

    def retire(self, pair_ids: Iterable[int]) -> None:
        """Stop pybullet testing these pairs (``setCollisionFilterPair``): their category is decided.

        A retired pair costs no narrowphase work in the configurations that follow; its count then
        stays where it was (:func:`ar3cli.collisions.rounds.count_in_rounds` stops adding to it).
        Pairs pybullet does not test anyway (:attr:`unsampled`, :attr:`constant`) are skipped.
        """
        p, client, body = self.session.p, self.session.client, self.body.id
        index = self.body.link_index
        for pair_id in pair_ids:
            if pair_id in self.unsampled or pair_id in self.constant:
                continue
            i, j = self.pairs[pair_id]
            p.setCollisionFilterPair(body, body, index[self.links[i]], index[self.links[j]], 0,
                                     physicsClientId=client)

    def _hits(self) -> set[int]:
        """Pair ids penetrating deeper than the tolerance at the current pose (after a fresh collision pass)."""
        p, client = self.session.p, self.session.client
        p.performCollisionDetection(physicsClientId=client)
        return _penetrating(p.getContactPoints(self.body.id, self.body.id, physicsClientId=client), self._lookup)

    def __enter__(self) -> Checker:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def close(self) -> None:
        self.session.close()

    def joint_space(self) -> JointSpace:
        """The body's joint space (:mod:`ar3cli.sim.sampling`): mimic joints follow their source."""
        return joint_space(self.body)

    def colliding(self, q: Sequence[float]) -> list[int]:
        """Pair ids in collision at one configuration, sorted."""
        hits: set[int] = set()
        self._check(np.asarray(q, dtype=float).reshape(1, -1), hits_out=hits)
        return sorted(hits)

    def count(self, configs: np.ndarray) -> np.ndarray:
        """How many of ``configs`` (rows) put each pair in collision (int64, one per pair)."""
        return self._check(configs)

    def _check(self, configs: np.ndarray, hits_out: set[int] | None = None) -> np.ndarray:
        p, client, body = self.session.p, self.session.client, self.body.id
        reset, detect, contacts = p.resetJointStatesMultiDof, p.performCollisionDetection, p.getContactPoints
        lookup, indices = self._lookup, self._joint_indices
        counts = [0] * len(self.pairs)
        targets = configs[:, :, None].tolist()  # [[q0], [q1], ...] per row, as resetJointStatesMultiDof wants
        for target in targets:
            if indices:
                reset(body, indices, target, physicsClientId=client)
            detect(physicsClientId=client)
            hits = _penetrating(contacts(body, body, physicsClientId=client), lookup)
            for pair_id in hits:
                counts[pair_id] += 1
            if hits_out is not None:
                hits_out.update(hits)
        for pair_id in self.constant:  # settled once at load (pybullet no longer tests them)
            counts[pair_id] = len(targets) if pair_id in self._constant_hits else 0
        if hits_out is not None:
            hits_out.difference_update(self.constant)
            hits_out.update(self._constant_hits if targets else ())
        return np.array(counts, dtype=np.int64)


def _penetrating(points: Sequence[tuple], lookup: list[list[int]]) -> set[int]:
    """The pair ids (``lookup[a + 1][b + 1]``) of contact ``points`` deeper than the tolerance."""
    hits = {lookup[point[3] + 1][point[4] + 1] for point in points if point[8] < -PENETRATION_TOLERANCE}
    hits.discard(-1)
    return hits


# ---- parallel counting ----------------------------------------------------------------------------
def chunk_bounds(total: int, jobs: int, per_job: int = 8, minimum: int = 100) -> list[tuple[int, int]]:
    """Contiguous [start, stop) chunks: about ``per_job`` per job (balance, progress), none tiny."""
    if total <= 0:
        return []
    count = max(1, min(jobs * per_job, math.ceil(total / minimum)))
    edges = np.linspace(0, total, count + 1).round().astype(int)
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]


PAIR_SAMPLES_PER_WORKER = 100_000
"""Automatic --jobs adds a process per this many (sampled pair x configuration) checks: a forked copy
of the loaded checker starts in a few milliseconds, which pays from ~50 ms of work on. The panda (46
sampled pairs) gets a second process from ~2,200 samples, as the old rule of one per 2,000 samples
gave; a humanoid (Romeo: 885 sampled pairs, ~1 ms per configuration) from ~115 samples."""


def default_workers(jobs: int | None, samples: int, pairs: int) -> int:
    """Processes for ``samples`` configurations of ``pairs`` sampled pairs: ``jobs`` if given (at most
    one per CPU and per sample), else one per :data:`PAIR_SAMPLES_PER_WORKER` checks, at most one per CPU."""
    from ar3cli.infra.process_pool import worker_count

    if samples <= 0:
        return 1
    return min(samples, worker_count(jobs, samples * max(1, pairs), PAIR_SAMPLES_PER_WORKER))


def count_collisions(checker: Checker, configs: np.ndarray, jobs: int | None = None,
                     progress: Callable[[int], None] | None = None) -> np.ndarray:
    """Per-pair collision counts over ``configs`` (rows): exact and independent of ``jobs``.

    ``jobs`` processes share the chunks, this one included (None: :func:`default_workers`); each
    child is a fork of this process with the model already loaded (a private copy-on-write copy of
    the in-process DIRECT world), so it starts in
    milliseconds. ``progress(n)`` is called as chunks finish (this process's own chunks, scaled
    by the number of processes: the others advance at the same pace).
    """
    from ar3cli.infra.process_pool import map_in_processes

    workers = default_workers(jobs, len(configs), checker.sampled_pairs)
    chunks = chunk_bounds(len(configs), workers)
    parent = os.getpid()
    tick = progress or (lambda done: None)

    def count(bounds: tuple[int, int]) -> np.ndarray:
        start, stop = bounds
        counts = checker.count(configs[start:stop])
        if os.getpid() == parent:
            tick((stop - start) * workers)
        return counts

    gc.freeze()  # forked children then leave the parent's objects alone: fewer copy-on-write page faults
    try:
        parts = map_in_processes(count, chunks, workers, what="a collision worker")
    finally:
        gc.unfreeze()
    return np.sum(parts, axis=0, dtype=np.int64) if parts else np.zeros(len(checker.pairs), dtype=np.int64)
