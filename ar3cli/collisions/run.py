"""One sample-collisions run: load the model in pybullet (in a forked child), check the home and
limit configurations, count the uniform samples, classify every pair like MoveIt."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

from ar3cli.collisions import matrix as cm
from ar3cli.errors import UserError
from ar3cli.findings import Finding
from ar3cli.urdf.model import Model


@dataclass
class MatrixRun:
    """What a run found: the links and pairs, each pair's result, and how the sampling went."""

    links: list[str]
    pairs: list[tuple[int, int]]
    results: list[cm.PairResult]
    warnings: list[Finding]
    samples: int
    seed: int
    jobs: int
    limit_configurations: int
    dof: int
    elapsed_s: float
    always_threshold: float
    unsampled: set[int] = field(default_factory=set)
    unchecked: list[str] = field(default_factory=list)
    """Links left out of the matrix: a collision mesh pybullet cannot load
    (:func:`~ar3cli.sim.adjacency.unloadable_collision_links`)."""

    @property
    def configs_per_second(self) -> float | None:
        return self.samples / self.elapsed_s if self.elapsed_s > 0 else None


@dataclass
class _Counted:
    """What the pybullet child sends back (plain data: it is pickled; lists, not numpy arrays, so that
    this process never imports numpy)."""

    links: list[str]
    pairs: list[tuple[int, int]]
    unsampled: set[int]
    unchecked: list[str]
    counts: list[int]
    checked: list[int]
    home_hits: set[int]
    limit_hits: dict[int, list[str]]
    limit_configurations: int
    dof: int
    elapsed_s: float
    jobs: int


def sample_matrix(model: Model, samples: int, seed: int, jobs: int | None, always_threshold: float,
                  meanwhile: Callable[[], None] | None = None) -> MatrixRun:
    """The self-collision matrix of ``model``; UserError when it has fewer than two links with
    collision geometry (the matrix would be empty). ``meanwhile()`` runs here while the pybullet
    child samples (the caller's report imports: off the critical path)."""
    from ar3cli.sim.adjacency import adjacent_pairs, collision_links, unloadable_collision_links
    from ar3cli.sim.session import run_pybullet

    if len(set(collision_links(model)) - set(unloadable_collision_links(model))) < 2:
        raise UserError(no_pairs_message(model))
    counted = run_pybullet(lambda: _count(model, samples, seed, jobs, always_threshold), model,
                           meanwhile=meanwhile)
    solid = [*counted.links, *counted.unchecked]  # an unchecked link keeps its place in the adjacency
    adjacent = adjacent_pairs(model, solid)
    results = cm.classify(counted.links, counted.pairs, counted.counts, samples, adjacent, counted.home_hits,
                          counted.limit_hits, always_threshold, counted.unsampled, counted.checked)
    warnings = [*_left_out_warnings(model, counted.unchecked), *cm.findings(model, results, solid, always_threshold)]
    return MatrixRun(links=counted.links, pairs=counted.pairs, results=results,
                     warnings=warnings, samples=samples,
                     seed=seed, jobs=counted.jobs, limit_configurations=counted.limit_configurations,
                     dof=counted.dof, elapsed_s=counted.elapsed_s, always_threshold=always_threshold,
                     unsampled=counted.unsampled, unchecked=counted.unchecked)


def _left_out_warnings(model: Model, unchecked: list[str]) -> list[Finding]:
    """One warning naming the links left out of the matrix (a collision mesh pybullet cannot load)."""
    from ar3cli.findings import Severity
    from ar3cli.sim.loadable_copy import left_out_summary, unloadable_shapes

    if not unchecked:
        return []
    left_out = unloadable_shapes(model, roles=("collision",))
    names = ", ".join(unchecked[:5]) + (f" and {len(unchecked) - 5} more" if len(unchecked) > 5 else "")
    return [Finding("collision-left-out", Severity.WARNING,
                    f"{left_out_summary(left_out)}: pybullet cannot load it, so the pairs of {names} are not in "
                    "the matrix: not checked, and none of them is disabled", str(model.path),
                    left_out[0].place.line if left_out and left_out[0].place else 0,
                    hint="fix the mesh path (lint-urdf reports it as G001) and run again")]


def _count(model: Model, samples: int, seed: int, jobs: int | None, always_threshold: float) -> _Counted:
    """In the pybullet child: home and limit configurations, then the uniform samples, timed; a pair
    stops being counted once its category is decided (:mod:`ar3cli.collisions.rounds`)."""
    # numpy is first imported here, in the child, single-threaded (cli.SINGLE_THREADED_BLAS)
    from ar3cli.collisions.checker import Checker
    from ar3cli.collisions.rounds import count_in_rounds
    from ar3cli.output.progress import progress_bar
    from ar3cli.sim.adjacency import adjacent_pairs
    from ar3cli.sim.sampling import limit_configurations, sample_configurations

    with Checker(model) as checker:
        space = checker.joint_space()
        home_hits: set[int] = set()
        limit_hits: dict[int, list[str]] = {}
        limits = limit_configurations(space)
        for label, q in limits:
            for pair_id in checker.colliding(q):
                if label == "home":
                    home_hits.add(pair_id)
                else:
                    limit_hits.setdefault(pair_id, []).append(label)
        adjacent = adjacent_pairs(model, [*checker.links, *checker.unchecked])
        adjacent_ids = {pair_id for pair_id, (i, j) in enumerate(checker.pairs)
                        if frozenset((checker.links[i], checker.links[j])) in adjacent}

        def settled(pair_id: int, collisions: int, checked: int) -> bool:
            return cm.settled(collisions, checked, samples, always_threshold, pair_id in adjacent_ids,
                              pair_id in home_hits)

        configs = sample_configurations(space, samples, seed)
        with progress_bar("sampling", samples) as advance:
            start = time.perf_counter()
            counts, checked, workers = count_in_rounds(checker, configs, settled, always_threshold, jobs,
                                                       progress=advance)
            elapsed = time.perf_counter() - start
        return _Counted(checker.links, checker.pairs, checker.unsampled, checker.unchecked, counts.tolist(),
                        checked.tolist(),
                        home_hits, limit_hits,
                        len(limits), space.dof, elapsed, workers)


def no_pairs_message(model: Model) -> str:
    """Why there is no matrix: which links lack <collision> geometry, and what to do."""
    from ar3cli.sim.adjacency import collision_links, unloadable_collision_links

    unloadable = unloadable_collision_links(model)
    solid = [link for link in collision_links(model) if link not in unloadable]
    if unloadable:
        return (f"{model.path}: {len(solid)} link(s) have <collision> geometry pybullet can load "
                f"(a mesh of {', '.join(unloadable[:4])}{', ...' if len(unloadable) > 4 else ''} cannot be loaded), "
                "so there is no pair to check; fix the mesh paths (see lint-urdf, G001)")
    visual_only = [link.name for link in model.links if link.visuals and link.name not in solid]
    if not solid:
        what = "no link has <collision> geometry"
    else:
        what = f"only one link ({solid[0]}) has <collision> geometry"
    if visual_only:
        what += f"; {len(visual_only)} link(s) have only <visual> ({', '.join(visual_only[:4])}" \
                f"{', ...' if len(visual_only) > 4 else ''}), which never collide"
    return (f"{model.path}: {what}, so there is no pair to check and the collision matrix would be empty; "
            "add <collision> elements (e.g. a copy of each <visual> geometry)")
