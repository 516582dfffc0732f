"""Expand ``.xacro`` files with the ``xacro`` package, in a child process with limits.

Safe mode (the default) evaluates expressions without Python's ``eval`` and reads only the robot's
own files (:mod:`ar3cli.urdf.xacro_safe`); ``--xacro trusted`` runs xacro as it is. Either way
the expansion runs in a forked child with CPU, memory and wall-clock limits (:func:`expand`).

No ROS installation is needed: ``$(find NAME)`` is answered by the same
:class:`~ar3cli.urdf.packages.PackageResolver` that resolves ``package://`` URIs, and ``$(arg ...)``
values come from ``--xacro-arg NAME:=VALUE``. Whatever goes wrong inside xacro becomes a one-line
:class:`~ar3cli.errors.UserError` naming the file.

Each element of the expanded URDF remembers where it was written: xacro's parser is wrapped so that
every element it reads from the top file or an included file gets its file, line and column
(expat's). An element xacro may copy (inside a macro body or a block) carries them through the copy
as an ``ar3cli-origin`` attribute, so an element a macro produced points at the macro's file and
line; the attributes are taken off before the text is written, so the URDF is byte for byte what
xacro alone writes. :func:`origins` gives the linter each element's origin, in document order.
"""

from __future__ import annotations

import collections
import contextlib
import io
import os
import re
import weakref
from pathlib import Path
from typing import NamedTuple

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.infra.safe_read import MAX_FILE_BYTES
from ar3cli.output.report import log
from ar3cli.urdf.packages import PackageResolver, shown_places
from ar3cli.urdf.xacro_safe import ReadRoots, XacroPolicy, read_inside, safe_hooks


class Origin(NamedTuple):
    """Where an element of the expanded URDF was written: the xacro file as xacro named it
    (relative to the current directory, or absolute), 1-based line and column of its start tag."""

    file: str
    line: int
    column: int


ORIGIN_ATTRIBUTE = "ar3cli-origin"
"""The attribute that carries an element's origin through xacro (taken off before the output)."""
_KEEP_ORIGINS = 4
"""Expansions whose origins are kept in any case: a file is linted right after it is expanded."""


class Expansion:
    """What an expansion knows beyond its URDF: each element's origin and the files xacro read.
    A :class:`~ar3cli.urdf.model.Model` holds its own (``Model.expansion``), so :func:`origins`
    answers for every model still in use (an editor's open files), not only the last few."""

    __slots__ = ("found", "included", "digests", "__weakref__")

    def __init__(self, found: list[Origin | None], included: list[str], digests: dict[str, str]) -> None:
        self.found = found
        self.included = included
        self.digests = digests
        """Each xacro file parsed (as xacro named it) -> the SHA-256 of the bytes parsed."""


_origins: weakref.WeakValueDictionary[bytes, Expansion] = weakref.WeakValueDictionary()
_recent: collections.deque[Expansion] = collections.deque(maxlen=_KEEP_ORIGINS)


def expansion_of(xml_bytes: bytes) -> Expansion | None:
    """The :class:`Expansion` of bytes :func:`expand` returned (None for other bytes)."""
    return _origins.get(xml_bytes)


def origins(xml_bytes: bytes) -> list[Origin | None] | None:
    """The origin of each element of an expansion :func:`expand` returned, in document order
    (None for an element xacro made itself, such as ``xacro:element``); None for other bytes."""
    kept = _origins.get(xml_bytes)
    return kept.found if kept is not None else None


def set_policy(policy: XacroPolicy) -> None:
    """How the following expansions run (``--xacro``, ``--xacro-env``); set once by the command."""
    global _policy
    _policy = policy


def current_policy() -> XacroPolicy:
    """The policy :func:`expand` uses now (safe mode unless a command chose otherwise)."""
    return _policy


_policy = XacroPolicy()

WALL_SECONDS = 30
"""Wall-clock limit of one expansion; the largest real robot seen expands in under 2 s."""
CPU_SECONDS = 20
"""CPU-time limit of one expansion (``RLIMIT_CPU``)."""
MEMORY_BYTES = 1024 * 1024 * 1024
"""Address space an expansion may add to what the process already maps (``RLIMIT_AS``)."""


class _Expansion(NamedTuple):
    """What the child sends back: the URDF, its elements' origins, the files xacro read, xacro's
    chatter, and the SHA-256 of the bytes of each xacro file it parsed."""

    data: bytes
    found: list[Origin | None]
    included: list[str]
    notes: list[str]
    digests: dict[str, str]


def expand(path: Path, args: dict[str, str], resolver: PackageResolver, source: bytes | None = None) -> bytes:
    """Return the expanded URDF as UTF-8 bytes (and keep its elements' :func:`origins` and
    :func:`included_files`). ``source`` stands in for the bytes of ``path`` itself (an editor's
    unsaved buffer, or a fixer's result checked before it is written); the files it includes are read
    from disk as usual.

    The expansion runs in a forked child (:func:`~ar3cli.infra.isolation.run_isolated`) with CPU,
    memory and wall-clock limits, under the current policy (safe mode by default,
    :mod:`ar3cli.urdf.xacro_safe`): a hostile file costs at most :data:`WALL_SECONDS` and is one
    line. xacro is imported here first, so the child does not import it again.
    """
    import xacro  # noqa: F401 - imported before the fork: every expansion's child has it

    from ar3cli.infra.isolation import CrashError, run_isolated

    policy, parent = _policy, os.getpid()

    def work() -> _Expansion:
        if os.getpid() != parent:  # in the child (where fork is missing, the work runs here: no limits)
            _limit_this_process()
        return _expand_here(path, args, resolver, policy, source)

    try:
        result = run_isolated(work, str(path))
    except CrashError as exc:
        if exc.signal_name in ("SIGALRM", "SIGXCPU", "SIGKILL"):
            raise UserError(f"{path}: xacro error: expansion stopped at its limit of {WALL_SECONDS} s "
                            f"({CPU_SECONDS} s of CPU): a macro that calls itself many times?") from None
        raise UserError(f"{path}: xacro error: the expansion died ({exc.signal_name})") from None
    for line in result.notes:
        log(f"ar3cli: note: {path}: xacro says: {line}")
    kept = Expansion(result.found, result.included, result.digests)
    _origins[result.data] = kept
    _recent.append(kept)
    return result.data


def included_files(xml_bytes: bytes) -> list[str]:
    """The files xacro read (includes, YAML) for an expansion :func:`expand` returned, as xacro named them."""
    kept = _origins.get(xml_bytes)
    return list(kept.included) if kept is not None else []


def parsed_digests(xml_bytes: bytes) -> dict[str, str]:
    """For an expansion :func:`expand` returned: each xacro file it parsed (as xacro named it, as
    :class:`Origin` names it) -> the SHA-256 of the bytes parsed. What may be shown of those files
    is exactly these bytes (a page's cited lines are checked against them)."""
    kept = _origins.get(xml_bytes)
    return dict(kept.digests) if kept is not None else {}


def _limit_this_process() -> None:
    """In the expansion's child: die by SIGALRM after :data:`WALL_SECONDS`, SIGXCPU after
    :data:`CPU_SECONDS` of CPU, get MemoryError past :data:`MEMORY_BYTES` more address space."""
    import resource
    import signal

    signal.signal(signal.SIGALRM, signal.SIG_DFL)
    signal.alarm(WALL_SECONDS)
    with contextlib.suppress(ValueError, OSError):
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        resource.setrlimit(resource.RLIMIT_CPU, (CPU_SECONDS, CPU_SECONDS + 1))
        with open("/proc/self/statm") as handle:
            mapped = int(handle.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
        hard = resource.getrlimit(resource.RLIMIT_AS)[1]
        wanted = mapped + MEMORY_BYTES
        resource.setrlimit(resource.RLIMIT_AS, (wanted if hard == resource.RLIM_INFINITY else min(wanted, hard), hard))


def _expand_here(path: Path, args: dict[str, str], resolver: PackageResolver, policy: XacroPolicy,
                 source: bytes | None = None) -> _Expansion:
    """The expansion itself, in this process.

    xacro keeps module-level state and prints diagnostics with ``print``; both are contained
    here: its ``$(find)`` hook and its ``parse`` are swapped for ours (and, in safe mode, its
    evaluation, YAML loading and environment lookups: :func:`~ar3cli.urdf.xacro_safe.safe_hooks`)
    for the duration of the call, and anything it prints is kept off stdout (stdout may be
    carrying JSON).
    """
    import xacro
    from xacro import substitution_args

    failures: list[UserError] = []  # xacro wraps what the hooks raise; keep ours to re-raise them as they are
    roots = ReadRoots(path, list(resolver.package_paths.values()))

    def find_package(name: str) -> str:
        folder, tried = resolver.find_package(name)
        if folder is None:
            failures.append(UserError(f"{path}: $(find {name}): package not found; tried "
                                      f"{', '.join(shown_places(tried, resolver.base_dir))}; "
                                      f"pass --package-path {name}=DIR"))
            raise failures[-1]
        roots.add_package(folder)
        return str(folder)

    table: list[Origin] = []
    kept: dict = {}
    digests: dict[str, str] = {}
    original_find, original_parse = substitution_args._eval_find, xacro.parse
    substitution_args._eval_find = find_package
    xacro.parse = _parse_with_origins(original_parse, table, kept, None if policy.trusted else roots, digests,
                                      {str(path): source} if source is not None else {})
    chatter = io.StringIO()
    included_before = len(xacro.all_includes)
    try:
        with contextlib.redirect_stdout(chatter), contextlib.redirect_stderr(chatter), \
                safe_hooks(policy, roots, failures):
            document = xacro.process_file(str(path), mappings=dict(args))
            found = _take_origins(document, table, kept)
            _inert_banner(document)
            text = document.toprettyxml(indent="  ")
    except UserError as exc:
        raise _located(exc, path) from None
    except Exception as exc:  # noqa: BLE001 - xacro raises many types: XacroException, NameError, XML errors...
        if failures:
            raise _located(failures[-1], path) from None
        if _caused_by(exc, MemoryError):
            raise UserError(f"{path}: xacro error: the expansion needs more than {MEMORY_BYTES >> 20} MB "
                            "of memory") from None
        if isinstance(exc, RecursionError):
            raise UserError(f"{path}: xacro error: macro recursion too deep") from None
        known = _arg_without_default(path, exc) or _package_uri_include(path, exc, resolver)
        if known:
            raise UserError(f"{path}: xacro error: {known}") from None
        raise UserError(f"{path}: xacro error: {_one_line(exc)}{_arguments_hint(path, args)}") from None
    finally:
        substitution_args._eval_find = original_find
        xacro.parse = original_parse
    data = text.encode("utf-8")
    if len(data) > MAX_FILE_BYTES:
        raise UserError(f"{path}: xacro error: the expanded URDF is {len(data) / 1e6:.0f} MB, larger than the "
                        f"{MAX_FILE_BYTES >> 20} MB limit for robot descriptions")
    notes = [line.strip() for line in chatter.getvalue().splitlines()
             if line.strip() and not line.startswith("when processing file:")]
    return _Expansion(data, found, [str(name) for name in xacro.all_includes[included_before:]], notes, digests)


def _inert_banner(document) -> None:
    """xacro's banner comment names the file: a name holding a control character (ESC, which XML
    forbids even in a comment) or a byte that is not UTF-8 would make the expanded URDF unreadable
    (a false F002) or unencodable. Shown as every name is; a plain name leaves it byte for byte."""
    from ar3cli.output.report import printable

    for node in document.childNodes:
        if node.nodeType == node.COMMENT_NODE and "autogenerated by xacro from" in node.data:
            node.data = printable(node.data)


def _located(exc: UserError, path: Path) -> UserError:
    """A refusal from a hook, naming the linted file (and, when it is another, the file xacro was reading)."""
    if exc.message.startswith(f"{path}:"):
        return exc
    location = _xacro_location()
    where = f" (in {location})" if location and location != str(path) else ""
    return UserError(f"{path}: xacro error: {exc.message}{where}", exc.exit_code)


def _caused_by(exc: BaseException, kind: type[BaseException]) -> bool:
    seen: set[int] = set()
    stack: list[BaseException | None] = [exc]
    while stack:
        item = stack.pop()
        if item is None or id(item) in seen:
            continue
        seen.add(id(item))
        if isinstance(item, kind):
            return True
        stack += [getattr(item, "exc", None), item.__cause__, item.__context__]
    return False


_ARG_DECLARATION = re.compile(r"<xacro:arg\b[^>]*?\bname\s*=\s*[\"']([^\"']+)[\"']")
_ARG_USE = re.compile(r"\$\(arg\s+([^\s)]+)\s*\)")


_ARG_TAG = re.compile(r"<xacro:arg\b[^>]*>")


def _arg_without_default(path: Path, exc: BaseException) -> str:
    """For xacro's "xacro:arg: missing attribute 'default'": which ``<xacro:arg>`` lacks it (file:line)
    and the true fix. xacro requires a default even for an argument given on its command line (or with
    --xacro-arg), so passing the argument cannot help; "" for any other error."""
    from ar3cli.infra.safe_read import read_bytes

    if "xacro:arg: missing attribute 'default'" not in str(exc):
        return ""
    where = Path(_xacro_location() or path)
    try:
        text = read_bytes(where).decode("utf-8", "replace")
    except UserError:
        text = ""
    for match in _ARG_TAG.finditer(text):
        if not re.search(r"\bdefault\s*=", match.group(0)):
            names = _ARG_DECLARATION.findall(match.group(0))
            line = text.count("\n", 0, match.start()) + 1
            return (f"<xacro:arg name=\"{names[0] if names else '?'}\"> at {where}:{line} has no default: xacro needs "
                    "one even when the argument is given (--xacro-arg NAME:=VALUE does not help); add "
                    "default=\"...\" to it")
    return (f"an <xacro:arg> has no default (in {where}): xacro needs one even when the argument is given; "
            "add default=\"...\" to it")


_INCLUDE_TAG = re.compile(r"<xacro:include\b[^>]*?\bfilename\s*=\s*[\"'](package://([^/\"']+)/?([^\"']*))[\"']")


def _package_uri_include(path: Path, exc: BaseException, resolver: PackageResolver) -> str:
    """For an ``<xacro:include filename="package://...">`` (xacro reads it as a relative file name and
    fails): where it is (file:line) and the spelling xacro resolves, ``$(find PKG)/...``, saying so when that
    file does not exist either (hector's include names a urdf/ folder its package does not have); "" otherwise."""
    from ar3cli.infra.safe_read import read_bytes

    inner = getattr(exc, "exc", None)
    if not (isinstance(inner, OSError) and "package://" in str(inner.filename or "")):
        return ""
    where = Path(_xacro_location() or path)
    try:
        text = read_bytes(where).decode("utf-8", "replace")
    except UserError:
        return ""
    for match in _INCLUDE_TAG.finditer(text):
        if match.group(1) in str(inner.filename):
            line = text.count("\n", 0, match.start()) + 1
            missing = "" if resolver.resolve(match.group(1)).found else " (no such file there either: check the path)"
            return (f"<xacro:include filename=\"{match.group(1)}\"> at {where}:{line}: xacro does not resolve package:// "
                    f"in includes (it reads it as a relative file name); write $(find {match.group(2)})/{match.group(3)}"
                    f"{missing}")
    return ""


def _arguments_hint(path: Path, given: dict[str, str]) -> str:
    """When the file takes xacro arguments the user did not give: which, and how to give them."""
    from ar3cli.infra.safe_read import read_bytes

    try:
        text = read_bytes(path).decode("utf-8", "replace")
    except UserError:
        return ""
    names = [name for name in dict.fromkeys(_ARG_DECLARATION.findall(text) + _ARG_USE.findall(text))
             if name not in given]
    if not names:
        return ""
    shown = listed(names, 8)
    return f"; the file takes xacro arguments ({shown}): pass the ones it needs with --xacro-arg NAME:=VALUE"


def _parse_with_origins(original_parse, table: list[Origin], kept: dict, roots: ReadRoots | None,
                        digests: dict[str, str], sources: dict[str, bytes] | None = None):
    """xacro's ``parse(inp, filename)``, noting the origin of each element read from a file.

    The file is read as xacro reads it (text, default encoding) and parsed by the builder
    ``xml.dom.minidom.parse`` uses, so the document and every error are the same. An element inside
    a xacro element (a macro body, a block passed to a macro, a property's block) may be copied by
    xacro, so it carries its origin as an attribute (its index in ``table``); every other element
    stays the same node up to the output, and ``kept`` maps it to its origin (no attribute for
    xacro to evaluate: 3 ms less on the AR3). xacro's own elements are left alone (xacro checks
    their attributes); inside ``xacro:if``/``xacro:unless`` nodes are moved, never copied.
    With ``roots`` (safe mode), an existing file is read only inside them, through the capped reader.
    ``digests`` receives the SHA-256 of each file's bytes, by the name its elements' origins carry;
    ``sources`` maps a file name as xacro names it to the bytes that stand in for the file.
    """
    import hashlib
    import locale
    from xml.dom import expatbuilder

    class Builder(expatbuilder.ExpatBuilderNS):
        def __init__(self, file: str) -> None:
            super().__init__()
            self.file = file
            self.copied = 0  # depth inside xacro elements whose content xacro may copy
            self.copying: list[bool] = []

        def start_element_handler(self, name, attributes):
            # name is "URI LOCALNAME PREFIX" for a prefixed element
            if name.endswith(" xacro"):
                super().start_element_handler(name, attributes)
                copies = name.split(" ")[1] not in ("if", "unless")
            else:
                parser = self._parser
                origin = Origin(self.file, parser.CurrentLineNumber, parser.CurrentColumnNumber + 1)
                if self.copied:
                    attributes.append(ORIGIN_ATTRIBUTE)  # expat's flat list of names and values
                    attributes.append(str(len(table)))
                    table.append(origin)
                    super().start_element_handler(name, attributes)
                else:
                    super().start_element_handler(name, attributes)
                    kept[self.curNode] = origin
                copies = False
            self.copying.append(copies)
            self.copied += copies

        def end_element_handler(self, name):
            self.copied -= self.copying.pop()
            super().end_element_handler(name)

    def parse(inp, filename=None):
        import xacro

        if inp is not None or filename is None:
            return original_parse(inp, filename)
        full = os.path.join(getattr(xacro, "root_dir", os.curdir), filename)
        if sources and str(filename) in sources:
            digests[str(filename)] = hashlib.sha256(sources[str(filename)]).hexdigest()
            return Builder(str(filename)).parseString(sources[str(filename)].decode("utf-8", "replace"))
        if roots is not None:
            roots.check(full)  # outside: refused whether or not something is there
        if roots is not None and os.path.lexists(full):
            data = read_inside(roots, full)
            digests[str(filename)] = hashlib.sha256(data).hexdigest()
            text = data.decode(locale.getpreferredencoding(False))  # as open() decodes
            return Builder(str(filename)).parseString(text)
        try:
            with open(full) as handle:
                text = handle.read()
        except OSError:
            return original_parse(inp, filename)  # raises xacro's own error, with its file stack
        with contextlib.suppress(UserError):  # trusted mode: the same file's bytes, through the capped reader
            from ar3cli.infra.safe_read import read_bytes

            digests[str(filename)] = hashlib.sha256(read_bytes(Path(full))).hexdigest()
        return Builder(str(filename)).parseString(text)

    return parse


def _take_origins(document, table: list[Origin], kept: dict) -> list[Origin | None]:
    """Each element's origin in document order; the origin attributes are removed from the document."""
    found: list[Origin | None] = []
    stack = [document.documentElement] if document.documentElement is not None else []
    while stack:
        node = stack.pop()
        origin = kept.get(node)
        if origin is None:
            attribute = node.getAttributeNode(ORIGIN_ATTRIBUTE)
            if attribute is not None:
                node.removeAttributeNode(attribute)
                index = attribute.value
                origin = table[int(index)] if index.isdigit() and int(index) < len(table) else None
        found.append(origin)
        stack.extend(reversed([child for child in node.childNodes if child.nodeType == 1]))  # ELEMENT_NODE
    return found


def _one_line(exc: BaseException) -> str:
    inner = getattr(exc, "exc", None)  # XacroException wraps the real error and repeats its text
    if isinstance(inner, OSError) and inner.filename:
        message = f"cannot read {inner.filename}: {inner.strerror or inner}"
    else:
        message = " ".join(str(exc).split()) or type(exc).__name__
    location = _xacro_location()
    return f"{message} (in {location})" if location else message


def _xacro_location() -> str:
    """The innermost file xacro was reading when it failed, when xacro recorded one."""
    try:
        import xacro

        stack = [entry for entry in getattr(xacro, "filestack", None) or [] if entry]
    except Exception:  # noqa: BLE001 - defensive: xacro internals differ between versions
        return ""
    return str(stack[-1]) if stack else ""
