"""Shared helper for the benchmarks: time whole processes, round-robin, and print markdown tables.

Every benchmark in this folder compares commands a user would run (``ar3cli ...``) with the
alternative they would otherwise run, each as a **separate process**, so interpreter start-up,
imports, file reading, mesh loading and the work itself all count, as they do for the user.

How one comparison is measured (:func:`measure`):

* every variant runs once first as a warm-up (not counted: it fills the OS file cache and the
  bytecode cache, see below);
* then ``runs`` rounds, each running every variant once in the same order (A B A B ... or
  A B C A B C ...), so a machine that speeds up or slows down during the benchmark (other users,
  thermal limits) moves all variants alike;
* per run: wall time (``time.perf_counter`` around ``Popen`` + ``os.wait4``) and CPU time = user +
  sys of the child **and of every descendant it waited for** (``os.wait4``'s rusage), so the work
  done in ar3cli's forked pybullet child and in ``--jobs`` workers is counted;
* reported: the median wall and CPU time of each variant, and the ratio of each variant to the
  first one (the reference) computed **round by round** (variant / reference within one round),
  whose median is printed together with the per-round values.

Bytecode: ``PYTHONDONTWRITEBYTECODE`` is dropped for the children and ``PYTHONPYCACHEPREFIX``
points at a folder of this benchmark run, so the warm-up compiles every module once (as
``pip install`` does at install time) and no timed run pays for compiling, without writing
``__pycache__`` folders into the source tree. ``AR3CLI_CACHE_DIR`` points at a folder of this
run too (the user's ``~/.cache/ar3cli`` is never read or written); ``NO_COLOR=1``.

Not a benchmark itself: ``import _timing`` from the scripts beside it.
"""

from __future__ import annotations

import atexit
import datetime
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
WORK = Path(tempfile.mkdtemp(prefix="ar3cli-bench-"))
"""This benchmark run's private folder: bytecode cache, ar3cli cache, baseline scripts; removed at exit."""

BASE_ENV = {
    **{key: value for key, value in os.environ.items() if key not in ("PYTHONDONTWRITEBYTECODE", "COLUMNS")},
    "PYTHONPYCACHEPREFIX": str(WORK / "pycache"),
    "AR3CLI_CACHE_DIR": str(WORK / "ar3cli-cache"),
    "NO_COLOR": "1",
    # the ar3cli this checkout holds, whichever install the console script comes from (an editable install of
    # another worktree ran that one's code under this one's "source: commit" line)
    "PYTHONPATH": os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH", "")])),
}


def ar3cli_command() -> list[str]:
    """The ``ar3cli`` console script users run (the one beside this Python), else ``python -m ar3cli``."""
    beside = Path(sys.executable).parent / "ar3cli"
    if beside.exists():
        return [str(beside)]
    found = shutil.which("ar3cli")
    return [found] if found else [sys.executable, "-m", "ar3cli"]


def write_script(name: str, text: str) -> Path:
    """Write a baseline script into this run's folder; run it with ``[sys.executable, path, ...]``."""
    path = WORK / name
    path.write_text(text)
    return path


def cleanup() -> None:
    shutil.rmtree(WORK, ignore_errors=True)


atexit.register(cleanup)


# ---- one process ----------------------------------------------------------------------------------


@dataclass
class Run:
    wall: float
    cpu: float
    returncode: int
    stdout: str
    stderr: str


def run_once(command: Sequence[str], env: dict[str, str] | None = None, cwd: Path | None = None) -> Run:
    """Run ``command`` to completion: wall time, CPU time (user + sys of it and its reaped descendants)."""
    with tempfile.TemporaryFile(dir=WORK) as out, tempfile.TemporaryFile(dir=WORK) as err:
        start = time.perf_counter()
        process = subprocess.Popen(list(command), stdin=subprocess.DEVNULL, stdout=out, stderr=err,
                                   env=env or BASE_ENV, cwd=cwd or WORK)
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - start
        process.returncode = os.waitstatus_to_exitcode(status)  # already reaped: keep Popen from waiting again
        out.seek(0)
        err.seek(0)
        return Run(wall, usage.ru_utime + usage.ru_stime, process.returncode,
                   out.read().decode("utf-8", "replace"), err.read().decode("utf-8", "replace"))


# ---- comparisons ----------------------------------------------------------------------------------


@dataclass
class Variant:
    """One command in a comparison.

    ``command`` is a list, or a callable returning one (called before every run). ``prepare`` runs
    before every run and may return extra environment variables (e.g. a fresh, empty cache folder);
    ``check`` validates each run (raise to stop the benchmark: a failing command is not a timing).
    """

    name: str
    command: Sequence[str] | Callable[[], Sequence[str]]
    prepare: Callable[[], dict[str, str] | None] | None = None
    check: Callable[[Run], None] | None = None
    ok_codes: tuple[int, ...] = (0,)
    runs: list[Run] = field(default_factory=list)

    def run(self) -> Run:
        extra = self.prepare() if self.prepare else None
        env = {**BASE_ENV, **extra} if extra else BASE_ENV
        command = self.command() if callable(self.command) else self.command
        result = run_once(command, env)
        if result.returncode not in self.ok_codes:
            raise SystemExit(f"{self.name}: exit {result.returncode} (expected {self.ok_codes})\n"
                             f"command: {' '.join(map(str, command))[:500]}\n{result.stderr[-2000:]}")
        if self.check:
            self.check(result)
        return result

    @property
    def wall(self) -> float:
        return statistics.median(run.wall for run in self.runs)

    @property
    def cpu(self) -> float:
        return statistics.median(run.cpu for run in self.runs)


@dataclass
class Comparison:
    title: str
    variants: list[Variant]
    notes: list[str] = field(default_factory=list)

    def ratios(self, variant: Variant, attribute: str) -> list[float]:
        """variant / reference, round by round."""
        reference = self.variants[0]
        return [getattr(mine, attribute) / getattr(ref, attribute) if getattr(ref, attribute) > 0 else float("nan")
                for mine, ref in zip(variant.runs, reference.runs)]


def measure(title: str, variants: list[Variant], runs: int, warmup: bool = True,
            notes: Sequence[str] = ()) -> Comparison:
    """Warm up every variant once, then ``runs`` round-robin rounds; returns the filled Comparison."""
    if runs < 1:
        raise SystemExit("--runs must be at least 1")
    print(f"  measuring: {title} ({len(variants)} variants x {runs} runs{', after a warm-up' if warmup else ''})",
          file=sys.stderr, flush=True)
    if warmup:
        for variant in variants:
            variant.run()
    for _ in range(runs):
        for variant in variants:
            variant.runs.append(variant.run())
    return Comparison(title, variants, list(notes))


# ---- reporting ------------------------------------------------------------------------------------


def _per_round(values: list[float]) -> str:
    return " ".join(f"{value:.2f}" for value in values)


def table(comparison: Comparison) -> str:
    """A markdown table: medians per variant, and the round-by-round ratios to the first variant."""
    reference = comparison.variants[0]
    lines = [f"### {comparison.title}", "",
             f"{len(reference.runs)} runs each, alternating; median; ratio = variant / reference "
             "in the same round (median, then every round)", "",
             "| variant | wall s | CPU s | wall ratio | CPU ratio | wall ratio per round |",
             "|---|---:|---:|---:|---:|---|"]
    for variant in comparison.variants:
        if variant is reference:
            lines.append(f"| {variant.name} (reference) | {variant.wall:.3f} | {variant.cpu:.3f} | 1 | 1 | |")
            continue
        walls, cpus = comparison.ratios(variant, "wall"), comparison.ratios(variant, "cpu")
        lines.append(f"| {variant.name} | {variant.wall:.3f} | {variant.cpu:.3f} | {statistics.median(walls):.2f} "
                     f"| {statistics.median(cpus):.2f} | {_per_round(walls)} |")
    lines += [""] + [f"- {note}" for note in comparison.notes]
    return "\n".join(lines).rstrip() + "\n"


def load() -> str:
    one, five, fifteen = os.getloadavg()
    return f"{one:.2f} / {five:.2f} / {fifteen:.2f} (1 / 5 / 15 min)"


def machine_header(name: str) -> str:
    """Date, machine, core counts and load average: printed before the first measurement."""
    import importlib.metadata as metadata

    def version(package: str) -> str:
        try:
            return metadata.version(package)
        except metadata.PackageNotFoundError:
            return "not installed"

    affinity = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return (f"## {name}\n\n"
            f"- date: {datetime.datetime.now().astimezone().isoformat(timespec='seconds')}\n"
            f"- machine: {platform.machine()} {platform.system()} {platform.release()}, "
            f"os.cpu_count() = {os.cpu_count()}, usable cores (sched_getaffinity) = {affinity}\n"
            f"- Python {platform.python_version()}, pybullet {version('pybullet')}, ar3cli {version('ar3cli')}\n"
            f"- ar3cli command: `{' '.join(ar3cli_command())}`, source: {source_state()}\n"
            f"- load average at start: {load()}\n")


def source_state() -> str:
    """The commit of the ar3cli source tree timed, and whether ar3cli/ had uncommitted changes (read-only git)."""
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True,
                                timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "ar3cli"], cwd=REPO, capture_output=True,
                               text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown (no git)"
    if not commit:
        return "unknown (not a git checkout)"
    return f"commit {commit}" + (f" + uncommitted changes in {len(dirty.splitlines())} ar3cli file(s)" if dirty else "")


def machine_footer() -> str:
    return f"- load average at end: {load()}\n"


def usable_cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def pybullet_data_path() -> Path:
    import pybullet_data

    return Path(pybullet_data.getDataPath())
