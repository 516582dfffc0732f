"""Time ``ar3cli sample-collisions`` as a user runs it, against the plain pybullet scripts it replaces.

Whole processes, alternating (see ``benchmarks/_timing.py``): warm-up, then ``--runs`` rounds of

* A: ``ar3cli sample-collisions ROBOT --samples N --seed 3`` with its default ``--jobs`` (text output,
  as a user reads it), and the same with ``--format json`` (which reports its sampling-loop time and
  how many processes it used: the default depends on N and the machine's cores);
* B: the plain script: ``loadURDF(..., useFixedBase=True, flags=URDF_USE_SELF_COLLISION)`` (pybullet's
  *default* self-collision: parent-child pairs are NOT checked), N uniform configurations within the
  joint limits (numpy, seed 3), per configuration ``resetJointState`` for each movable joint +
  ``performCollisionDetection`` + ``getContactPoints(body, body)``, counting penetrating pairs;
* C: the seed tutorial's loop: the same with ``stepSimulation`` instead of ``performCollisionDetection``.

The baselines are written to a temporary file and run with this Python, one process. They do less
than ar3cli: ar3cli also checks the home pose and every joint at its limits (2 x DOF + 1 extra
configurations), classifies the pairs and prints the matrix; the notes say which pairs each side
sampled. Each script (and ar3cli's JSON) reports its own sampling-loop time, so the notes split
process time into start-up and loop. CPU time includes every process ar3cli forks.

After the timing, once (not timed): the **verdicts** of ar3cli's JSON against an independent all-pairs
check of the same configurations (``VERIFY`` below: plain ``loadURDF``, one ``getClosestPoints`` query
per configuration for every link pair, its own adjacency and classification); the notes say how many
pairs got the same category and how many sampled pairs got a different count.

Then the ``--jobs`` scaling rows: ``ar3cli sample-collisions ... --jobs 1`` vs ``--jobs 2`` (and
``--jobs 4`` when this machine has at least 4 usable cores) at ``--scaling-samples`` configurations.

Usage (inside the project's venv)::

    python benchmarks/bench_collisions.py                         # panda, 10,000 samples, 5 runs
    python benchmarks/bench_collisions.py --samples 1000 --runs 7
    python benchmarks/bench_collisions.py --scaling-only --scaling-samples 100000  # the issue's scaling claim
    python benchmarks/bench_collisions.py --robot ~/.cache/ar3cli-sweep/erd/cmeel.prefix/share/\
example-robot-data/robots/talos_data/robots/talos_reduced.urdf --samples 2000 --no-scaling

``--robot`` takes any URDF plain pybullet can load as well (its meshes found relative to the file
or by pybullet's own ``package://`` search, which finds example-robot-data's meshes); install
example-robot-data with ``pip install --no-deps --target ~/.cache/ar3cli-sweep/erd example-robot-data``
(~400 MB, as the real-robot sweep does). A large robot takes longer per configuration (talos_reduced:
1,326 link pairs, ~1 ms per configuration), hence the smaller ``--samples`` above.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _timing  # noqa: E402 - after the sys.path line that finds it

SEED = 3

BASELINE = r'''
"""Plain pybullet self-collision sampling (pybullet's default self-collision flags)."""
import json, math, sys, time
import numpy as np
import pybullet as p

path, samples, seed, mode = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
p.connect(p.DIRECT)
body = p.loadURDF(path, useFixedBase=True, flags=p.URDF_USE_SELF_COLLISION)
joints, low, high = [], [], []
for i in range(p.getNumJoints(body)):
    info = p.getJointInfo(body, i)
    if info[2] in (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC):
        lower, upper = info[8], info[9]
        if upper < lower:  # continuous / unlimited
            lower, upper = -math.pi, math.pi
        joints.append(i)
        low.append(lower)
        high.append(upper)
configs = np.random.default_rng(seed).uniform(low, high, size=(samples, len(joints))).tolist()
advance = p.stepSimulation if mode == "step" else p.performCollisionDetection
counts = {}
start = time.perf_counter()
for q in configs:
    for joint, value in zip(joints, q):
        p.resetJointState(body, joint, value)
    advance()
    for pair in {(c[3], c[4]) for c in p.getContactPoints(body, body) if c[8] < 0}:
        counts[pair] = counts.get(pair, 0) + 1
loop = time.perf_counter() - start
print(json.dumps({"samples": samples, "joints": len(joints), "pairs_in_contact": len(counts), "loop_s": loop}))
'''


VERIFY = r'''
"""Independent all-pairs check of a sample-collisions matrix (run once, not timed).

The configurations come from ar3cli's own sampler (the same seed gives the same rows: joint names,
mimic joints and limits as ar3cli reads them). Everything else is done here without ar3cli: the
URDF loaded by plain loadURDF with no self-collision flags, each configuration set with
resetJointState and tested with ONE getClosestPoints(body, body, 5 mm) query (one-shot, every link
pair, a link and its parent included, no contact manifolds), adjacency computed from pybullet's own
joint tree (MoveIt's rule: links without collision shapes are looked through), and each pair
classified adjacent > default > always > never > sometimes. Prints {"link_a|link_b": [category,
count]} as JSON.
"""
import json, sys
from pathlib import Path
import pybullet as p
from ar3cli.sim.sampling import joint_space, limit_configurations, sample_configurations
from ar3cli.sim.session import Session
from ar3cli.urdf.model import load_model

path, samples, seed, threshold = Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])
with Session() as session:
    space = joint_space(session.load(load_model(path)))
configs = sample_configurations(space, samples, seed)
limits = [q for label, q in limit_configurations(space) if label != "home"]

p.connect(p.DIRECT)
body = p.loadURDF(str(path), useFixedBase=True)
count = p.getNumJoints(body)
infos = [p.getJointInfo(body, i) for i in range(count)]
name = {-1: p.getBodyInfo(body)[0].decode(), **{i: info[12].decode() for i, info in enumerate(infos)}}
joint = {info[1].decode(): i for i, info in enumerate(infos)}
columns = [joint[n] for n in space.names]
solid = [i for i in range(-1, count) if p.getCollisionShapeData(body, i)]
neighbours = {i: set() for i in range(-1, count)}
for i, info in enumerate(infos):
    neighbours[i].add(info[16]); neighbours[info[16]].add(i)
adjacent = set()
for start in solid:
    seen, frontier = {start}, [start]
    while frontier:
        for other in neighbours[frontier.pop()] - seen:
            seen.add(other)
            if other in solid:
                adjacent.add(frozenset((start, other)))
            else:
                frontier.append(other)

def hits(q):
    for index, value in zip(columns, q):
        p.resetJointState(body, index, float(value))
    deepest = {}
    for point in p.getClosestPoints(body, body, 0.005):
        if point[3] != point[4]:
            key = frozenset((point[3], point[4]))
            deepest[key] = min(deepest.get(key, 1.0), point[8])
    return {key for key, depth in deepest.items() if depth < -1e-6}

home = hits(space.home)
at_limits = set().union(*(hits(q) for q in limits)) if limits else set()
counts = {}
for q in configs:
    for key in hits(q):
        counts[key] = counts.get(key, 0) + 1
result = {}
for k, a in enumerate(solid):
    for b in solid[k + 1:]:
        key = frozenset((a, b))
        n = counts.get(key, 0)
        if key in adjacent:
            category = "adjacent"
        elif key in home:
            category = "default"
        elif samples and n / samples >= threshold:
            category = "always"
        elif n == 0 and key not in at_limits:
            category = "never"
        else:
            category = "sometimes"
        result["|".join(sorted((name[a], name[b])))] = [category, n]
print(json.dumps(result))
'''


def verdicts(robot: Path, samples: int, document: dict) -> str:
    """Compare ar3cli's categories (its JSON) with :data:`VERIFY`'s independent all-pairs check."""
    import subprocess
    import time

    script = _timing.write_script("verify_matrix.py", VERIFY)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, str(script), str(robot), str(samples), str(SEED),
                           str(document.get("always_threshold", 0.95))], capture_output=True, text=True)
    if done.returncode != 0:
        return f"independent all-pairs check failed: {done.stderr.strip()[-500:]}"
    theirs = json.loads(done.stdout.strip().splitlines()[-1])
    ours = {"|".join(sorted((pair["link_a"], pair["link_b"]))): pair for pair in document["pairs"]}
    def said(key: str) -> str:
        return f"{ours[key]['category']} ({ours[key]['collisions']})" if key in ours else "absent"

    differing = [f"{key}: ar3cli {said(key)}, independent {theirs[key][0]} ({theirs[key][1]})"
                 for key in sorted(theirs) if key not in ours or ours[key]["category"] != theirs[key][0]]
    # a pair retired once its category was decided was counted over its first `samples` configurations only
    complete = {key: pair for key, pair in ours.items() if pair.get("sampled", True)
                and pair.get("samples", samples) == samples}
    count_differs = sum(1 for key, pair in complete.items() if key in theirs and pair["collisions"] != theirs[key][1])
    same = len(theirs) - len(differing)
    VERDICTS.append((robot.name, samples, same, len(theirs)))
    return (f"**verdicts: {same} of {len(theirs)} pairs in the same category** as an independent all-pairs check "
            f"(same {samples} configurations, one getClosestPoints query each, own adjacency; "
            f"{time.perf_counter() - start:.0f} s); pairs counted over all {samples} samples whose count differs: "
            f"{count_differs} of {len(complete)} (the other sampled pairs were retired once their category was "
            f"decided)" + (f"; differing: {'; '.join(differing[:5])}" if differing else ""))


VERDICTS: list[tuple[str, int, int, int]] = []
"""(robot, samples, pairs in the same category, pairs) of every verdict check, for the summary."""
RATIOS: list[tuple[str, int, int, float, list[float]]] = []
"""(robot, samples, runs, median plain / ar3cli wall ratio, the per-round ratios), for the summary."""

class Parsed:
    """Keeps the JSON each run of a variant printed (last line of stdout), for the notes."""

    def __init__(self, samples: int) -> None:
        self.samples = samples
        self.documents: list[dict] = []

    def __call__(self, run: _timing.Run) -> None:
        lines = [line for line in run.stdout.splitlines() if line.strip()]
        try:
            document = json.loads(run.stdout) if run.stdout.lstrip().startswith("{") else json.loads(lines[-1])
        except (ValueError, IndexError):
            raise SystemExit(f"no JSON on stdout:\n{run.stdout[-1000:]}\n{run.stderr[-1000:]}") from None
        if document.get("samples") != self.samples:
            raise SystemExit(f"expected {self.samples} samples, the run reports {document.get('samples')}")
        self.documents.append(document)

    def loop_seconds(self, key: str) -> float:
        # the warm-up's document is the first one; medians over the timed runs only
        return statistics.median(document[key] for document in self.documents[1:] or self.documents)


def note_loop(name: str, variant: _timing.Variant, parsed: Parsed, key: str) -> str:
    loop = parsed.loop_seconds(key)
    return (f"{name}: sampling loop {loop:.3f} s wall as the process timed it ({loop / parsed.samples * 1e6:.0f} us "
            f"per configuration), the rest of the process {variant.wall - loop:.3f} s (start-up, loading, "
            f"reporting: median process wall minus median loop)")


def describe(document: dict) -> str:
    """What ar3cli's JSON says it did: processes, pairs sampled, extra configurations."""
    pairs = document.get("pairs", [])
    sampled = [pair for pair in pairs if pair.get("sampled", True)]
    retired = [pair for pair in sampled if pair.get("retired")]
    return (f"ar3cli (its JSON): {document.get('jobs', '?')} process(es), {len(sampled)} of {len(pairs)} link "
            f"pairs sampled (the others are a link and its direct parent, not checked), {len(retired)} of them "
            f"retired before the last sample once their category was decided, plus "
            f"{document.get('limit_configurations', '?')} home/limit configurations")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", type=Path, action="append",
                        help="URDF to sample, repeatable (default: pybullet_data's franka_panda/panda.urdf)")
    parser.add_argument("--samples", type=int, nargs="+", default=[10_000],
                        help="configurations per run, one or more counts (default 10,000)")
    parser.add_argument("--runs", type=int, default=5, help="timed runs of each variant (default 5)")
    parser.add_argument("--large-runs", type=int,
                        help="timed runs at 100,000 samples or more (default: --runs; say so when fewer)")
    parser.add_argument("--no-tutorial", action="store_true", help="skip the (slowest) tutorial-loop variant")
    parser.add_argument("--no-verdicts", action="store_true",
                        help="skip the independent all-pairs check (slow: minutes for a humanoid at 10,000)")
    parser.add_argument("--scaling-samples", type=int, default=10_000,
                        help="configurations for the --jobs rows (default 10,000; the issue's claim: 100,000)")
    parser.add_argument("--no-scaling", action="store_true", help="skip the --jobs rows")
    parser.add_argument("--scaling-only", action="store_true", help="only the --jobs rows")
    args = parser.parse_args()

    robots = [robot.expanduser().resolve() for robot in args.robot or
              [_timing.pybullet_data_path() / "franka_panda" / "panda.urdf"]]
    for robot in robots:
        if not robot.is_file():
            raise SystemExit(f"{robot}: no such file")
    ar3cli = _timing.ar3cli_command()
    script = _timing.write_script("plain_self_collision.py", BASELINE)
    print(_timing.machine_header(f"sample-collisions: {', '.join(robot.name for robot in robots)}"))
    try:
        for robot in robots:
            if not args.scaling_only:
                for samples in args.samples:
                    runs = args.large_runs if samples >= 100_000 and args.large_runs else args.runs
                    compare_with_plain(ar3cli, robot, script, samples, runs, not args.no_tutorial,
                                       not args.no_verdicts)
            if not args.no_scaling:
                scaling(ar3cli, robot, args.scaling_samples, args.runs)
        print_summary()
        print(_timing.machine_footer())
    finally:
        _timing.cleanup()


def print_summary() -> None:
    """One line per robot and sample count: the plain script's wall time over ar3cli's, and the verdicts."""
    if not RATIOS:
        return
    print("#### Summary: plain script wall time / ar3cli wall time (whole processes, medians)\n")
    print("| robot | samples | runs | plain / ar3cli | per round | verdicts (same category) |")
    print("|---|---:|---:|---:|---|---|")
    checked = {(robot, samples): f"{same} of {total}" for robot, samples, same, total in VERDICTS}
    for robot, samples, runs, ratio, rounds in RATIOS:
        print(f"| {robot} | {samples} | {runs} | **{ratio:.2f}x** | {' '.join(f'{r:.2f}' for r in rounds)} | "
              f"{checked.get((robot, samples), 'not checked')} |")
    print()


def compare_with_plain(ar3cli: list[str], robot: Path, script: Path, samples: int, runs: int,
                       tutorial_loop: bool = True, check_verdicts: bool = True) -> None:
    """ar3cli (text, json) vs the plain script (vs the tutorial loop), one process each."""
    ours, plain, tutorial = Parsed(samples), Parsed(samples), Parsed(samples)
    command = [*ar3cli, "sample-collisions", str(robot), "--samples", str(samples), "--seed", str(SEED)]
    baseline = [sys.executable, str(script), str(robot), str(samples), str(SEED)]
    variants = [
        _timing.Variant(f"`ar3cli sample-collisions {robot.name} --samples {samples} --seed {SEED}`", command),
        _timing.Variant("the same, `--format json`", [*command, "--format", "json"], check=ours),
        _timing.Variant("plain script: resetJointState + performCollisionDetection + getContactPoints",
                        [*baseline, "detect"], check=plain),
    ]
    if tutorial_loop:
        variants.append(_timing.Variant("tutorial loop: resetJointState + stepSimulation + getContactPoints",
                                        [*baseline, "step"], check=tutorial))
    comparison = _timing.measure(f"{robot.name}, {samples} configurations, one process each", variants, runs)
    comparison.notes += [
        note_loop("ar3cli (json)", variants[1], ours, "elapsed_s"),
        note_loop("plain script", variants[2], plain, "loop_s"),
        *([note_loop("tutorial loop", variants[3], tutorial, "loop_s")] if tutorial_loop else []),
        describe(ours.documents[-1]),
        verdicts(robot, samples, ours.documents[-1]) if check_verdicts else "verdicts: not checked (--no-verdicts)",
        f"the plain script loads with pybullet's default self-collision (URDF_USE_SELF_COLLISION: a link "
        f"and its direct parent are never checked) and found {plain.documents[-1]['pairs_in_contact']} "
        f"pairs in contact at least once",
    ]
    rounds = comparison.ratios(variants[2], "wall")  # plain script / ar3cli (the reference), round by round
    ratio = statistics.median(rounds)
    RATIOS.append((robot.name, samples, runs, ratio, rounds))
    print(_timing.table(comparison))
    print(f"RATIO {robot.name} {samples} samples: plain script / ar3cli = {ratio:.2f}x wall "
          f"(rounds {min(rounds):.2f}-{max(rounds):.2f}, {runs} runs)\n", flush=True)


def scaling(ar3cli: list[str], robot: Path, samples: int, runs: int) -> None:
    """``--jobs 1`` vs ``--jobs 2`` (and 4 on a machine with 4 usable cores)."""
    job_counts = [1, 2] + ([4] if _timing.usable_cores() >= 4 else [])
    scaled = {jobs: Parsed(samples) for jobs in job_counts}
    variants = [_timing.Variant(f"`--jobs {jobs}`",
                                [*ar3cli, "sample-collisions", str(robot), "--samples", str(samples), "--seed",
                                 str(SEED), "--jobs", str(jobs), "--format", "json"], check=scaled[jobs])
                for jobs in job_counts]
    comparison = _timing.measure(f"`ar3cli sample-collisions {robot.name} --samples {samples}`: --jobs scaling",
                                 variants, runs)
    comparison.notes += [note_loop(f"--jobs {jobs}", variant, scaled[jobs], "elapsed_s")
                         for jobs, variant in zip(job_counts, variants)]
    if _timing.usable_cores() < 4:
        comparison.notes.append(f"--jobs 4 not run: {_timing.usable_cores()} usable cores")
    print(_timing.table(comparison))


if __name__ == "__main__":
    main()
