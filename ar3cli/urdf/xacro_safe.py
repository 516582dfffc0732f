"""Safe mode for xacro: what a stranger's ``.xacro`` file may evaluate, read and see.

xacro runs ``${...}`` and ``$(eval ...)`` through Python's ``eval``, reads any file an include or
``load_yaml`` names, and hands out environment variables. While :func:`safe_hooks` is active:

- expressions go to :mod:`ar3cli.urdf.xacro_eval` (no attribute access to objects, no ``python.``
  namespace, bounded integers and strings): xacro's ``safe_eval`` and ``substitution_args._eval``
  are swapped for ours;
- ``load_yaml`` and includes read only files inside the :class:`ReadRoots` (the robot file's
  folder tree and its packages), through :func:`~ar3cli.infra.safe_read.read_bytes` (size cap,
  FIFOs and devices refused); YAML is parsed by ``yaml.safe_load``; an include pattern
  (``filename="parts/*.xacro"``) lists only inside them (:meth:`ReadRoots.glob`), and a file
  outside is refused whether or not it exists, so no answer tells what is there;
- ``$(cwd)`` (the folder ar3cli runs in) is refused;
- ``$(env X)`` and ``$(optenv X ...)`` are refused unless X was allowed with ``--xacro-env X``.
  ``$(optenv X default)`` is refused too rather than quietly taking the default: the robot would
  differ from the one the author's environment builds, with nothing said.

Whatever is refused raises a :class:`~ar3cli.errors.UserError` (noted in ``failures`` as well,
because xacro wraps what its hooks raise).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError
from ar3cli.urdf import xacro_eval
from ar3cli.urdf.xacro_eval import Function, Namespace


@dataclass(frozen=True)
class XacroPolicy:
    """How ``.xacro`` files are expanded: ``trusted`` runs xacro as it is (Python ``eval``, any file,
    any environment variable); otherwise safe mode, with ``env`` the variables files may read."""

    trusted: bool = False
    env: frozenset[str] = field(default_factory=frozenset)


class ReadRoots:
    """The folders a xacro expansion may read from: the robot file's folder (and below), the
    folder of each package given with ``--package-path``, the nearest ancestor package (a folder
    with a ``package.xml``), and each package ``$(find NAME)`` resolved to a folder with a
    ``package.xml`` (a bare ancestor folder that merely has the name, such as ``/home``, is no
    package and is not added)."""

    def __init__(self, robot_file: Path, package_folders: list[Path]) -> None:
        folder = Path(os.path.realpath(robot_file)).parent
        self.folders: list[str] = [str(folder)]
        for candidate in [folder, *folder.parents]:
            if (candidate / "package.xml").is_file():
                self.folders.append(str(candidate))
                break
        for package in package_folders:
            self.folders.append(os.path.realpath(package))

    def add_package(self, folder: Path) -> None:
        """A folder ``$(find NAME)`` answered: readable when it is a real package."""
        if (Path(folder) / "package.xml").is_file():
            self.folders.append(os.path.realpath(folder))

    def inside(self, filename: str) -> bool:
        """True when ``filename`` (symlinks resolved) lies inside a root."""
        real = os.path.realpath(filename)
        return any(real == root or real.startswith(root.rstrip(os.sep) + os.sep) for root in self.folders)

    def check(self, filename: str, verb: str = "read", shown: str | None = None) -> Path:
        """``filename`` (symlinks resolved) when it lies inside a root; UserError otherwise, naming
        ``shown`` (default ``filename``, as the file wrote it), whether or not anything is there."""
        if not self.inside(filename):
            raise UserError(f"xacro may not {verb} {shown or filename}: it is outside the robot's folder and packages "
                            f"(safe mode; pass --package-path NAME=DIR for a package, or {xacro_eval.SAFE_MODE_HINT})")
        return Path(os.path.realpath(filename))

    def glob(self, pattern: str) -> list[str]:
        """``glob.glob(pattern)`` for ``<xacro:include filename="...*...">``, without listing anything
        outside the roots: a pattern whose folder (the part before its first wildcard) lies outside,
        or that climbs out with ``..`` after a wildcard, is one refusal naming the pattern (decided
        by the pattern alone, so the answer says nothing about what is there); a match that leads
        outside through a symbolic link inside the tree is left out, as if it were not there."""
        import glob

        parts = pattern.split(os.sep)
        first = next(index for index, part in enumerate(parts) if glob.has_magic(part))
        folder = os.sep.join(parts[:first]) or (os.sep if pattern.startswith(os.sep) else os.curdir)
        if ".." in parts[first:]:  # climbs after a wildcard: names no single folder, refused
            raise UserError(f"xacro may not list {pattern}: a pattern may not climb with '..' after a wildcard "
                            f"(safe mode; {xacro_eval.SAFE_MODE_HINT})")
        self.check(folder, verb="list", shown=pattern)
        return [match for match in glob.glob(pattern) if self.inside(match)]


def read_inside(roots: ReadRoots, filename: str) -> bytes:
    """The bytes of an included file or YAML file, when the roots allow it: capped, no FIFO or device."""
    from ar3cli.infra.safe_read import read_bytes

    return read_bytes(roots.check(filename))


@contextlib.contextmanager
def safe_hooks(policy: XacroPolicy, roots: ReadRoots, failures: list[UserError]) -> Iterator[None]:
    """xacro's evaluation, YAML loading and environment lookups swapped for safe ones while active
    (the environment rule applies in trusted mode too when names were allowed; else trusted mode
    changes nothing here)."""
    import xacro
    from xacro import substitution_args

    def fail(exc: UserError) -> UserError:
        failures.append(exc)
        return exc

    class ListInside:
        """Stands for the ``glob`` module inside xacro: include patterns list only the roots."""

        @staticmethod
        def glob(pattern: str) -> list[str]:
            try:
                return roots.glob(pattern)
            except UserError as exc:
                raise fail(exc) from None

    def extension(text: str) -> Any:
        if text == "$(cwd)":  # the folder ar3cli runs in: where the runner keeps the checkout
            raise fail(UserError("$(cwd): xacro may not read the working folder's path in safe mode (it shows "
                                 "the layout outside the robot's folder); write paths relative to the file, or "
                                 f"{xacro_eval.SAFE_MODE_HINT}"))
        return original_extension(text)

    def read_env(name: str, default: str | None = None) -> str:
        if name not in policy.env:
            kind = "env" if default is None else "optenv"
            raise fail(UserError(f"$({kind} {name}): xacro may not read environment variables in safe mode; "
                                 f"pass --xacro-env {name} to allow it"))
        if default is None:
            return original_env(name)
        return os.environ.get(name, default)

    def load_yaml(filename: str) -> Any:
        from ar3cli.urdf.yamlfile import load_yaml as parse_yaml

        filename = xacro.abs_filename_spec(str(filename))
        try:
            read_inside(roots, filename)  # refuses outside files, FIFOs, devices and huge files first
            _add_unit_constructors()
            xacro.filestack.append(filename)
            try:
                data = parse_yaml(Path(filename), "YAML file")
            finally:
                xacro.filestack.pop()
        except UserError as exc:
            raise fail(exc) from None
        xacro.all_includes.append(filename)
        return xacro.YamlListWrapper.wrap(data)

    saved = (xacro.safe_eval, xacro.glob, xacro.eval_extension, substitution_args._eval, substitution_args._eval_env,
             substitution_args._eval_optenv)
    original_env, original_extension = substitution_args._eval_env, xacro.eval_extension
    if not policy.trusted:
        xacro_globals = _expression_globals(xacro, load_yaml)
        xacro.safe_eval = lambda expr, symbols, _locals=None: _evaluate(expr, symbols, xacro_globals, xacro.Table)
        xacro.glob = ListInside
        xacro.eval_extension = extension
        substitution_args._eval = _eval_substitution(substitution_args, read_env)
        substitution_args._eval_env = read_env
        substitution_args._eval_optenv = lambda name, default="": read_env(name, default)
    try:
        yield
    finally:
        (xacro.safe_eval, xacro.glob, xacro.eval_extension, substitution_args._eval, substitution_args._eval_env,
         substitution_args._eval_optenv) = saved


def _evaluate(expr: str, symbols: Any, known: dict[str, Any], table_type: type) -> Any:
    """``${expr}`` with xacro's lookup rules: a property in the innermost table that has it
    (evaluated lazily by xacro as usual), else one of safe mode's global names."""

    def member(table: Any, name: Any) -> Any:
        while isinstance(table, table_type):
            if dict.__contains__(table, name):
                return table._resolve_(name)
            table = table.parent
        if name in known:
            return known[name]
        raise KeyError(name)

    def lookup(name: str) -> Any:
        try:
            return member(symbols, name)
        except KeyError:
            raise NameError(f"name '{name}' is not defined") from None

    return xacro_eval.evaluate(expr, lookup, member)


_XACRO_DIRECT = ("list", "dict", "map", "len", "str", "float", "int", "bool", "True", "False", "min", "max", "round",
                 "sorted", "range")
"""The built-in names xacro exposes directly in ``${...}`` (the rest live in its ``python.`` namespace,
which safe mode does not offer)."""


def _expression_globals(xacro: Any, load_yaml: Callable[[str], Any]) -> dict[str, Any]:
    """The names ``${...}`` sees in safe mode: xacro's direct built-ins and math, and its ``math``
    and ``xacro`` namespaces with ``load_yaml`` routed to the safe loader."""
    original = xacro._global_symbols["xacro"]
    xacro_namespace = {
        "load_yaml": Function("load_yaml", load_yaml),
        "arg": Function("arg", lambda name: xacro.substitution_args_context["arg"][name]),
        "tokenize": Function("tokenize", xacro.tokenize),
        "dotify": Function("dotify", xacro.YamlDictWrapper),
        "abs_filename": Function("abs_filename", xacro.abs_filename_spec),
        **{name: Function(name, original[name]) for name in ("message", "warning", "error", "fatal", "print_location")
           if dict.__contains__(original, name)},
    }
    return {
        **{name: xacro_eval.BUILTINS[name] for name in _XACRO_DIRECT},
        **xacro_eval.MATH,
        "math": Namespace("math", xacro_eval.MATH),
        "xacro": Namespace("xacro", xacro_namespace),
        "load_yaml": xacro_namespace["load_yaml"],
        "abs_filename": xacro_namespace["abs_filename"],
        "dotify": xacro_namespace["dotify"],
    }


def _eval_substitution(substitution_args: Any, read_env: Callable[..., str]) -> Callable[[str, dict], str]:
    """``$(eval ...)`` on the safe evaluator, with the names roslaunch gives it: ``arg()``,
    ``dirname()``, ``find()``, ``env()``/``optenv()`` (under the environment rule), true/false, math,
    built-ins, and each argument by its name (converted as roslaunch does)."""

    def evaluate(text: str, context: dict) -> str:
        args = context.setdefault("arg", {})
        if "__" in text:
            raise substitution_args.SubstitutionException("$(eval ...) may not contain double underscore expressions")
        known: dict[str, Any] = {
            **xacro_eval.BUILTINS, **xacro_eval.MATH, "true": True, "false": False,
            "arg": Function("arg", lambda name: substitution_args.convert_value(
                substitution_args._eval_arg(name, args=args), "auto")),
            "dirname": Function("dirname", lambda: substitution_args._eval_dirname(context.get("filename"))),
            "find": Function("find", lambda name: substitution_args._eval_find(name)),
            "env": Function("env", lambda name: read_env(name)),
            "optenv": Function("optenv", lambda name, default="": read_env(name, default)),
        }

        def lookup(name: str) -> Any:
            if name in known:
                return known[name]
            if name in args:
                return substitution_args.convert_value(args[name], "auto")
            raise NameError(f"name '{name}' is not defined")

        return str(xacro_eval.evaluate(text, lookup))

    return evaluate


_units_added = False


def _add_unit_constructors() -> None:
    """xacro's ``!degrees``, ``!millimeters``... YAML tags, as its own ``load_yaml`` adds them (their
    values are evaluated by the patched, safe ``safe_eval``)."""
    global _units_added
    if _units_added:
        return
    import xacro
    import yaml

    for unit in xacro.ConstructUnits:
        yaml.SafeLoader.add_constructor(unit.value.tag, unit.constructor)
    _units_added = True
