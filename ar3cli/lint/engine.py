"""The lint engine: collect files, load each once, run the selected rules, apply configuration.

One file's trouble never stops the run: a file that cannot be read, parsed or expanded becomes a
finding of the F family on that file (:func:`load_failure`) and the engine moves on. Rules yield
:class:`~ar3cli.lint.rules.base.Hit` objects; this module turns them into located
:class:`~ar3cli.findings.Finding` objects, drops the suppressed ones (inline comments,
``per-file-ignores``) and applies severity overrides. Nothing here imports pybullet: ``--sim`` rules
open a :class:`~ar3cli.sim.session.Session` lazily through :attr:`Context.session`.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import functools
import hashlib
import os
import re
from collections import Counter
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ar3cli.errors import UserError
from ar3cli.findings import Finding, Severity
from ar3cli.infra.file_cache import cache_dir, merge_learned, take_learned
from ar3cli.lint.context import Context
from ar3cli.lint.reuse import ITEM_LOCAL, Carry, Reuse, options_key
from ar3cli.lint.rules import REGISTRY, RULES, Hit, Rule, matches
from ar3cli.lint.rules.file import LIBRARY

if TYPE_CHECKING:
    from ar3cli.lint.result_cache import ResultCache
    from ar3cli.urdf.srdf_read import DisabledPairs

ROBOT_SUFFIXES = (".urdf", ".xacro")
ENGINE_OF = {"P": "pybullet", "M": "mujoco"}
"""Simulation rule family -> the engine it needs (``--engine``)."""
_SKIP_DIRS = {".git", ".hg", ".svn", "__pycache__", "node_modules", ".venv", "venv", ".tox"}
_INLINE = re.compile(r"ar3cli:\s*ignore(?!-file)(?:\[([^\]]*)\])?")
_FILE_LEVEL = re.compile(rb"ar3cli:\s*ignore-file(?:\[([^\]]*)\])?")


@dataclass
class LintOptions:
    """What to check and how: the merged command line and ``[tool.ar3cli.lint]`` configuration."""

    select: list[str] = field(default_factory=lambda: ["ALL"])
    ignore: list[str] = field(default_factory=list)
    per_file_ignores: dict[str, list[str]] = field(default_factory=dict)
    severity: dict[str, Severity] = field(default_factory=dict)
    sim: bool = False
    package_paths: Mapping[str, Path] = field(default_factory=dict)
    xacro_args: Mapping[str, str] = field(default_factory=dict)
    srdf_disabled: DisabledPairs | None = None
    """Link pairs an SRDF tells MoveIt not to check (``--srdf``): not reported as colliding at home. None: no
    ``--srdf``, the package's own SRDF is looked for."""
    engines: tuple[str, ...] = ("pybullet",)
    """Simulators ``--sim`` runs (``--engine``): P rules need ``pybullet``, M rules ``mujoco`` (or their code named)."""
    targets: tuple[str, ...] = ("pybullet", "ros")
    """Engines the robot is meant for (``--target``): their T rules run."""
    config_select: list[str] | None = None
    """``[tool.ar3cli.lint] select`` when the command line gave no ``--select``: the findings of
    other rules are suppressed by the configuration (counted and said, never silently dropped)."""
    config_ignore: list[str] = field(default_factory=list)
    """``[tool.ar3cli.lint] ignore``: the findings of these rules are suppressed by the configuration."""
    config_file: str | None = None
    """The pyproject.toml the configuration came from, as the summary names it."""
    in_file: bool = True
    """Honour the files' own suppression comments (``ar3cli: ignore``, ``ar3cli: ignore-file``);
    ``--isolated`` turns it off."""
    sources: bool = False
    """Record which files' lines a page may show, with the digest of the bytes parsed
    (:attr:`LintResult.sources`): for ``--format html`` and ``report``."""

    @classmethod
    def configured(cls, config: Any, select: list[str] | None = None, ignore: list[str] | None = None,
                   isolated: bool = False, **settings: Any) -> LintOptions:
        """The options for the project's ``config`` (a :class:`~ar3cli.lint.config.LintConfig`) and
        the command line's ``select`` and ``ignore`` codes (None: none given); ``settings`` are the
        other fields. Every front-end builds them here (lint-urdf, report, view, server), so they agree.

        What the command line selects is what runs; the configuration's select, ignore and
        per-file-ignores only suppress findings afterwards (:func:`settle`: counted, and said in
        every format), its severity table re-grades them. ``isolated`` (``--isolated``) also reports
        what the files' own comments suppress. A malformed code is a UserError."""
        from ar3cli.lint.rules import validate_patterns

        try:
            chosen = validate_patterns(select, "--select") if select else None
            return cls(select=chosen or ["ALL"], ignore=validate_patterns(ignore or [], "--ignore"),
                       config_select=None if chosen else config.select, config_ignore=list(config.ignore),
                       per_file_ignores=dict(config.per_file_ignores), severity=dict(config.severity),
                       config_file=str(config.path) if config.path is not None else None,
                       in_file=not isolated, **settings)
        except ValueError as exc:
            raise UserError(str(exc)) from None

    def rules(self) -> list[Rule]:
        """Selected rules in registry order; simulation rules only with ``sim``; opt-in rules only
        when ``select`` (or the configuration's) names their code; target rules only for the
        ``targets`` (or when named). The configuration's select and ignore do not narrow this: their
        rules run and their findings are suppressed by :func:`settle`, so the run can say so."""
        named = {code.upper() for code in (*self.select, *(self.config_select or []))}
        return [r for r in RULES if matches(r.code, self.select) and not matches(r.code, self.ignore)
                and (self.sim or not r.needs_sim) and (not r.opt_in or r.code in named)
                and (not r.needs_sim or ENGINE_OF.get(r.code[0]) in self.engines or r.code in named)
                and (not r.targets or set(r.targets) & set(self.targets) or r.code in named)]


@dataclass
class LintResult:
    """One linted file: its display path, whether it loaded, its findings, and the one-line error
    that cut its check short (pybullet crashed on it under ``--sim``), if any."""

    path: str
    loaded: bool
    findings: list[Finding]
    error: str | None = None
    cached: bool = False
    """Answered from the result cache (said in the text summary; the JSON is the same either way)."""
    suppressed: list[Suppressed] = field(default_factory=list)
    """Findings not reported, and by what: the file's comments, the configuration, the baseline."""
    lowered: int = 0
    """Findings the configuration's ``severity`` table made less severe than their rule's."""
    sources: dict[str, str] = field(default_factory=dict)
    """With :attr:`LintOptions.sources`: display path -> SHA-256 of the bytes ar3cli parsed, for each
    file whose lines may be shown with a finding (:func:`shown_sources`)."""
    carry: Carry | None = field(default=None, repr=False, compare=False)
    """With ``lint_model(..., keep=True)``: what the static rules' run leaves for a check after an edit
    (:mod:`ar3cli.lint.reuse`; an editor's language server keeps it)."""

    def to_dict(self) -> dict[str, Any]:
        return {"path": self.path, "loaded": self.loaded, "findings": len(self.findings), "error": self.error}


SUPPRESSED_BY = ("config", "comment", "baseline")
"""What may suppress a finding: ``[tool.ar3cli.lint]`` (select, ignore, per-file-ignores), a comment
in the file (``ar3cli: ignore``, ``ar3cli: ignore-file``), or ``--baseline``."""


@dataclass(frozen=True)
class Suppressed:
    """A finding that is not reported, and what suppressed it (one of :data:`SUPPRESSED_BY`)."""

    finding: Finding
    by: str


def display_path(path: Path) -> str:
    """The path relative to the current directory when it is below it, else as given."""
    if ".." in Path(path).parts:  # relpath would drop "link/.." although the OS follows the link
        return str(path)
    try:
        relative = os.path.relpath(path)
    except ValueError:  # another drive on Windows
        return str(path)
    return str(path) if relative.startswith("..") else Path(relative).as_posix()


def collect_files(paths: Iterable[Path], skipped: list[str] | None = None) -> list[Path]:
    """Files to lint: given files as they are, folders searched for ``*.urdf`` / ``*.xacro`` (sorted).

    A folder's search leaves out a symbolic link whose target lies outside that folder
    (``robot.urdf -> ~/.aws/credentials`` committed in a pull request): its display path goes to
    ``skipped`` when given. A file named on the command line is linted as asked, link or not.
    A path that does not exist is a usage error (exit 2): it is a typo, not a finding.
    """
    found: list[Path] = []
    for path in paths:
        try:
            is_dir = path.is_dir()
        except OSError:  # a name the OS refuses (a component over 255 bytes): the file's F001 says so
            found.append(path)
            continue
        if is_dir:
            for folder, dirs, files in os.walk(path):
                dirs[:] = sorted(d for d in dirs if d not in _SKIP_DIRS)
                for name in sorted(files):
                    if not name.lower().endswith(ROBOT_SUFFIXES):
                        continue
                    full = os.path.join(folder, name)  # os.walk enters no linked folder: only the file may lead out
                    if not os.path.islink(full) or inside_tree(full, path):
                        found.append(Path(folder) / name)
                    elif skipped is not None:
                        skipped.append(display_path(Path(folder) / name))
        elif path.exists() or path.is_symlink():
            found.append(path)
        else:
            raise UserError(f"{path}: no such file or directory")
    unique: dict[str, Path] = {}
    for path in found:  # the same file named twice (by itself and by its folder) is linted once
        folder, name = os.path.split(path)
        unique.setdefault(os.path.join(os.path.realpath(folder or "."), name), path)
    return list(unique.values())


def inside_tree(file: str | os.PathLike[str], tree: str | os.PathLike[str]) -> bool:
    """True when ``file``, symbolic links resolved, lies in the folder ``tree`` (links resolved too)
    or below it: what ar3cli may show of a robot file (and what a folder's search takes)."""
    root = os.path.realpath(tree)
    return os.path.realpath(file).startswith(root.rstrip(os.sep) + os.sep)


FILES_PER_WORKER = 24
"""Automatic --jobs adds a process per this many files (a forked process costs ~3 ms to start and
hand its findings back; a static lint of a file ~5 ms with lint v3's rules, ~100 ms when its meshes
are read for the first time). The number is also in lint-urdf's --help and docs/commands/lint-urdf.md."""
SIM_FILES_PER_WORKER = 2
"""With --sim a file takes a few hundred milliseconds: two files repay a process."""
BYTES_PER_WORKER = 256 * 1024
"""... or a process per this many bytes of robot files, when that gives more: a static lint costs
~0.4 µs per byte of URDF (pybullet_data's 95 files, 0.7 MB: ~0.3 s), so 256 KB is ~0.1 s of work, and
large robots are few files: 40 of example-robot-data's, 1.5 MB, took 3.0 s with an empty mesh cache in
one process and 1.9 s in two (0.7 and 0.45 s with the cache warm). Also in lint-urdf's --help and
docs/commands/lint-urdf.md."""


def lint_paths(paths: Iterable[Path], options: LintOptions, use_cache: bool = True,
               jobs: int | None = None, skipped: list[str] | None = None) -> list[LintResult]:
    """Lint every file under ``paths``; one :class:`LintResult` per file, in order.

    With ``use_cache``, unchanged files reuse the findings of an earlier run (:mod:`ar3cli.lint.result_cache`).
    ``jobs`` processes share the files (None: one per CPU for large batches, see
    :func:`~ar3cli.infra.process_pool.worker_count`); the results do not depend on it. ``skipped``
    receives the links a folder's search left out (:func:`collect_files`).
    """
    from ar3cli.infra import process_pool
    from ar3cli.infra.streaming_pool import stream
    from ar3cli.lint.included import merge_included

    rules = options.rules()
    cache = _result_cache(options, rules) if use_cache else None
    files = collect_files(paths, skipped)
    if not process_pool.can_fork():  # Windows, macOS: in this process, without limits
        return [settle(result, options) for result in merge_included([lint_file(path, rules, options, cache)
                                                                       for path in files])]
    sizes = [_size(path) for path in files]
    workers = _workers(jobs, sizes, options.sim)
    take_learned()  # what this process knows already need not come back from every child
    job = functools.partial(_lint_file_in_worker, rules=rules, options=options, cache=cache)
    largest_first = sorted(range(len(files)), key=lambda index: -sizes[index])
    limit = file_time_limit(options)
    results: list[LintResult] = [None] * len(files)  # type: ignore[list-item]
    for index, (kind, payload) in stream(lambda index: job(files[index]), largest_first, workers, limit):
        if kind == "ok":
            result, learned = payload
            merge_learned(learned)
        elif kind == "interrupted":
            raise KeyboardInterrupt
        else:
            result = LintResult(display_path(files[index]), False, [], _stopped(display_path(files[index]), kind,
                                                                                 payload, limit))
        results[index] = result
    return [settle(result, options) for result in merge_included(results)]  # merged first: the counts agree


def file_time_limit(options: LintOptions) -> float | None:
    """Seconds one file's check may take (None: no limit): the command's ``--timeout`` for its
    static checks, plus as much again for each simulator ``--sim`` runs (each in a child of its own
    with that limit)."""
    from ar3cli.infra import child_limits

    seconds = child_limits.timeout()
    if seconds is None:
        return None
    return seconds * (1 + (len(options.engines) if options.sim else 0))


def _stopped(shown: str, kind: str, payload: Any, limit: float | None) -> str:
    """The one line for a file whose check did not come back: it ran past its time, out of memory,
    its process died, or ar3cli failed on it (a bug)."""
    from ar3cli.infra.child_limits import MEMORY_VARIABLE, describe_memory_limit

    if kind == "timeout":
        return (f"{shown}: checking it took longer than the limit of {limit:g} s per file; raise --timeout "
                "(0: no limit) if the file is just large")
    if kind == "out-of-memory":
        return (f"{shown}: checking it ran out of memory (the limit of a child process is {describe_memory_limit()}; "
                f"set {MEMORY_VARIABLE} to change it)")
    if kind == "crash":
        return f"{shown}: the process checking it died: {payload}"
    if kind == "user-error":
        return payload[0]
    return f"{shown}: {internal_error('while checking it', RuntimeError(payload))}"


def settle(result: LintResult, options: LintOptions) -> LintResult:
    """``result`` (as :func:`lint_file` gives it) with the run's settings applied: without
    ``in_file``, the findings the file's own comments suppressed are reported again; the findings
    the configuration deselects (its ``select``, ``ignore``, ``per-file-ignores``) move to the
    suppressed ones, by ``config``; its ``severity`` table is applied (``lowered`` counts the
    findings it made less severe). A file that could not be loaded reports why whatever the
    configuration selected: only its ``ignore`` suppresses that."""
    findings, suppressed = list(result.findings), []
    for item in result.suppressed:
        if item.by == "comment" and not options.in_file:
            findings.append(item.finding)
        else:
            suppressed.append(item)
    if len(findings) != len(result.findings):
        findings.sort(key=finding_order(result.path))
    kept, lowered = [], 0
    for finding in findings:
        if _config_suppresses(finding, result, options):
            suppressed.append(Suppressed(finding, "config"))
            continue
        changed = _override(finding, options)
        lowered += changed.severity < finding.severity
        kept.append(changed)
    return dataclasses.replace(result, findings=kept, suppressed=suppressed, lowered=result.lowered + lowered)


def _config_suppresses(finding: Finding, result: LintResult, options: LintOptions) -> bool:
    code = finding.rule
    if matches(code, options.config_ignore) or _file_ignored(finding.path, code, options):
        return True
    if finding.path != result.path and _file_ignored(result.path, code, options):  # an included file's finding
        return True
    return options.config_select is not None and result.loaded and not matches(code, options.config_select)


def _workers(jobs: int | None, sizes: list[int], sim: bool) -> int:
    """Processes for files of these ``sizes``: ``--jobs``, else one per :data:`FILES_PER_WORKER` files
    or per :data:`BYTES_PER_WORKER` bytes, whichever is more (one per :data:`SIM_FILES_PER_WORKER`
    files with ``--sim``), within :func:`~ar3cli.infra.process_pool.worker_count`'s limits."""
    from ar3cli.infra.process_pool import worker_count

    if sim:
        return worker_count(jobs, len(sizes), SIM_FILES_PER_WORKER)
    by_files = worker_count(jobs, len(sizes), FILES_PER_WORKER)
    if jobs is not None:
        return by_files
    return max(by_files, min(len(sizes), worker_count(None, sum(sizes), BYTES_PER_WORKER)))


def _size(path: Path) -> int:
    """The file's size in bytes (0 when it cannot be read: its one-line finding is cheap)."""
    try:
        return os.stat(path).st_size
    except (OSError, ValueError):
        return 0


MAX_FINDINGS_TEXT = 64 * 1024 * 1024
"""Characters of findings (messages and hints) one file may hand back: a 20,000-link star's findings
are ~6 MB. More is a file built to flood the output (every finding listing thousands of names):
the file gets one error line instead, and ar3cli never holds or prints it."""


def _lint_file_in_worker(path: Path, rules: list[Rule], options: LintOptions,
                         cache: ResultCache | None) -> tuple[LintResult, dict[str, Any]]:
    """:func:`lint_file`, plus what the on-disk caches learnt meanwhile (a worker never saves them:
    its parent merges and saves); a result over :data:`MAX_FINDINGS_TEXT` stays in the worker."""
    result = lint_file(path, rules, options, cache)
    size = sum(len(f.message) + len(f.hint) for f in result.findings)
    if size > MAX_FINDINGS_TEXT:
        result = LintResult(result.path, result.loaded, [], f"{result.path}: its {len(result.findings)} findings "
                            f"hold {size / 1e6:.0f} million characters, more than ar3cli reports for one file "
                            f"({MAX_FINDINGS_TEXT / 1e6:.0f} million): a file built to flood the output?")
    return result, take_learned()


def _result_cache(options: LintOptions, rules: list[Rule]) -> ResultCache | None:
    """The result cache for these settings, or None when caching is off or cannot apply (``--sim``)."""
    if options.sim or cache_dir() is None:
        return None
    from ar3cli.lint.result_cache import ResultCache

    return ResultCache.for_settings(rules=[rule.code for rule in rules], package_paths=options.package_paths,
                                    xacro_args=options.xacro_args, targets=options.targets)


def lint_file(path: Path, rules: list[Rule], options: LintOptions, cache: ResultCache | None = None) -> LintResult:
    """Load one file and run ``rules`` on it; a load failure is a finding, never an exception.

    ``cache`` (a :class:`~ar3cli.lint.result_cache.ResultCache`) answers for unchanged ``.urdf`` files
    and learns the findings of the others.
    """
    from ar3cli.urdf.file_kind import is_xacro
    from ar3cli.urdf.model import load_model

    shown = display_path(path)
    if cache is not None and not is_xacro(path):
        remembered = cache.get(path, shown)
        if remembered is not None:
            found, by_comment, digest = remembered
            sources = {shown: digest} if options.sources and inside_tree(path, os.path.dirname(path) or ".") else {}
            return LintResult(shown, True, found, cached=True, suppressed=[Suppressed(f, "comment") for f in by_comment],
                              sources=sources)
    data = None
    try:
        if options.sources:  # read here, so that what a page may show is exactly what was parsed
            from ar3cli.infra.safe_read import read_bytes

            data = read_bytes(path)
        model = load_model(path, options.package_paths, options.xacro_args, source=data)
    except UserError as exc:
        finding = included_failure(path, load_failure(path, shown, exc.message), options)
    except RecursionError:
        finding = Finding("F002", Severity.ERROR, "document nested too deeply to parse", shown)
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001 - the loader's bug: this file's error line, the batch goes on
        return LintResult(shown, False, [], f"{shown}: {internal_error('while loading it', exc)}")
    else:
        result = lint_model(model, shown, rules, options)
        if cache is not None and not model.is_xacro and result.error is None:
            cache.put(path, shown, model.source_bytes, result.findings, model.resolver.probed,
                      [item.finding for item in result.suppressed if item.by == "comment"])
        return result
    own = data is not None and inside_tree(path, os.path.dirname(path) or ".")
    return unloaded_result(finding, options, {shown: hashlib.sha256(data).hexdigest()} if own else {})


def unloaded_result(finding: Finding, options: LintOptions, sources: dict[str, str] | None = None) -> LintResult:
    """The result of a file that did not load, ``finding`` (:func:`load_failure`) saying why; ``sources``
    as :attr:`LintResult.sources` (the bytes read, where a page may show them).

    A file that cannot be loaded was not checked at all: say so whatever --select picked (as ruff
    always reports syntax errors); only an explicit ignore hides it (the configuration's: :func:`settle`)."""
    if matches(finding.rule, options.ignore):
        return LintResult(finding.path, False, [])
    return LintResult(finding.path, False, [finding], sources=sources or {})


def lint_model(model, shown: str, rules: list[Rule], options: LintOptions, reuse: Reuse | None = None,
               keep: bool = False) -> LintResult:
    """Run ``rules`` on a loaded model and apply suppressions and severity overrides.

    The simulation rules run in a forked child (:func:`~ar3cli.infra.isolation.run_isolated`): when
    pybullet crashes in C on this file, the static findings stay and the crash is the file's error.
    ``reuse``: the earlier check of a text ``model`` was edited from (the same findings, less work);
    ``keep``: the result's :attr:`~LintResult.carry` is what the next check after an edit reuses.
    """
    if not model.links and not model.joints and is_macro_library(model):  # a xacro library: one info line (F008)
        rules = [] if matches(LIBRARY, options.ignore) else [REGISTRY[LIBRARY]]
    static, simulated, in_mujoco = _partition(rules)
    key = options_key(static, options)
    carry = Carry(key, model, Context(model, options.srdf_disabled, options.targets)) if keep else None
    if reuse is not None and not reuse.usable(model, key):
        reuse = None
    findings, suppressed, failures = _run_rules(model, shown, static, options, reuse, carry)
    error = None
    if simulated or in_mujoco:
        from ar3cli.infra.isolation import CrashError
        from ar3cli.sim.mujoco_session import run_mujoco
        from ar3cli.sim.session import run_pybullet

        for run, selected in ((run_pybullet, simulated), (run_mujoco, in_mujoco)):
            if not selected:
                continue
            try:
                found, held, failed = run(lambda selected=selected: _run_rules(model, shown, selected, options),
                                          model)
            except CrashError as exc:
                error = exc.message
            else:
                findings += found
                suppressed += held
                failures += failed
        if simulated and in_mujoco:
            from ar3cli.lint.rules.mujoco import merge_home_contacts

            findings = merge_home_contacts(findings)
    if failures and error is None:
        error = f"{shown}: {failures[0]}" + (f" (and {len(failures) - 1} more rules)" if len(failures) > 1 else "")
    order = finding_order(shown)
    findings.sort(key=order)
    suppressed.sort(key=lambda item: order(item.finding))
    return LintResult(shown, True, findings, error, suppressed=suppressed,
                      sources=shown_sources(model, shown) if options.sources else {}, carry=carry)


def finding_order(shown: str) -> Callable[[Finding], tuple]:
    """The order findings are reported in: the linted file's first, then each included file's; by line,
    column, rule, then message and hint, so that two findings at one place (two elements on one line share
    the column of the first) come in the same order whatever order the rules found them in (an editor's
    check after a keystroke finds the edited item's last: :mod:`ar3cli.lint.reuse`)."""
    return lambda f: (f.path != shown, f.path, f.line, f.column, f.rule, f.message, f.hint or "")


def shown_sources(model, shown: str) -> dict[str, str]:
    """The files whose lines a page may show with a finding, by display path, each with the SHA-256
    of the bytes ar3cli parsed: the linted file, unless it is a symbolic link leading out of its own
    folder (``robot.urdf -> ~/.aws/credentials``: linted as asked, never shown), and for a xacro,
    each file xacro parsed (read only inside the robot's folder and packages in safe mode). The
    page re-reads a file and shows it only when its bytes still have that digest."""
    own = inside_tree(model.path, os.path.dirname(model.path) or ".")
    sources = {shown: hashlib.sha256(model.source_bytes).hexdigest()} if own else {}
    if model.is_xacro:
        from ar3cli.urdf.xacro_expand import parsed_digests

        locator = Locator(model, shown)
        for name, digest in parsed_digests(model.xml_bytes).items():
            path = locator.shown_file(name)
            if path != shown:
                sources.setdefault(path, digest)
    return sources


def is_macro_library(model) -> bool:
    """Whether ``model``'s file is a xacro library that makes no robot (:mod:`ar3cli.urdf.macro_library`)."""
    from ar3cli.urdf.macro_library import macro_library

    return macro_library(model, find_includers=False) is not None


def _partition(rules: list[Rule]) -> tuple[list[Rule], list[Rule], list[Rule]]:
    """(static rules with a check, PyBullet rules, MuJoCo rules) of ``rules``; sorted out once per
    list, not once per file (a bulk lint hands every file the same list)."""
    global _PARTITIONED
    given = tuple(rules)
    known = _PARTITIONED  # read once: another thread (an editor's server) may replace it meanwhile
    if known is None or known[0] != given:  # the same rules: an identity check each
        static = [rule for rule in given if not rule.needs_sim and rule.check is not None]
        simulated = [rule for rule in given if rule.needs_sim and ENGINE_OF.get(rule.code[0]) != "mujoco"]
        in_mujoco = [rule for rule in given if rule.needs_sim and ENGINE_OF.get(rule.code[0]) == "mujoco"]
        known = _PARTITIONED = (given, (static, simulated, in_mujoco))
    return known[1]


_PARTITIONED: tuple[tuple[Rule, ...], tuple[list[Rule], list[Rule], list[Rule]]] | None = None


def _run_rules(model, shown: str, rules: list[Rule], options: LintOptions, reuse: Reuse | None = None,
               carry: Carry | None = None) -> tuple[list[Finding], list[Suppressed], list[str]]:
    """The located findings of ``rules`` on ``model`` (unsorted), those the file's own comments
    suppress, and one line per rule that failed on this file. The configuration is applied later,
    by :func:`settle` (so the result cache holds what the file alone decides).

    A rule that raises (a value the file holds overflows a computation it did not expect, say) is a
    bug in that rule: its findings so far are kept, the other rules still run, and the file's error
    line names it, so one file never ends the batch (:func:`lint_model` makes it the file's error).
    ``reuse`` gives the hits of item-local rules and the answers about untouched links from the earlier
    check (:mod:`ar3cli.lint.reuse`); ``carry`` records this run's for the next.
    """
    context = carry.context if carry is not None else Context(model, options.srdf_disabled, options.targets)
    if reuse is not None:
        reuse.prepare(context)
    locator = Locator(model, shown)
    file_ignores = _file_level_ignores(model)
    findings: list[Finding] = []
    suppressed: list[Suppressed] = []
    failures: list[str] = []
    try:
        for rule in rules:
            if rule.check is None:
                continue
            try:
                known = _reused(reuse, rule) if reuse is not None and rule.code in ITEM_LOCAL else None
                produced: list[Hit] = []
                for hit in known if known is not None else rule.check(context):
                    produced.append(hit)
                    path, line, column = locator.locate(hit)
                    finding = Finding(rule.code, rule.severity_for(options.targets), hit.message, path, line, column,
                                      hit.hint or rule.fix)
                    if matches(rule.code, file_ignores) or (hit.element is not None
                                                            and suppressed_inline(hit.element, rule.code)):
                        suppressed.append(Suppressed(finding, "comment"))
                    else:
                        findings.append(finding)
                if carry is not None:
                    carry.record(rule, produced)
            except (UserError, MemoryError):
                raise
            except Exception as exc:  # noqa: BLE001 - a rule's bug: this file's error line, the batch goes on
                failures.append(internal_error(f"in rule {rule.code}", exc) + "; the other rules ran")
    finally:
        context.close()
    return findings, suppressed, failures


def _reused(reuse: Reuse, rule: Rule) -> list[Hit] | None:
    """``rule``'s hits from the earlier check (:meth:`~ar3cli.lint.reuse.Reuse.hits`), or None: run it in full
    (also when reusing fails: a bug there costs the reuse, never the rule's findings)."""
    try:
        return reuse.hits(rule)
    except (UserError, MemoryError):
        raise
    except Exception:  # noqa: BLE001
        return None


def internal_error(where: str, exc: BaseException) -> str:
    """The line that says ar3cli failed on a file ``where`` (``in rule G014``): a bug to report."""
    text = " ".join(str(exc).split())[:200]
    return f"internal error {where} ({type(exc).__name__}{': ' + text if text else ''}), please report it"


def included_failure(path: Path, failure: Finding, options: LintOptions) -> Finding:
    """``failure``, or F008 at info when it is an F004 of a xacro library, or of a fragment that a file of its
    package includes and that expands there (:func:`~ar3cli.lint.rules.file.fragment_message`): the includer
    reports it."""
    from ar3cli.infra.safe_read import read_bytes
    from ar3cli.lint.rules.file import fragment_message

    if failure.rule != "F004":
        return failure
    try:
        message = fragment_message(path, read_bytes(path), failure.message,
                                   lambda includer: _expands_including(includer, path, options))
    except UserError:
        return failure
    if message is None:
        return failure
    return Finding(LIBRARY, REGISTRY[LIBRARY].severity, message, failure.path, 0, 0, REGISTRY[LIBRARY].fix)


def _expands_including(includer: Path, path: Path, options: LintOptions) -> bool:
    """Whether ``includer`` expands (with the run's packages and xacro arguments) and what it included is the
    file ``path`` (not another of the same name)."""
    from ar3cli.urdf.model import load_model

    try:
        model = load_model(includer, options.package_paths, options.xacro_args)
    except UserError:
        return False
    included = model.expansion.included if model.expansion is not None else []
    own = path.resolve()
    return any(Path(name).resolve() == own for name in included)


def load_failure(path: Path, shown: str, message: str) -> Finding:
    """Turn the loader's one-line UserError into an F001-F004 finding on the file."""
    line = 0
    for prefix in (str(path), shown):
        match = re.match(re.escape(prefix) + r"(?::(\d+))?: ", message)
        if match:
            line = int(match.group(1) or 0)
            message = message[match.end():]
            break
    if "xacro error" in message or "$(find" in message:
        code = "F004"  # an include xacro cannot read is the expansion's failure, not the file's
    elif any(key in message for key in ("no such file", "is a directory", "not a regular file", "cannot read",
                                        "MB limit")):
        code = "F001"
    elif message.startswith("root element is"):
        code = "F003"
    else:
        code = "F002"
    rule = REGISTRY[code]
    return Finding(code, rule.severity, message, shown, line, 1 if line else 0, rule.fix)


class Locator:
    """File, line and column of a hit: in the parsed text, or, for a .xacro file, where the element
    was written: the top file, or the included file whose macro or text produced it."""

    def __init__(self, model, shown: str) -> None:
        self.model = model
        self.shown = shown
        self._source_text: str | None = None
        self._origins: dict[Any, Any] | None = None
        self._files: dict[str, str] = {}

    def locate(self, hit: Hit) -> tuple[str, int, int]:
        element = hit.element
        if element is None:
            return self.shown, hit.line, (1 if hit.line else 0)
        if not self.model.is_xacro:
            line = element.sourceline or 0
            return self.shown, line, (self.model.column_of(element) if line else 0)
        origins = self._element_origins()
        if origins:
            # The element itself, where its text was written (as for a .urdf); an element xacro
            # made itself takes its nearest ancestor's origin.
            node = element
            while node is not None:
                origin = origins.get(node)
                if origin is not None:
                    return self.shown_file(origin.file), origin.line, origin.column
                node = node.getparent()
        return (self.shown, *self._xacro_position(element))

    def _element_origins(self) -> dict[Any, Any]:
        """Each element of the expanded tree -> its :class:`~ar3cli.urdf.xacro_expand.Origin`
        (empty when the expansion's origins are unknown or do not match the tree)."""
        if self._origins is None:
            from ar3cli.urdf.xacro_expand import origins

            found = origins(self.model.xml_bytes) or []
            elements = [node for node in self.model.root.iter() if isinstance(node.tag, str)]
            self._origins = dict(zip(elements, found)) if len(found) == len(elements) else {}
        return self._origins

    def shown_file(self, file: str) -> str:
        """The display path of a file xacro read: the linted file as shown, an included one
        relative to the current directory (``a/../b`` folded when it is the same file)."""
        if file not in self._files:
            if file == str(self.model.path):
                shown = self.shown
            else:
                folded = os.path.normpath(file)
                try:
                    same = folded == file or os.path.samefile(folded, file)
                except OSError:
                    same = False
                shown = display_path(Path(folded if same else file))
            self._files[file] = shown
        return self._files[file]

    def _xacro_position(self, element) -> tuple[int, int]:
        """Position of the enclosing link/joint (by its name) in the xacro source; (0, 0) if ambiguous.
        Used only when the expansion's origins are unknown."""
        from ar3cli.urdf.xmlsource import decode_text

        if self._source_text is None:
            self._source_text = decode_text(self.model.source_bytes)
        node = _enclosing_link_or_joint(element)
        if node is element and not (node.tag in ("link", "joint") and node.get("name")):
            pattern = r"<robot\b"
        else:
            pattern = rf"""<{node.tag}\b[^>]*?\bname\s*=\s*["']{re.escape(node.get("name"))}["']"""
        found = list(re.finditer(pattern, self._source_text))
        if len(found) != 1:
            return 0, 0
        start = found[0].start()
        line = self._source_text.count("\n", 0, start) + 1
        return line, start - (self._source_text.rfind("\n", 0, start) + 1) + 1


def _enclosing_link_or_joint(element):
    """The named <link> or <joint> holding ``element`` (or being it); else ``element``."""
    node = element
    while node is not None and not (node.tag in ("link", "joint") and node.get("name")):
        node = node.getparent()
    return element if node is None else node


def _file_ignored(shown: str, code: str, options: LintOptions) -> bool:
    for pattern, codes in options.per_file_ignores.items():
        if (fnmatch.fnmatch(shown, pattern) or fnmatch.fnmatch(Path(shown).name, pattern)) and matches(code, codes):
            return True
    return False


def _file_level_ignores(model) -> list[str]:
    """The codes of the ``<!-- ar3cli: ignore-file[...] -->`` comments of the file: only in an XML
    comment, as documented (the same words in a name or a text were a way to silence a file), and
    in the file as written (a xacro's source, not its expansion)."""
    if not _FILE_LEVEL.search(model.source_bytes):
        return []
    codes: list[str] = []
    for comment in _comments(model):
        for match in _FILE_LEVEL.finditer((comment.text or "").encode("utf-8", "surrogateescape")):
            codes += _codes(match.group(1).decode("ascii", "replace") if match.group(1) is not None else None)
    return codes


def _comments(model) -> list[Any]:
    """Every comment of the file as written, those before and after its root element included."""
    from lxml import etree

    from ar3cli.urdf import xmlsource

    root = model.root
    if model.is_xacro:
        try:
            root, _ = xmlsource.parse(xmlsource.normalize(model.source_bytes)[0], model.path)
        except UserError:
            return []
    return [*root.itersiblings(etree.Comment, preceding=True), *root.iter(etree.Comment),
            *root.itersiblings(etree.Comment)]


def _codes(text: str | None) -> list[str]:
    """Codes listed in ``ignore[...]``; no list means every rule."""
    if text is None:
        return ["ALL"]
    return [code.strip().upper() for code in text.split(",") if code.strip()] or ["ALL"]


def suppressed_inline(element, code: str) -> bool:
    """True when the element or an ancestor holds a ``<!-- ar3cli: ignore[...] -->`` child comment.

    The ignore comments of the element's tree are gathered once (:class:`InlineIgnores`, kept for the
    last tree asked about), so each question walks only the element's ancestors: the 20,000 siblings
    of a star robot's root are not read again for every finding.
    """
    global _LAST_IGNORES
    root = element.getroottree().getroot()
    known = _LAST_IGNORES  # read once: another thread may be linting another tree
    if known is None or known.root is not root:
        known = _LAST_IGNORES = InlineIgnores(root)
    return known.suppresses(element, code)


class InlineIgnores:
    """The ``<!-- ar3cli: ignore[...] -->`` comments of one tree: element -> codes its comment children list."""

    def __init__(self, root) -> None:
        from lxml import etree

        self.root = root
        """Held so the tree (and the identity of its elements) lives as long as this index."""
        self.codes: dict[Any, list[str]] = {}
        for comment in root.iter(etree.Comment):
            match = _INLINE.search(comment.text or "")
            parent = comment.getparent()
            if match and parent is not None:
                self.codes.setdefault(parent, []).extend(_codes(match.group(1)))

    def suppresses(self, element, code: str) -> bool:
        node = element
        while node is not None:
            codes = self.codes.get(node)
            if codes is not None and matches(code, codes):
                return True
            node = node.getparent()
        return False


_LAST_IGNORES: InlineIgnores | None = None


def _override(finding: Finding, options: LintOptions) -> Finding:
    severity = options.severity.get(finding.rule)
    if severity is None or severity == finding.severity:
        return finding
    return Finding(finding.rule, severity, finding.message, finding.path, finding.line, finding.column, finding.hint)


GROUP_AT = 5
"""From this many findings of one rule in one file, alike but for names and numbers, the text
table shows one row for them (Talos: 93 G002 rows, one per mesh URI, become one). A few stay one
per row: three links without <inertial> are worth naming one by one."""
GROUP_LOCATIONS = 3
"""Locations a grouped row lists."""
_VARIABLE = re.compile(r"""'[^']*'|"[^"]*"|[^\s'"]*[/\\][^\s'"]*|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?""")
"""What differs between alike messages: quoted names and values, paths and URIs, numbers."""
_VARIABLES = re.compile(r"#(?:[\s,]+#)+")


@functools.lru_cache(maxsize=4096)
def message_shape(message: str) -> str:
    """``message`` with names, paths and numbers replaced by ``#`` (a run of them by one ``#``)."""
    return _VARIABLES.sub("#", _VARIABLE.sub("#", message))


@dataclass(frozen=True)
class FindingGroup:
    """Alike findings of one rule in one file, shown as one row of the text table."""

    findings: tuple[Finding, ...]

    @property
    def first(self) -> Finding:
        return self.findings[0]

    @property
    def message(self) -> str:
        """``93x: <first message> (and 92 more like it); at 31:9, 38:9, 54:9, ...`` (without the
        "and N more" when every message is the same)."""
        count = len(self.findings)
        text = f"{count}x: {self.first.message}"
        if any(finding.message != self.first.message for finding in self.findings):
            text += f" (and {count - 1} more like it)"
        places = [f"{f.line}:{f.column or 1}" for f in self.findings if f.line]
        if places:
            text += "; at " + ", ".join(places[:GROUP_LOCATIONS]) + (", ..." if len(places) > GROUP_LOCATIONS else "")
        return text


def group_findings(findings: list[Finding], at_least: int = GROUP_AT) -> list[Finding | FindingGroup]:
    """The rows of a text table: each finding, except that ``at_least`` or more findings with the
    same file, rule, severity and message and hint shapes (:func:`message_shape`) become one
    :class:`FindingGroup`, placed where the first of them was."""
    def key(finding: Finding) -> tuple:
        plain = (finding.path, finding.rule, finding.severity)
        if candidates[plain] < at_least:  # too few to group whatever their messages: no regex
            return plain
        return (*plain, message_shape(finding.message), message_shape(finding.hint))

    candidates = Counter((finding.path, finding.rule, finding.severity) for finding in findings)
    keys = [key(finding) for finding in findings]
    members: dict[tuple, list[Finding]] = {}
    for finding, finding_key in zip(findings, keys):
        members.setdefault(finding_key, []).append(finding)
    rows: list[Finding | FindingGroup] = []
    for finding, finding_key in zip(findings, keys):
        alike = members[finding_key]
        if len(alike) < at_least:
            rows.append(finding)
        elif alike[0] is finding:
            rows.append(FindingGroup(tuple(alike)))
    return rows


def summarize(results: list[LintResult], fail_on: Severity) -> dict[str, Any]:
    """Counts for the summary line and the JSON ``summary`` object (docs/commands/lint-urdf.md).

    ``error``/``warning``/``info`` count findings; ``files_with_errors`` the files with at least one
    error finding (so it is 0 exactly when ``error`` is); ``files_not_checked`` the files whose check
    was cut short (pybullet crashed: exit 2); ``files_clean`` the files fully checked with no finding
    at or above ``fail_on`` (what passes the gate: an info finding such as P003 leaves a file clean
    under the default ``--fail-on error``; ``scan`` calls the same files clean). ``failed`` is the
    verdict of the summary line: a finding at or above ``fail_on`` (``findings_failing``), or a file
    not checked. ``suppressed``
    counts the findings not reported by what suppressed them (:data:`SUPPRESSED_BY`), and
    ``severity_lowered`` those the configuration made less severe.
    """
    findings = [f for r in results for f in r.findings]
    counts = {level.value: sum(f.severity == level for f in findings) for level in Severity}
    failing = sum(f.severity >= fail_on for f in findings)
    not_checked = sum(r.error is not None for r in results)
    held = Counter(item.by for r in results for item in r.suppressed)
    return {"files": len(results), "files_with_findings": sum(bool(r.findings) for r in results),
            "files_with_errors": sum(any(f.severity is Severity.ERROR for f in r.findings) for r in results),
            "files_not_checked": not_checked,
            "files_clean": sum(r.error is None and not any(f.severity >= fail_on for f in r.findings)
                               for r in results),
            "findings": len(findings), **counts, "fail_on": fail_on.value, "findings_failing": failing,
            "failed": bool(failing or not_checked),
            "suppressed": {by: held[by] for by in SUPPRESSED_BY},
            "severity_lowered": sum(r.lowered for r in results)}


def find_rule(code: str) -> Rule:
    """The rule with this code (any case) or name; an unknown one is a one-line UserError."""
    wanted = code.strip()
    found = REGISTRY.get(wanted.upper()) or next((r for r in RULES if r.name == wanted.lower()), None)
    if found is None:
        raise UserError(f"unknown rule code {code!r} (codes look like F001 or J006; docs/rules.md lists them all)")
    return found


def rule_document(rule: Rule) -> dict[str, Any]:
    """Every documentation field of ``rule`` (whatever fields :class:`Rule` has, its ``check``
    aside), plus its family, docs anchor and section of docs/rules.md: what ``lint-urdf --explain``
    and the language server's hover show."""
    import dataclasses

    from ar3cli import RULES_DOC

    document: dict[str, Any] = {}
    for item in dataclasses.fields(rule):
        value = getattr(rule, item.name)
        if item.name == "check" or (callable(value) and not isinstance(value, (str, Severity))):
            continue
        document[item.name] = value.value if isinstance(value, Severity) else value
    document["family"] = rule.family
    document["anchor"] = rule.anchor
    document["doc"] = f"{RULES_DOC}#{rule.anchor}"
    return document
