"""Self-collision sampling: which link pairs touch, in how many joint configurations.

The fast path per configuration is ``resetJointStatesMultiDof`` + ``performCollisionDetection`` +
one ``getContactPoints(body, body)``, on a body loaded with every pair checked (parent-child
included). Measured on pybullet_data's panda: ~8,700 configs/s against ~3,400 for the tutorial loop
(``resetJointState`` per joint + ``stepSimulation``); see ``benchmarks/bench_collisions.py``.

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
  penetrates deeper than :data:`~ar3cli.sim.session.PENETRATION_TOLERANCE` (1 um), the threshold lint-urdf's
  P002 and render use too.

Configurations are generated up front in the parent by :mod:`ar3cli.sim.sampling` (only the driving
joints are drawn from ``numpy.random.default_rng(seed)``; ``<mimic>`` joints follow), split
into chunks, counted by worker processes (one PyBullet client each) and summed: the counts are exact
and independent of the number of jobs.
"""

from __future__ import annotations

import gc
import math
import multiprocessing
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ar3cli.errors import UserError
from ar3cli.sim.adjacency import collision_links
from ar3cli.sim.sampling import JointSpace, joint_space
from ar3cli.sim.session import PENETRATION_TOLERANCE
from ar3cli.urdf.model import Model, load_model

__all__ = ["Checker", "ModelSource", "count_collisions"]

CONTACT_BREAKING_THRESHOLD = 1e-5
"""m: Bullet drops manifold points that drifted more than this; small, so teleports leave no stale points."""


@dataclass(frozen=True)
class ModelSource:
    """How to load the model again in a worker process (a Model holds lxml trees: not picklable)."""

    path: Path
    package_paths: dict[str, Path] = field(default_factory=dict)
    xacro_args: dict[str, str] = field(default_factory=dict)

    def load(self) -> Model:
        return load_model(self.path, self.package_paths or None, self.xacro_args or None)


class Checker:
    """One PyBullet client with the model loaded for all-pairs self-collision; counts colliding pairs.

    ``pairs`` are the unordered pairs of :attr:`links` (links with collision geometry, in pybullet
    order, base first), as (i, j) with i < j; counts are indexed like ``pairs``.
    """

    def __init__(self, model: Model) -> None:
        from ar3cli.sim.session import Session

        self.session = Session()
        try:
            p, client = self.session.p, self.session.client
            p.setPhysicsEngineParameter(contactBreakingThreshold=CONTACT_BREAKING_THRESHOLD,
                                        physicsClientId=client)
            self.body = self.session.load(model, self_collision="all-pairs")
        except BaseException:
            self.session.close()
            raise
        with_geometry = set(collision_links(model))
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
        lookup, indices, tolerance = self._lookup, self._joint_indices, -PENETRATION_TOLERANCE
        counts = [0] * len(self.pairs)
        targets = configs[:, :, None].tolist()  # [[q0], [q1], ...] per row, as resetJointStatesMultiDof wants
        for target in targets:
            if indices:
                reset(body, indices, target, physicsClientId=client)
            detect(physicsClientId=client)
            hits = {lookup[point[3] + 1][point[4] + 1]
                    for point in contacts(body, body, physicsClientId=client) if point[8] < tolerance}
            hits.discard(-1)
            for pair_id in hits:
                counts[pair_id] += 1
            if hits_out is not None:
                hits_out.update(hits)
        return np.array(counts, dtype=np.int64)


# ---- parallel counting ----------------------------------------------------------------------------
# The parent and J-1 child processes pull chunks from a shared counter until none is left, so a
# process that starts late or runs slowly simply takes fewer chunks; every chunk's counts depend
# only on its configurations, so the sums are exact and identical for any J.
_inherited_checker: Checker | None = None
_DONE = "done"


def chunk_bounds(total: int, jobs: int, per_job: int = 8, minimum: int = 100) -> list[tuple[int, int]]:
    """Contiguous [start, stop) chunks: about ``per_job`` per job (balance, progress), none tiny."""
    if total <= 0:
        return []
    count = max(1, min(jobs * per_job, math.ceil(total / minimum)))
    edges = np.linspace(0, total, count + 1).round().astype(int)
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]


def start_method() -> str:
    """``fork`` where the platform has it: the child inherits the parent's loaded client (a private
    copy-on-write copy of an in-process DIRECT world), so a worker starts in milliseconds instead of
    ~0.7 s (Python start + pybullet import + loading and hulling the meshes again). Elsewhere ``spawn``,
    and each worker loads the model itself."""
    return "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"


def _claim(next_chunk, chunks) -> tuple[int, int] | None:
    with next_chunk.get_lock():
        index = next_chunk.value
        next_chunk.value += 1
    return chunks[index] if index < len(chunks) else None


def _child(source: ModelSource | None, configs: np.ndarray, chunks, next_chunk, results) -> None:
    """A worker process: count chunks until none is left, then say so (errors travel as messages)."""
    try:
        checker = _inherited_checker if source is None else Checker(source.load())
        assert checker is not None
        while (chunk := _claim(next_chunk, chunks)) is not None:
            results.put((chunk[1] - chunk[0], checker.count(configs[chunk[0]:chunk[1]])))
    except BaseException as exc:  # noqa: BLE001 - reported by the parent as a one-line error
        results.put(("error", str(exc)))
    finally:
        results.put(_DONE)


def count_collisions(
    checker: Checker,
    source: ModelSource,
    configs: np.ndarray,
    jobs: int = 1,
    progress: Callable[[int], None] | None = None,
    method: str | None = None,
) -> np.ndarray:
    """Per-pair collision counts over ``configs`` (rows), in ``checker`` plus ``jobs - 1`` worker
    processes (one PyBullet client each); exact and independent of ``jobs``.

    ``progress(n)`` is called with the number of configurations finished, chunk by chunk.
    """
    global _inherited_checker
    chunks = chunk_bounds(len(configs), jobs)
    counts = np.zeros(len(checker.pairs), dtype=np.int64)
    tick = progress or (lambda done: None)
    if jobs <= 1 or len(chunks) <= 1:
        for start, stop in chunks:
            counts += checker.count(configs[start:stop])
            tick(stop - start)
        return counts
    method = method or start_method()
    context = multiprocessing.get_context(method)
    next_chunk, results = context.Value("i", 0), context.SimpleQueue()
    _inherited_checker = checker if method == "fork" else None
    children = [context.Process(target=_child, daemon=True,
                                args=(None if method == "fork" else source, configs, chunks, next_chunk, results))
                for _ in range(min(jobs, len(chunks)) - 1)]
    gc.freeze()  # forked children then leave the parent's objects alone: fewer copy-on-write page faults
    try:
        for child in children:
            child.start()
        running = len(children)

        def take(message) -> None:
            nonlocal counts, running
            if message == _DONE:
                running -= 1
            elif message[0] == "error":
                raise UserError(f"{source.path}: a collision worker failed: {message[1]}")
            else:
                counts += message[1]
                tick(message[0])

        while (chunk := _claim(next_chunk, chunks)) is not None:
            counts += checker.count(configs[chunk[0]:chunk[1]])
            tick(chunk[1] - chunk[0])
            while not results.empty():
                take(results.get())
        while running:
            if results.empty() and not any(child.is_alive() for child in children):
                raise UserError(f"{source.path}: a collision worker process died; rerun with --jobs 1")
            take(results.get())
    finally:
        gc.unfreeze()
        _inherited_checker = None
        for child in children:
            child.join(timeout=5)
            if child.is_alive():
                child.terminate()
    return counts
