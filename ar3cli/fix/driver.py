"""The plumbing shared by every fixer: load, plan edits, diff / check / write, report.

A fixer is a :class:`Fixer`: its command's name, a plan function ``(model, document, options) ->
FixPlan`` that queues byte splices on the :class:`~ar3cli.urdf.edits.Document` and records a
:class:`Change` for each field it changes (with old value, new value and where the new number came
from) and a :class:`Skipped` for each element it could not fix, and optionally a verify function
that checks the written file in PyBullet. Each ``fix/*_plan.py`` exports one as ``FIXER``.
:func:`run_fixer` does everything else the same way for all fixers, as the :class:`FixerArgs`
every fixer command takes ask: edits a xacro source where the fixer can (:attr:`Fixer.edits_xacro`;
:class:`~ar3cli.urdf.xacro_edits.XacroDocument`) and refuses it otherwise, builds the new bytes, checks they still parse,
prints a diff (``--diff``), reports (``--check``), or writes atomically in place or to ``-o``,
verifies the written file (``--verify``), and renders one table or one JSON document.
"""

from __future__ import annotations

import difflib
import functools
import math
from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Generic, TypeVar

from ar3cli.errors import EXIT_OK, EXIT_PROBLEMS, UserError
from ar3cli.infra.atomic import atomic_write, check_writable
from ar3cli.output.report import OutputFormat, Report, Table, printable, render_report
from ar3cli.urdf.edits import Document


@dataclass
class Change:
    """One changed field of one element."""

    element: str
    line: int
    field: str
    old: str | None
    new: str | None
    source: str


@dataclass
class Skipped:
    """An element that needed a fix but could not get one, and why."""

    element: str
    line: int
    reason: str


@dataclass
class FixPlan:
    """What a fixer did to one document; ``context`` is private data for its verify step."""

    changes: list[Change] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    context: dict[str, Any] = field(default_factory=dict)
    data: dict[str, Any] = field(default_factory=dict)
    """Extra per-file fields for the JSON output (e.g. fix-inertia's ``left_alone``)."""


Options = TypeVar("Options")
Verifier = Callable[[Any, FixPlan], dict[str, Any]]
"""``verify(model, plan)``: the written file's model and the plan that made it -> the verification
(``verified_in_pybullet``'s answer: ``verified`` and its ``checks`` rows)."""


@dataclass(frozen=True)
class Fixer(Generic[Options]):
    """What the driver needs of one fixer; each ``fix/*_plan.py`` exports one as ``FIXER``."""

    name: str
    """The command (``fix-joints``): the report's title and its JSON ``command``."""
    plan: Callable[[Any, Document, Options], FixPlan]
    """``plan(model, document, options)``: queue the splices on ``document``, say what changed and
    what was skipped; the options are the command's own (``JointsOptions``, ...)."""
    verify: Verifier | None = None
    """Checks the written file (in PyBullet); None when there is nothing a load could check."""
    options: type[Options] | None = field(default=None, kw_only=True)
    """The options dataclass: its :func:`~ar3cli.fix.settings.setting` fields are the command's own
    options, and the command builds it from their values (its ``__post_init__`` checks them and
    derives what the plan reads). A field named ``verify`` is the ``--verify`` switch."""
    help: str = field(default="", kw_only=True)
    """The command's ``--help``: its first line is the summary ``ar3cli --help`` lists."""
    timeout: float | None = field(default=None, kw_only=True)
    """The ``--timeout`` default of a fixer that starts a child process; None: no ``--timeout``."""
    session: Callable[[Options, FixerArgs], AbstractContextManager[FixerArgs]] | None = field(default=None,
                                                                                          kw_only=True)
    """Wraps the run, for a fixer that needs more than its options: it may adjust the shared
    arguments (it yields the ones to use) and clean up after the run, whatever its end."""
    edits_xacro: bool = field(default=False, kw_only=True)
    """The fixer edits text values (a URI, a limit) and asks :meth:`~ar3cli.urdf.edits.Document.refusal`
    before each edit, so it can fix a ``.xacro`` source where the value is literal text there; the
    others refuse xacro (their values are computed from the whole model)."""

    def run(self, options: Options, args: FixerArgs) -> int:
        """Run this fixer with ``options`` (an instance of :attr:`options`) on ``args``; the exit code."""
        session = self.session(options, args) if self.session is not None else nullcontext(args)
        with session as session_args:
            return run_fixer(self, options, session_args, verify=bool(getattr(options, "verify", False)))


@dataclass(frozen=True)
class FixerArgs:
    """What every fixer command is asked besides its own options: the files and where and how the
    result goes (``commands/fixer_options.py`` declares the options once)."""

    paths: list[Path]
    diff: bool = False
    check: bool = False
    output: Path | None = None
    follow_symlinks: bool = False
    package_path: list[str] | None = None
    format: OutputFormat = OutputFormat.text
    xacro_arg: list[str] | None = None
    xacro_trusted: bool = False
    xacro_env: list[str] | None = None

    def specs(self) -> tuple[dict, dict]:
        """(packages, xacro arguments) parsed, the xacro mode made this run's policy (UserError when malformed)."""
        from ar3cli.urdf.loading import read_specs

        return read_specs(self.package_path, self.xacro_arg, self.xacro_trusted, self.xacro_env)

    @property
    def writes(self) -> bool:
        """True unless --diff or --check: the fix is written (in place or to -o)."""
        return not self.diff and not self.check


@dataclass
class FixResult:
    path: Path
    plan: FixPlan
    changed: bool
    written: Path | None = None
    diff: str = ""
    verification: dict[str, Any] | None = None
    remaining: dict[str, Any] | None = None
    """What a static lint of the result still finds: counts per severity and the rule codes."""

    def to_dict(self) -> dict[str, Any]:
        data = {"path": str(self.path), "changed": self.changed,
                "written": str(self.written) if self.written else None,
                "changes": [asdict(c) for c in self.plan.changes],
                "skipped": [asdict(s) for s in self.plan.skipped], "notes": self.plan.notes,
                **self.plan.data}
        if self.verification is not None:
            data["verification"] = self.verification
        if self.remaining is not None:
            data["remaining"] = self.remaining
        if self.diff:
            data["diff"] = self.diff
        return data


def check_row(element: str, check: str, ok: bool, detail: str) -> dict[str, str]:
    """One row of a verifier's report: what was checked on which element, ok or fail, and why."""
    return {"element": element, "check": check, "status": "ok" if ok else "fail", "detail": detail}


def verified_in_pybullet(model: Any, checks: Callable[[], list[dict[str, str]]],
                         nothing_changed: bool = False) -> dict[str, Any]:
    """Run a verifier's ``checks()`` (pybullet work on the fixed file) in a contained child; when
    ``nothing_changed``, there is nothing to verify and pybullet is not started.

    A file pybullet cannot load, or crashes on, is one failed row as well as ``error`` (the text
    output shows the rows); the temporary file's path is left out of the message.
    """
    from ar3cli.sim.session import run_pybullet

    if nothing_changed:
        return {"verified": True, "checks": []}
    try:
        rows = run_pybullet(checks, model)
    except UserError as exc:
        message = exc.message.removeprefix(f"{model.path}: ")
        return {"verified": False, "checks": [check_row("(the file)", "loaded", False, message)], "error": message}
    return {"verified": all(row["status"] == "ok" for row in rows), "checks": rows}


def same_numbers(old: str | None, new: str, rel_tol: float, abs_tol: float = 0.0) -> bool:
    """True when the old attribute text already says the new numbers (so nothing is rewritten):
    same count of whitespace-separated numbers, each equal within the tolerances."""
    if old is None:
        return False
    try:
        a = [float(x) for x in old.split()]
        b = [float(x) for x in new.split()]
    except ValueError:
        return False
    return len(a) == len(b) and all(math.isclose(x, y, rel_tol=rel_tol, abs_tol=abs_tol) for x, y in zip(a, b))


def number(value: float) -> str:
    """A float as URDF text: exactly as typed when it is short (a yaml limit, a --mass), else 10
    significant digits (a computed number; far below any physical tolerance)."""
    if value == 0:
        return "0"
    text = repr(float(value))
    digits = text.lower().split("e")[0].replace("-", "").replace(".", "").strip("0")
    if len(digits) > 12:
        text = f"{value:.10g}"
    elif text.endswith(".0"):
        text = text[:-2]
    return "0" if text in ("-0", "0") else text


def refuse_xacro(fixer: Fixer, paths: list[Path]) -> None:
    """A fixer whose values are computed from the whole model (not :attr:`Fixer.edits_xacro`) refuses xacro."""
    from ar3cli.urdf.file_kind import is_xacro

    for path in paths:
        if is_xacro(path) and not fixer.edits_xacro:
            raise UserError(f"{path}: is a xacro file, and {fixer.name} computes values xacro may write from "
                            f"expressions, so it fixes URDF only. To see what to change in the .xacro: ar3cli expand "
                            f"{path.name} -o robot.urdf, then ar3cli {fixer.name} robot.urdf --diff; 'ar3cli "
                            "lint-urdf' reads the .xacro directly")


def run_fixer(fixer: Fixer[Options], options: Options, args: FixerArgs, verify: bool = False) -> int:
    """Run ``fixer`` with its ``options`` on every path of ``args`` and report; returns the exit code.

    Every file is loaded and planned before the first write: a bad second input stops the run
    with no file changed, instead of after the first one was rewritten. A symlinked input or
    ``-o`` is refused unless ``--follow-symlinks`` (see :func:`~ar3cli.infra.atomic.check_writable`);
    an in-place write is refused when the file changed since it was read. With ``verify`` (and a
    fixer that has a verify step), a fix whose PyBullet check fails is not written (see
    :func:`settle_verification`).
    """
    from ar3cli.urdf.model import load_model
    from ar3cli.urdf.xacro_edits import XacroDocument

    output = args.output
    verifier = fixer.verify if verify else None
    if not args.paths:
        raise UserError("give at least one file")
    if output is not None and len(args.paths) != 1:
        raise UserError("-o/--output takes exactly one input file")
    refuse_xacro(fixer, args.paths)
    packages, xacro_args = args.specs()
    planned: list[tuple[FixResult, bytes, Any]] = []
    for path in args.paths:
        model = load_model(path, packages, xacro_args)
        document = XacroDocument(model) if model.is_xacro else Document(model.source_bytes)
        document.bind(model.root)
        plan = fixer.plan(model, document, options)
        for item in (*plan.changes, *plan.skipped):
            item.line = document.user_line(item.line)
        new = document.apply()
        result = FixResult(path, plan, changed=new != model.source_bytes)
        if result.changed:
            _check_parses(path, new)
        if args.diff and result.changed:
            result.diff = unified_diff(path, model.source_bytes, new)
        if result.changed:  # a full lint of the result: in a child with the limits of every child
            from ar3cli.infra.isolation import run_limited

            result.remaining = run_limited(functools.partial(remaining_findings, path, new, packages, xacro_args),
                                           str(path), "linting the fixed file")
        planned.append((result, new, model))
    writing = args.writes
    if writing:
        for result, _, _ in planned:
            if result.changed or output is not None:
                check_writable(output or result.path, args.follow_symlinks)
    for result, new, original in planned:
        if not writing or not (result.changed or output is not None):
            continue
        target = output or result.path

        def validate(temp: Path, result: FixResult = result, original: Any = original, new: bytes = new) -> None:
            # a xacro is expanded from the new bytes in place of the file: its includes are found beside it
            new_model = load_model(result.path if original.is_xacro else temp, packages, xacro_args,
                                   source=new if original.is_xacro else None)
            if verifier is not None and result.plan.changes:
                result.verification = settle_verification(verifier(new_model, result.plan), original)
                if result.verification["status"] == "failed":
                    raise _VerificationFailed

        try:
            atomic_write(target, new, validate, follow_symlinks=args.follow_symlinks,
                         expect=original.source_bytes if output is None else None)
        except _VerificationFailed:
            continue
        result.written = target
    return _report(fixer.name, [result for result, _, _ in planned], diff=args.diff, check=args.check, fmt=args.format)


class _VerificationFailed(Exception):
    """Raised inside the atomic write's validation: the temporary file is removed, the target kept."""


def settle_verification(verification: dict[str, Any], original: Any) -> dict[str, Any]:
    """Give a verifier's answer its ``status``: ``verified`` (every row ok), ``failed`` (a row
    failed: the fix is not written), or ``not verified`` (pybullet cannot load the fixed file,
    and cannot load the original either: the fix did not break loading, it is written, and the
    output says it was not verified). The verdict always agrees with the rows."""
    if verification.get("verified"):
        return {**verification, "status": "verified"}
    if "error" not in verification:
        return {**verification, "status": "failed"}
    reason = pybullet_load_error(original)
    if reason is None:
        return {**verification, "status": "failed"}
    rows = [*verification["checks"], check_row("(the original)", "loaded", False, reason)]
    return {**verification, "checks": rows, "status": "not verified",
            "note": "PyBullet cannot load the original either: not verified"}


def pybullet_load_error(model: Any) -> str | None:
    """Why pybullet cannot load ``model`` (in a contained child), or None when it can."""
    from ar3cli.sim.session import run_pybullet

    def load() -> None:
        from ar3cli.sim.session import Session

        with Session() as session:
            session.load(model, visuals=False, allow_nan_frames=True)

    try:
        run_pybullet(load, model)
    except UserError as exc:
        return exc.message.removeprefix(f"{model.path}: ")
    return None


def remaining_findings(path: Path, data: bytes, packages: dict, xacro_args: dict) -> dict[str, Any]:
    """A static lint of the fixed bytes (nothing is written for it): what is left to do."""
    from ar3cli.lint.engine import LintOptions, lint_model
    from ar3cli.urdf.model import load_model

    options = LintOptions(package_paths=packages, xacro_args=xacro_args)
    findings = lint_model(load_model(path, packages, xacro_args, source=data), str(path), options.rules(), options).findings
    counts = {severity: sum(f.severity.value == severity for f in findings) for severity in ("error", "warning", "info")}
    return {**counts, "rules": sorted({f.rule for f in findings})}


def _check_parses(path: Path, data: bytes) -> None:
    from ar3cli.urdf import xmlsource

    normalized, _ = xmlsource.normalize(data)
    xmlsource.parse(normalized, path)  # raises UserError (a fixer bug) rather than writing junk


def _remaining_line(result: FixResult) -> str:
    left = result.remaining or {}
    if not left.get("rules"):
        return f"{result.path}: after the fix, ar3cli lint-urdf finds nothing"
    return (f"{result.path}: after the fix, ar3cli lint-urdf still finds {left['error']} error(s), "
            f"{left['warning']} warning(s), {left['info']} info ({', '.join(left['rules'])}); run it for details")


def unified_diff(path: Path, old: bytes, new: bytes, context: int = 3) -> str:
    """A unified diff like ``difflib.unified_diff``, matched without its "autojunk" heuristic: in a
    file over 200 lines difflib treats frequent lines (``</geometry>``) as junk and shows them as
    removed and added again, so a diff of 16 changes listed 41 removed lines (measured on kuka_iiwa)."""
    from ar3cli.urdf.xmlsource import decode_text

    a, b = decode_text(old).splitlines(keepends=True), decode_text(new).splitlines(keepends=True)
    lines = [f"--- {_diff_name('a', path)}\n", f"+++ {_diff_name('b', path)}\n"]
    for group in difflib.SequenceMatcher(None, a, b, autojunk=False).get_grouped_opcodes(context):
        first, last = group[0], group[-1]
        lines.append(f"@@ -{_hunk_range(first[1], last[2])} +{_hunk_range(first[3], last[4])} @@\n")
        for tag, i1, i2, j1, j2 in group:
            if tag == "equal":
                lines += [" " + line for line in a[i1:i2]]
                continue
            lines += ["-" + line for line in a[i1:i2]]
            lines += ["+" + line for line in b[j1:j2]]
    return "".join(lines) if len(lines) > 2 else ""


def _hunk_range(start: int, stop: int) -> str:
    """``start,length`` of a hunk, 1-based, as unified diffs write it (``start`` alone for one line)."""
    length = stop - start
    if length == 1:
        return str(start + 1)
    return f"{start + 1 if length else start},{length}"


def _diff_name(side: str, path: Path) -> str:
    """``a/urdf/robot.urdf`` for a relative path (as git writes it); an absolute path as it is. Shown
    as every name is (a newline in the name would end the header line)."""
    return printable(str(path) if Path(path).is_absolute() else f"{side}/{path}")


def _report(command: str, results: list[FixResult], *, diff: bool, check: bool, fmt: OutputFormat) -> int:
    needs_change = any(r.changed for r in results)
    skipped = any(r.plan.skipped for r in results)
    failed_verify = any(r.verification and r.verification.get("status", "verified") != "verified" for r in results)
    mode = "diff" if diff else "check" if check else "write"
    code = EXIT_PROBLEMS if skipped or failed_verify or (check and needs_change) else EXIT_OK
    data = {"command": command, "mode": mode, "ok": code == EXIT_OK,
            "files": [r.to_dict() for r in results]}
    rows, skipped_rows, verify_rows = [], [], []
    for r in results:
        for c in r.plan.changes:
            rows.append([str(r.path), c.element, c.line, c.field, c.old, c.new, c.source])
        for s in r.plan.skipped:
            skipped_rows.append([str(r.path), s.element, s.line, s.reason])
        for check_row in (r.verification or {}).get("checks", []):
            verify_rows.append([str(r.path), check_row["element"], check_row["check"], check_row["status"],
                                check_row["detail"]])
    verb = {"diff": "would change", "check": "would change", "write": "changed"}[mode]
    tables = [Table(f"ar3cli {command}: {verb}", ["file", "element", "line", "field", "old", "new", "source"], rows)]
    if skipped_rows:
        tables.append(Table("not fixed", ["file", "element", "line", "reason"], skipped_rows))
    if verify_rows:
        title = "verified in PyBullet" if all(row[3] == "ok" for row in verify_rows) else "checked in PyBullet: not verified"
        tables.append(Table(title, ["file", "element", "check", "status", "detail"], verify_rows,
                            status_column="status"))
    if len(results) == 1:  # the file is in the summary line; keep the table narrow
        for table in tables:
            table.columns, table.rows = table.columns[1:], [row[1:] for row in table.rows]
    lines = [note for r in results for note in r.plan.notes]
    for r in results:
        if not r.changed and r.plan.skipped:
            lines.append(f"{r.path}: nothing written ({len(r.plan.skipped)} element(s) not fixed, see above)")
        elif not r.changed:
            lines.append(f"{r.path}: nothing to change")
        elif r.written:
            lines.append(f"{r.path}: {len(r.plan.changes)} field(s) changed, written to {r.written}"
                         + (f"; {r.verification['note']}" if r.verification and r.verification.get("note") else ""))
        elif r.verification and r.verification.get("status") == "failed":
            lines.append(f"{r.path}: nothing written: the fixed file failed its check in PyBullet (see above)")
        else:
            lines.append(f"{r.path}: {len(r.plan.changes)} field(s) would change")
        if r.remaining is not None:
            lines.append(_remaining_line(r))
    patch = "".join(r.diff for r in results) if diff else ""
    render_report(Report(data=data, tables=[t for t in tables if t.rows], lines=lines, ok=code == EXIT_OK, text=patch,
                         quoted=True), fmt)
    return code
