"""Run every ar3cli command on every real robot description and tabulate how each run ended.

Robots come from two public collections:

* example-robot-data (69 URDF + 2 xacro: UR, Panda, Talos, Solo, ANYmal, iCub, PR2, ...), installed
  once with ``pip install --no-deps --target <cache> example-robot-data`` (~400 MB) into
  ``~/.cache/ar3cli-sweep/erd`` (``--cache DIR``); an existing install is reused, pip is skipped.
  Its meshes are ``package://example-robot-data/...``: ar3cli finds that package by itself (the
  ancestor folder ``share/example-robot-data`` holds its package.xml), so no --package-path is given.
* pybullet_data, every ``*.urdf`` in it recursively (95 models) except the 1000 procedurally
  generated ``random_urdfs/`` objects (``--include-random`` adds them).

Each command runs as its own ``ar3cli`` subprocess with ``--format json``, its own empty TMPDIR and
working folder, a per-run timeout, and never on a writable robot file: the fixers only get --diff,
render writes its PNG into the run's folder, and the source trees are compared before and after.
``install-check`` runs once. lint-urdf gets --no-cache --no-config (every file really checked, the
sweep's working folder's pyproject.toml never applies), and every run gets AR3CLI_CACHE_DIR in the
sweep's own temporary folder (your ~/.cache/ar3cli is not touched). Every run is classified:

clean           exit 0 or 1, stdout is JSON without NaN/Infinity, and the command-specific checks hold
user error      exit 2 with a short stderr message and no traceback (expected for bad input)
crash           killed by a signal (SIGSEGV, SIGABRT, ...)
internal error  exit 3, a traceback, exit 2 with no or a long message or one naming an internal error
                (a rule that failed on one file), invalid JSON, NaN/Infinity in
                JSON, or any other exit code
silent wrong    looks clean but is not: render wrote a PNG with no robot in it (or none at all),
                fk-verify's JSON holds NaN or contradicts its exit code, lint's exit code
                contradicts its findings, a --diff fixer reports a write; and (second looks, issue 30)
                a fixer that changes values yet leaves lint findings of its own rules (it is run again
                with --output into a folder of symlinks to the robot's, and lint-urdf compares the
                original and the fixed copy; what the fixer lists as skipped is excused), a line number
                that does not hold what the message names (a finding's line must hold, or be inside
                the <link>/<joint> that holds, the link/joint/mesh it names; a FILE:LINE quoted in a
                load error or a P001 message must be a line of the user's file), fk-verify calling
                FAIL an error below float32 precision at the robot's reach (eps32 x the sum of joint
                offsets and prismatic travels)
timeout         still running after --timeout seconds (the process group is killed)

Runs that leave anything in their TMPDIR are counted separately ("leftover temp").

Usage (inside the project's venv)::

    python benchmarks/sweep_real_robots.py                       # everything, 2 jobs
    python benchmarks/sweep_real_robots.py --commands lint-urdf,fix-inertia,fix-continuous
    python benchmarks/sweep_real_robots.py --source erd --match ur5 --json runs.json
    python benchmarks/sweep_real_robots.py --help

From a plain install (what a user gets; PYTHONPATH is dropped for the runs)::

    python3 -m venv /tmp/plain && /tmp/plain/bin/pip install .
    python benchmarks/sweep_real_robots.py --ar3cli /tmp/plain/bin/ar3cli

Commands (``--commands``): lint-urdf, lint-urdf-sim, lint-urdf-mujoco, cross-check, render,
sample-collisions, fk-verify, fix-inertia, fix-continuous, fix-joints, fix-mesh-paths, fix-collision,
diff (each file against itself: any change is silently wrong), report (an HTML page that loads nothing),
info (with --torques), install-check.

Time on 2 cores with --jobs 2: the static commands (lint-urdf, fix-inertia, fix-continuous) on the
166 files take under 3 minutes (ar3cli's mesh cache starts empty in every sweep). The simulating
ones dominate a full sweep: 1-5 s per run on arms such as the UR5 and Panda, more on the large
humanoids; all 11 commands on the 166 files took 495 s (2 jobs, 2 cores shared with a test run).
The first run downloads example-robot-data (~400 MB).

Exit status: 0 when no run failed (crash, internal error, silent wrong, timeout) and no robot
file changed, 1 otherwise, 2 on a usage error.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

from PIL import Image, ImageChops

DEFAULT_CACHE = Path("~/.cache/ar3cli-sweep/erd").expanduser()
ERD_SHARE = Path("cmeel.prefix/share/example-robot-data")
CLASSES = ("clean", "user error", "crash", "internal error", "silent wrong", "timeout")
FAILURES = ("crash", "internal error", "silent wrong", "timeout")
MIN_ROBOT_PIXELS = 100
"""A render with fewer pixels unlike the background than this shows no robot (800x600 = 480000 px)."""
PIXEL_TOLERANCE = 8
"""Largest per-channel difference (0-255) at which a pixel still counts as background."""
SHORT_STDERR_LINES = 3
"""An exit-2 message longer than this many non-blank lines is not the promised one-line error."""


# --------------------------------------------------------------------------------------------
# Robots


@dataclass(frozen=True)
class Robot:
    """One robot description file and the collection it belongs to."""

    source: str
    root: Path
    path: Path

    @property
    def rel(self) -> str:
        return self.path.relative_to(self.root).as_posix()

    @property
    def label(self) -> str:
        return f"{self.source}:{self.rel}"


def ensure_erd(cache: Path) -> Path:
    """example-robot-data's robots folder under ``cache``, installed with pip when missing."""
    robots = cache / ERD_SHARE / "robots"
    if (cache / ERD_SHARE / "package.xml").is_file() and robots.is_dir():
        return robots
    cache.mkdir(parents=True, exist_ok=True)
    print(f"installing example-robot-data into {cache} (~400 MB)...", file=sys.stderr)
    pip = [sys.executable, "-m", "pip", "install", "--no-deps", "--target", str(cache), "example-robot-data"]
    if subprocess.run(pip, stdout=sys.stderr).returncode != 0:
        raise SystemExit(f"could not install example-robot-data: {' '.join(pip)} failed")
    if not robots.is_dir():
        raise SystemExit(f"pip installed example-robot-data but {robots} is missing")
    return robots


def pybullet_data_root() -> Path:
    import pybullet_data  # imported late: only needed for that source

    return Path(pybullet_data.getDataPath())


def find_robots(source: str, root: Path, include_random: bool) -> list[Robot]:
    """Every .urdf (and .xacro) under ``root``, sorted."""
    paths = [*root.rglob("*.urdf"), *root.rglob("*.xacro")]
    if not include_random:
        paths = [p for p in paths if "random_urdfs" not in p.relative_to(root).parts]
    return [Robot(source, root, p) for p in sorted(paths)]


def select_robots(args: argparse.Namespace) -> list[Robot]:
    robots: list[Robot] = []
    if args.source in ("erd", "all"):
        robots += find_robots("erd", ensure_erd(args.cache), args.include_random)
    if args.source in ("pybullet_data", "all"):
        robots += find_robots("pybullet_data", pybullet_data_root(), args.include_random)
    if args.match:
        robots = [r for r in robots if args.match.lower() in r.rel.lower()]
    return robots[:args.limit] if args.limit else robots


def snapshot(roots: Iterable[Path]) -> dict[str, tuple[int, int]]:
    """(size, mtime_ns) of every file under ``roots``: compared after the sweep to prove nothing wrote."""
    state: dict[str, tuple[int, int]] = {}
    for root in roots:
        for path in root.rglob("*"):
            if path.is_file():
                info = path.stat()
                state[str(path)] = (info.st_size, info.st_mtime_ns)
    return state


def snapshot_changes(before: dict[str, tuple[int, int]], after: dict[str, tuple[int, int]]) -> list[str]:
    changes = [f"added {p}" for p in sorted(after.keys() - before.keys())]
    changes += [f"removed {p}" for p in sorted(before.keys() - after.keys())]
    changes += [f"modified {p}" for p in sorted(before.keys() & after.keys()) if before[p] != after[p]]
    return changes


# --------------------------------------------------------------------------------------------
# Commands


@dataclass(frozen=True)
class Command:
    """How to run one ar3cli command: ``args(file, run_dir)`` is its argument list (file is "" for install-check)."""

    key: str
    label: str
    args: Callable[[str, Path], list[str]]
    per_file: bool = True


COMMANDS: tuple[Command, ...] = (
    Command("lint-urdf", "lint-urdf",
            lambda f, d: ["lint-urdf", f, "--no-cache", "--no-config", "--format", "json"]),
    Command("lint-urdf-sim", "lint-urdf --sim",
            lambda f, d: ["lint-urdf", "--sim", f, "--no-cache", "--no-config", "--format", "json"]),
    Command("lint-urdf-mujoco", "lint-urdf --sim --engine mujoco",
            lambda f, d: ["lint-urdf", "--sim", "--engine", "mujoco", f, "--no-cache", "--no-config", "--format", "json"]),
    Command("cross-check", "cross-check",
            lambda f, d: ["cross-check", f, "--samples", "5", "--seed", "1", "--format", "json"]),
    Command("render", "render",
            lambda f, d: ["render", f, "-o", str(d / "render.png"), "--format", "json"]),
    Command("sample-collisions", "sample-collisions",
            lambda f, d: ["sample-collisions", f, "--samples", "50", "--seed", "1", "--format", "json"]),
    Command("fk-verify", "fk-verify",
            lambda f, d: ["fk-verify", f, "--samples", "20", "--seed", "1", "--format", "json"]),
    Command("fix-inertia", "fix-inertia",
            lambda f, d: ["fix-inertia", f, "--diff", "--density", "1000", "--format", "json"]),
    Command("fix-continuous", "fix-continuous",
            lambda f, d: ["fix-continuous", f, "--diff", "--format", "json"]),
    Command("fix-joints", "fix-joints",
            lambda f, d: ["fix-joints", f, "--diff", "--format", "json"]),
    Command("fix-mesh-paths", "fix-mesh-paths",
            lambda f, d: ["fix-mesh-paths", f, "--diff", "--package", collection_package(f), "--format", "json"]),
    Command("fix-collision", "fix-collision",
            lambda f, d: ["fix-collision", f, "--diff", "--method", "vhacd", "--resolution", "20000",
                          "--format", "json"]),
    Command("diff", "diff (a file against itself)",
            lambda f, d: ["diff", f, f, "--samples", "5", "--seed", "1", "--format", "json"]),
    Command("report", "report",
            lambda f, d: ["report", f, "-o", str(d / "report.html"), "--samples", "20", "--seed", "1", "--format", "json"]),
    Command("info", "info --torques",
            lambda f, d: ["info", f, "--torques", "--samples", "20", "--format", "json"]),
    Command("install-check", "install-check", lambda f, d: ["install-check", "--format", "json"],
            per_file=False),
)


def collection_package(robot_file: str) -> str:
    """``--package NAME=DIR`` for fix-mesh-paths: the collection the file belongs to, as one package
    (example-robot-data's share folder, or pybullet_data's)."""
    path = Path(robot_file)
    for parent in path.parents:
        if parent.name in ("example-robot-data", "pybullet_data"):
            return f"{parent.name}={parent}"
    return f"robot={path.parent}"


def pick_commands(spec: str | None) -> list[Command]:
    if not spec:
        return list(COMMANDS)
    by_key = {c.key: c for c in COMMANDS}
    wanted = [s.strip() for s in spec.split(",") if s.strip()]
    unknown = [w for w in wanted if w not in by_key]
    if unknown:
        raise ValueError(f"unknown command(s) {', '.join(unknown)}; choose from {', '.join(by_key)}")
    return [c for c in COMMANDS if c.key in wanted]


def find_ar3cli(explicit: str | None) -> str:
    if explicit:
        return explicit
    beside = Path(sys.executable).parent / "ar3cli"
    found = shutil.which("ar3cli") or (str(beside) if beside.exists() else None)
    if not found:
        raise SystemExit("ar3cli not found: activate the project's venv or pass --ar3cli PATH")
    return found


# --------------------------------------------------------------------------------------------
# Running


@dataclass
class Outcome:
    """What one subprocess did."""

    returncode: int | None
    stdout: str
    stderr: str
    seconds: float
    timed_out: bool
    leftover: list[str]


@dataclass
class RunRecord:
    """One run, as written by --json."""

    command: str
    source: str
    file: str
    argv: list[str]
    returncode: int | None
    seconds: float
    outcome: str
    reason: str
    stderr_first_line: str
    leftover_temp: list[str] = field(default_factory=list)


class Runner:
    """Runs ar3cli subprocesses, each in its own folder; kills what is still running on interrupt."""

    def __init__(self, ar3cli: str, sweep_dir: Path, timeout: float, plain: bool = False) -> None:
        self.ar3cli = ar3cli
        self.sweep_dir = sweep_dir
        self.timeout = timeout
        self.env = {**os.environ, "AR3CLI_CACHE_DIR": str(sweep_dir / "ar3cli-cache")}
        self.env.pop("AR3CLI_DEBUG", None)  # tracebacks only where ar3cli prints them by itself
        if plain:  # --ar3cli of another venv: its own installed code, not a checkout's sources
            self.env.pop("PYTHONPATH", None)
        self._lock = threading.Lock()
        self._count = 0
        self._running: set[subprocess.Popen[bytes]] = set()
        self._stopped = False

    def new_run_dir(self) -> Path:
        with self._lock:
            self._count += 1
            run_dir = self.sweep_dir / f"run{self._count:05d}"
        (run_dir / "tmp").mkdir(parents=True)
        return run_dir

    def run(self, argv: list[str], run_dir: Path) -> Outcome:
        tmp = run_dir / "tmp"
        env = {**self.env, "TMPDIR": str(tmp), "TMP": str(tmp), "TEMP": str(tmp)}
        start = time.perf_counter()
        proc = subprocess.Popen([self.ar3cli, *argv], cwd=run_dir, env=env, stdin=subprocess.DEVNULL,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
        with self._lock:
            self._running.add(proc)
            if self._stopped:  # interrupted while this one was starting
                kill_group(proc)
        timed_out = False
        try:
            out, err = proc.communicate(timeout=self.timeout)
        except subprocess.TimeoutExpired:
            timed_out = True
            kill_group(proc)
            out, err = proc.communicate()
        finally:
            with self._lock:
                self._running.discard(proc)
        seconds = time.perf_counter() - start
        leftover = sorted(p.name for p in tmp.iterdir())
        return Outcome(proc.returncode, out.decode("utf-8", "replace"), err.decode("utf-8", "replace"),
                       seconds, timed_out, leftover)

    def kill_all(self) -> None:
        with self._lock:
            self._stopped = True
            running = list(self._running)
        for proc in running:
            kill_group(proc)


def kill_group(proc: subprocess.Popen[bytes]) -> None:
    """SIGKILL the process group ``proc`` leads (ar3cli's worker processes included)."""
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(proc.pid, signal.SIGKILL)


# --------------------------------------------------------------------------------------------
# Classification


class NonFinite(ValueError):
    """JSON held NaN or +-Infinity."""


def _reject_constant(token: str) -> float:
    raise NonFinite(token)


def parse_json(text: str) -> tuple[object | None, str]:
    """The document and '' when ``text`` is strict JSON, else None and what is wrong with it."""
    try:
        return json.loads(text, parse_constant=_reject_constant), ""
    except NonFinite as exc:
        return None, f"{exc} in JSON"
    except json.JSONDecodeError as exc:
        return None, f"invalid JSON on stdout ({exc.msg}, {len(text)} chars)"


def first_line(text: str) -> str:
    return next((line.strip() for line in text.splitlines() if line.strip()), "")


def signal_name(returncode: int) -> str:
    try:
        return signal.Signals(-returncode).name
    except ValueError:
        return f"signal {-returncode}"


def classify(command: Command, outcome: Outcome, run_dir: Path) -> tuple[str, str]:
    """The run's class and a short reason (empty for clean runs)."""
    rc = outcome.returncode
    if outcome.timed_out:
        return "timeout", f"killed after {outcome.seconds:.0f} s"
    assert rc is not None
    if rc < 0:
        return "crash", f"killed by {signal_name(rc)}"
    if "Traceback" in outcome.stderr:
        return "internal error", f"exit {rc} with a traceback"
    if rc == 2:
        lines = [line for line in outcome.stderr.splitlines() if line.strip()]
        if any("internal error" in line for line in lines):  # a rule's bug on one file: the batch went on
            return "internal error", "exit 2 naming an internal error"
        if not lines:
            return "internal error", "exit 2 with no message"
        if len(lines) > SHORT_STDERR_LINES:
            return "internal error", f"exit 2 with a {len(lines)}-line message"
        return "user error", ""
    if rc not in (0, 1):
        return "internal error", f"exit {rc}"
    document, problem = parse_json(outcome.stdout)
    if problem:
        if command.key == "fk-verify" and problem.endswith("in JSON"):
            return "silent wrong", problem
        return "internal error", problem
    problem = CHECKS.get(command.key, _no_check)(document, rc, run_dir)
    return ("silent wrong", problem) if problem else ("clean", "")


def _no_check(document: object, rc: int, run_dir: Path) -> str:
    return ""


def check_render(document: object, rc: int, run_dir: Path) -> str:
    """A PNG must exist and show something besides the background."""
    png = run_dir / "render.png"
    if not png.is_file():
        return f"exit {rc} but no PNG written"
    try:
        with Image.open(png) as image:
            rgb = image.convert("RGB")
    except OSError as exc:
        return f"unreadable PNG ({exc})"
    robot = robot_pixels(rgb)
    if robot < MIN_ROBOT_PIXELS:
        return f"PNG shows no robot ({robot} of {rgb.width * rgb.height} pixels differ from the background)"
    return ""


def robot_pixels(image: Image.Image) -> int:
    """Pixels that differ from the background (the most common colour of the image's border)."""
    width, height = image.size
    pixels = image.load()
    border = [pixels[x, y] for x in range(width) for y in (0, height - 1)]
    border += [pixels[x, y] for y in range(height) for x in (0, width - 1)]
    background = Counter(border).most_common(1)[0][0]
    red, green, blue = ImageChops.difference(image, Image.new("RGB", image.size, background)).split()
    largest = ImageChops.lighter(ImageChops.lighter(red, green), blue)
    return sum(largest.histogram()[PIXEL_TOLERANCE + 1:])


def check_fk(document: object, rc: int, run_dir: Path) -> str:
    """'passed' must agree with the exit code and with the errors against the tolerances."""
    if not isinstance(document, dict) or "passed" not in document:
        return "no 'passed' in the JSON"
    passed = document["passed"]
    if passed != (rc == 0):
        return f"exit {rc} but passed={passed}"
    worst_m = document.get("max_position_error_m")
    worst_rad = document.get("max_orientation_error_rad")
    numbers = isinstance(worst_m, (int, float)) and isinstance(worst_rad, (int, float))
    if passed and numbers and (worst_m > document.get("tolerance_m", 0) or worst_rad > document.get("tolerance_rad", 0)):
        return f"passed with errors {worst_m:.3g} m / {worst_rad:.3g} rad above the tolerances"
    return ""


def check_lint(document: object, rc: int, run_dir: Path) -> str:
    """Exit 1 exactly when there is an error finding (fail-on error, no config)."""
    if not isinstance(document, dict) or not isinstance(document.get("findings"), list):
        return "no 'findings' list in the JSON"
    errors = sum(1 for f in document["findings"] if isinstance(f, dict) and f.get("severity") == "error")
    if (errors > 0) != (rc == 1):
        return f"exit {rc} with {errors} error finding(s)"
    return ""


def check_fix(document: object, rc: int, run_dir: Path) -> str:
    """With --diff nothing may be written."""
    if not isinstance(document, dict) or not isinstance(document.get("files"), list):
        return "no 'files' list in the JSON"
    written = [f.get("written") for f in document["files"] if isinstance(f, dict) and f.get("written")]
    return f"--diff run reports a write to {written[0]}" if written else ""


def check_diff(document: object, rc: int, run_dir: Path) -> str:
    """A file compared with itself has no semantic change: exit 0 and ``changed`` false."""
    if not isinstance(document, dict) or "changed" not in document:
        return "no 'changed' in the JSON"
    return f"a file differs from itself (exit {rc}, changed={document['changed']})" if rc or document["changed"] else ""


def check_report(document: object, rc: int, run_dir: Path) -> str:
    """An HTML page was written, of the size the JSON says, and it loads nothing from the network."""
    page = run_dir / "report.html"
    if not page.is_file():
        return f"exit {rc} but no page written"
    data = page.read_bytes()
    if not data.startswith(b"<!DOCTYPE html>"):
        return "the page is not HTML"
    if isinstance(document, dict) and document.get("bytes") != len(data):
        return f"the JSON says {document.get('bytes')} bytes, the page has {len(data)}"
    if re.search(rb"""(?:src|href)\s*=\s*["']?https?:""", data):
        return "the page loads something from the network"
    return ""


CHECKS: dict[str, Callable[[object, int, Path], str]] = {
    "diff": check_diff,
    "report": check_report,
    "render": check_render,
    "fk-verify": check_fk,
    "lint-urdf": check_lint,
    "lint-urdf-sim": check_lint,
    "lint-urdf-mujoco": check_lint,
    "fix-inertia": check_fix,
    "fix-continuous": check_fix,
    "fix-joints": check_fix,
    "fix-mesh-paths": check_fix,
    "fix-collision": check_fix,
}


# --------------------------------------------------------------------------------------------
# Second looks: answers that sound sure and are wrong (issue 30)

FLOAT32_EPS = 1.1920929e-07
FIXERS = ("fix-inertia", "fix-continuous", "fix-joints", "fix-mesh-paths", "fix-collision")
NAMED = re.compile(r"\b(?P<kind>link|joint|mesh|parent|child|extension)\s+'(?P<name>[^'$]+)'")
"""A thing a message names: ``link 'base'``, ``joint 'j1'``, ``mesh 'x.stl'``, ``extension '.ply'`` (xacro
``${...}`` names skipped). Links and joints are matched as quoted attribute values, the rest as text."""
LOOKED = Counter()
"""How many things each second look examined (for the report: a signal that never looked proves nothing)."""
_LOOKED_LOCK = threading.Lock()


def looked(what: str) -> None:
    with _LOOKED_LOCK:
        LOOKED[what] += 1


QUOTED_LINE = re.compile(r"(?P<file>[^\s:'\"]+\.(?:urdf|URDF|xacro)):(?P<line>\d+):(?P<rest>[^\n]*)")
"""A ``FILE:LINE:`` a message quotes (a load error, a P001 finding): it must be a line of the user's file."""


def second_look(runner: Runner, command: Command, path: Path, outcome: Outcome, run_dir: Path) -> str:
    """The silent-wrong signals a run's own checks cannot see; '' when none."""
    document, _ = parse_json(outcome.stdout)
    if command.key in ("lint-urdf", "lint-urdf-sim") and isinstance(document, dict):
        for finding in document.get("findings") or []:
            if isinstance(finding, dict) and not QUOTED_LINE.search(str(finding.get("message", ""))):
                if NAMED.search(str(finding.get("message", ""))) and finding.get("line"):
                    looked("finding lines checked against the name they quote")
                problem = line_problem(finding.get("path"), finding.get("line"), str(finding.get("message", "")))
                if problem:
                    return f"{finding.get('rule')}: {problem}"
    texts = [outcome.stderr] if outcome.returncode == 2 else []
    if command.key in ("lint-urdf", "lint-urdf-sim") and isinstance(document, dict):
        texts += [str(f.get("message", "")) for f in document.get("findings") or [] if isinstance(f, dict)]
    for text in texts:
        for quoted in QUOTED_LINE.finditer(text):
            if Path(quoted["file"]).name == path.name:  # a line of "the robot file", as the user reads it
                looked("FILE:LINE quotes in load errors and P001 checked")
                problem = line_problem(str(path), int(quoted["line"]), quoted["rest"], need_name=False)
                if problem:
                    return f"quotes {problem}"
    if command.key == "fk-verify" and isinstance(document, dict):
        return fk_precision_problem(document, path)
    if command.key in FIXERS and isinstance(document, dict):
        return fixer_left_dirty(runner, command, path, document, run_dir)
    return ""


@functools.lru_cache(maxsize=16)
def _parsed(path: str) -> tuple[bytes, object] | None:
    """The robot file's bytes and lxml tree (each finding of a file looks at the same file)."""
    from lxml import etree

    try:
        text = Path(path).read_bytes()
        return text, etree.fromstring(text, etree.XMLParser(resolve_entities=False, no_network=True))
    except (OSError, etree.XMLSyntaxError, ValueError):
        return None


def line_problem(path: object, line: object, message: str, need_name: bool = True) -> str:
    """'' when line ``line`` of ``path`` is inside an element that holds the thing ``message`` names.

    The element at a line is the last one whose start tag begins at or before it (a multi-line start
    tag included); it holds the thing when an attribute of it, of an element inside it, or of an element
    around it has that value (a link or joint name) or contains it (a mesh file name, an extension):
    the ``<inertia>`` line of ``link 'a'`` holds it, a ``<transmission>`` holds the joint it drives.
    Without a name only the line's existence is checked (``need_name=False``)."""
    named = NAMED.search(message)
    if not isinstance(path, str) or not isinstance(line, int) or line < 1 or path.endswith(".xacro"):
        return ""
    if not named and need_name:
        return ""
    parsed = _parsed(path)
    if parsed is None:
        return ""
    text, root = parsed
    count = text.count(b"\n") + (not text.endswith(b"\n"))
    if line > count:
        return f"{Path(path).name}:{line}, a line the file does not have ({count} lines)"
    if not named:
        return ""
    name, kind = named["name"], named["kind"]
    elements = [e for e in root.iter() if isinstance(e.tag, str) and (e.sourceline or 0) <= line]
    if not elements:
        return ""
    at = elements[-1]

    def holds(element) -> bool:
        values = element.attrib.values()
        return any(name in v if kind in ("mesh", "extension") else name == v for v in values)

    if any(holds(e) for e in at.iter() if isinstance(e.tag, str)) or any(holds(e) for e in at.iterancestors()):
        return ""
    reads = text.splitlines()[line - 1].decode("utf-8", "replace").strip()[:60]
    return f"{Path(path).name}:{line} does not hold {named.group(0)} (it reads {reads!r})"


def fk_precision_problem(document: dict, path: Path) -> str:
    """fk-verify calling FAIL an error below float32 precision at the robot's reach (eps32 x reach)."""
    error = document.get("max_position_error_m")
    if document.get("passed") is not False or not isinstance(error, (int, float)):
        return ""
    looked("fk-verify FAILs checked against float32 precision")
    reach = robot_reach(path)
    if reach and error < FLOAT32_EPS * reach:
        return f"FAIL on {error:.3g} m, below float32 precision at {reach:.3g} m reach ({FLOAT32_EPS * reach:.3g} m)"
    return ""


def robot_reach(path: Path) -> float | None:
    """An upper bound on any link's distance from the base: every joint offset plus every prismatic travel."""
    from lxml import etree

    if path.suffix.lower() == ".xacro":
        return None
    try:
        root = etree.parse(str(path), etree.XMLParser(resolve_entities=False, no_network=True)).getroot()
    except (OSError, etree.XMLSyntaxError):
        return None
    reach = 0.0
    for joint in root.iter("joint"):
        origin, limit = joint.find("origin"), joint.find("limit")
        with contextlib.suppress(ValueError, TypeError):
            if origin is not None:
                reach += sum(float(v) ** 2 for v in (origin.get("xyz") or "0 0 0").split()) ** 0.5
            if joint.get("type") == "prismatic" and limit is not None:
                reach += max(abs(float(limit.get("lower", 0))), abs(float(limit.get("upper", 0))))
    return reach


def fixer_left_dirty(runner: Runner, command: Command, path: Path, document: dict, run_dir: Path) -> str:
    """A fixer that changed values must leave no finding of its own rules behind, except those it says it skipped.

    The fixer runs again with --output into a folder of symlinks to the robot's folder (so relative mesh
    paths still resolve, and the robot's tree is not written), then lint-urdf runs on the original and
    on the fixed copy: a finding whose ``fixed_by`` names this fixer, present before and after, on a
    thing the fixer neither skipped nor noted, is a fix that did not fix."""
    files = document.get("files") or []
    if not files or not isinstance(files[0], dict) or not files[0].get("changed"):
        return ""
    looked(f"{command.key} runs that changed values, re-linted after the fix")
    mirror = run_dir / "mirror"
    mirror.mkdir(exist_ok=True)
    for entry in path.parent.iterdir():
        if entry.name != path.name:
            with contextlib.suppress(OSError):
                (mirror / entry.name).symlink_to(entry)
    fixed = mirror / path.name
    argv = [a for a in command.args(str(path), run_dir) if a not in ("--diff",)]
    package = ["--package-path", collection_package(str(path))]
    rerun = runner.run([*argv, "--output", str(fixed), *package], run_dir)
    if rerun.returncode not in (0, 1) or not fixed.is_file():
        return ""
    options = set(argv)

    def own(target: Path) -> set[tuple[str, str]]:
        outcome = runner.run(["lint-urdf", str(target), "--no-cache", "--no-config", "--format", "json", *package],
                             run_dir)
        lint, _ = parse_json(outcome.stdout)
        findings = lint.get("findings", []) if isinstance(lint, dict) else []
        result = set()
        for finding in findings:
            words = str(finding.get("fixed_by") or "").split()
            if words[:1] == [command.key] and all(w in options for w in words[1:] if w.startswith("--")):
                named = NAMED.search(str(finding.get("message", "")))
                result.add((str(finding.get("rule")), named["name"] if named else str(finding.get("message"))))
        return result

    left = own(path) & own(fixed)
    excused = json.dumps([files[0].get("skipped"), files[0].get("notes")])
    left = {(rule, name) for rule, name in left if name not in excused}
    if left:
        rule, name = sorted(left)[0]
        return f"changed values but left {len(left)} of its own finding(s), e.g. {rule} on {name!r}"
    return ""


def execute(runner: Runner, command: Command, robot: Robot | None) -> RunRecord:
    """Run ``command`` on ``robot`` (None: a command without a file) and classify it."""
    run_dir = runner.new_run_dir()
    try:
        argv = command.args(str(robot.path) if robot else "", run_dir)
        outcome = runner.run(argv, run_dir)
        verdict, reason = classify(command, outcome, run_dir)
        if verdict in ("clean", "user error") and robot is not None:
            problem = second_look(runner, command, robot.path, outcome, run_dir)
            if problem:
                verdict, reason = "silent wrong", problem
    finally:
        shutil.rmtree(run_dir, ignore_errors=True)
    return RunRecord(
        command=command.label, source=robot.source if robot else "", file=robot.rel if robot else "",
        argv=["ar3cli", *argv], returncode=outcome.returncode, seconds=round(outcome.seconds, 3),
        outcome=verdict, reason=reason,
        stderr_first_line="" if verdict == "clean" else first_line(outcome.stderr),
        leftover_temp=outcome.leftover)


# --------------------------------------------------------------------------------------------
# Progress and report


class Progress:
    """One stderr line per file once all of its runs have finished."""

    def __init__(self, robots: list[Robot], commands: list[Command]) -> None:
        self.total = len(robots)
        self.order = {c.label: i for i, c in enumerate(commands)}
        self.pending = {r: len(commands) for r in robots}
        self.records: dict[Robot, list[RunRecord]] = {r: [] for r in robots}
        self.done = 0
        self._lock = threading.Lock()

    def finished(self, robot: Robot, record: RunRecord) -> None:
        with self._lock:
            self.records[robot].append(record)
            self.pending[robot] -= 1
            if self.pending[robot]:
                return
            self.done += 1
            records = sorted(self.records.pop(robot), key=lambda r: self.order.get(r.command, 0))
        seconds = sum(r.seconds for r in records)
        bad = [f"{r.command}: {r.outcome}" for r in records if r.outcome != "clean"]
        status = "; ".join(bad) if bad else "all clean"
        print(f"[{self.done}/{self.total}] {robot.label} ({seconds:.1f} s): {status}", file=sys.stderr, flush=True)


def summary_table(records: list[RunRecord], commands: list[Command]) -> str:
    header = ["command", "runs", *CLASSES, "leftover temp", "total seconds"]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for command in commands:
        rows = [r for r in records if r.command == command.label]
        counts = Counter(r.outcome for r in rows)
        leftover = sum(1 for r in rows if r.leftover_temp)
        cells = [f"`{command.label}`", str(len(rows)), *(str(counts[c]) for c in CLASSES),
                 str(leftover), f"{sum(r.seconds for r in rows):.1f}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def run_list(records: list[RunRecord], with_reason: bool = True) -> str:
    lines = []
    for r in records:
        where = f" `{r.source}:{r.file}`" if r.file else ""
        detail = f" ({r.reason})" if with_reason and r.reason else ""
        stderr = f": {r.stderr_first_line}" if r.stderr_first_line else ""
        lines.append(f"- `{r.command}`{where} **{r.outcome}**{detail}{stderr}")
    return "\n".join(lines) or "(none)"


def report(records: list[RunRecord], commands: list[Command], changes: list[str], wall: float) -> str:
    failed = [r for r in records if r.outcome in FAILURES]
    user = [r for r in records if r.outcome == "user error"]
    leftover = [r for r in records if r.leftover_temp]
    parts = [
        summary_table(records, commands),
        f"\n### Failed runs ({len(failed)})\n\n{run_list(failed)}",
        f"\n### User errors ({len(user)}; expected for bad input, worth reading)\n\n{run_list(user, False)}",
        f"\n### Runs that left files in their TMPDIR ({len(leftover)})\n\n"
        + ("\n".join(f"- `{r.command}` `{r.source}:{r.file}`: {', '.join(r.leftover_temp)}" for r in leftover)
           or "(none)"),
        f"\n### Robot files changed by the sweep ({len(changes)})\n\n"
        + ("\n".join(f"- {c}" for c in changes) or "(none)"),
        "\n### Second looks (what the silent-wrong signals examined)\n\n"
        + ("\n".join(f"- {what}: {count}" for what, count in sorted(LOOKED.items())) or "(nothing to examine)"),
        f"\nTotal wall time: {wall:.1f} s",
    ]
    return "\n".join(parts)


# --------------------------------------------------------------------------------------------
# Main


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--source", choices=("erd", "pybullet_data", "all"), default="all",
                        help="robot collection(s) to sweep (default: all)")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE,
                        help=f"where example-robot-data is (or gets) installed (default: {DEFAULT_CACHE})")
    parser.add_argument("--match", metavar="SUBSTRING",
                        help="only files whose path (relative to their collection) contains this, any case")
    parser.add_argument("--limit", type=int, metavar="N", help="only the first N files (after --match)")
    parser.add_argument("--include-random", action="store_true",
                        help="also pybullet_data's 1000 generated random_urdfs/ objects")
    parser.add_argument("--commands", metavar="A,B",
                        help="comma-separated subset of: " + ", ".join(c.key for c in COMMANDS))
    parser.add_argument("--jobs", "-j", type=int, default=2, help="subprocesses at once (default: 2)")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per run (default: 300)")
    parser.add_argument("--json", type=Path, metavar="FILE", help="write every run's record to FILE")
    parser.add_argument("--ar3cli", metavar="PATH",
                        help="the ar3cli executable (default: from PATH); given, it runs without PYTHONPATH, so "
                             "VENV/bin/ar3cli of a plain `pip install .` sweeps exactly what a user installs")
    args = parser.parse_args(argv)
    if args.jobs < 1 or (args.limit is not None and args.limit < 1) or args.timeout <= 0:
        parser.error("--jobs, --limit and --timeout must be positive")
    try:
        args.command_list = pick_commands(args.commands)
    except ValueError as exc:
        parser.error(str(exc))
    return args


def sweep(runner: Runner, robots: list[Robot], commands: list[Command], jobs: int) -> list[RunRecord]:
    """Every (file, command) pair plus the file-less commands, ``jobs`` at a time, in submission order."""
    per_file = [c for c in commands if c.per_file]
    progress = Progress(robots, per_file)
    futures: list[Future[RunRecord]] = []
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        try:
            futures += [pool.submit(execute, runner, c, None) for c in commands if not c.per_file]
            for robot in robots:
                for command in per_file:
                    future = pool.submit(execute, runner, command, robot)
                    future.add_done_callback(
                        lambda f, robot=robot: f.exception() or progress.finished(robot, f.result()))
                    futures.append(future)
            return [f.result() for f in futures]
        except KeyboardInterrupt:
            pool.shutdown(wait=False, cancel_futures=True)
            runner.kill_all()
            raise


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    commands: list[Command] = args.command_list
    ar3cli = find_ar3cli(args.ar3cli)
    robots = select_robots(args) if any(c.per_file for c in commands) else []
    roots = sorted({r.root for r in robots})
    print(f"{len(robots)} files x {sum(c.per_file for c in commands)} commands, {args.jobs} jobs, "
          f"ar3cli = {ar3cli}", file=sys.stderr)
    before = snapshot(roots)
    sweep_dir = Path(tempfile.mkdtemp(prefix="sweep-real-robots-"))
    start = time.perf_counter()
    try:
        records = sweep(Runner(ar3cli, sweep_dir, args.timeout, plain=bool(args.ar3cli)), robots, commands, args.jobs)
    finally:
        shutil.rmtree(sweep_dir, ignore_errors=True)
    wall = time.perf_counter() - start
    changes = snapshot_changes(before, snapshot(roots))
    if args.json:
        args.json.write_text(json.dumps([asdict(r) for r in records], indent=1) + "\n", encoding="utf-8")
    print(report(records, commands, changes, wall))
    failed = any(r.outcome in FAILURES for r in records)
    return 1 if failed or changes else 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        print("interrupted: running ar3cli processes killed, temporary folder removed", file=sys.stderr)
        sys.exit(130)
