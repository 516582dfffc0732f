"""One robot, loaded once, and every answer about it: :class:`RobotAnalysis` and :func:`question`.

A :class:`RobotAnalysis` is a snapshot: the robot file (or an editor's buffer standing in for it)
read and expanded once into a :class:`~ar3cli.urdf.model.Model`, with the
:class:`~ar3cli.analysis.settings.AnalysisSettings` it is checked with. It never changes; when a
file changes, :meth:`RobotAnalysis.reloaded` makes the next snapshot, and the caller decides which
one to show (a viewer keeps the last good robot on screen while the file does not parse).

Questions are plain functions of an analysis decorated with :func:`question`: the first call
computes the answer, later calls (from any thread: a viewer's callbacks, an editor's server) get
the same object, and two threads asking at once wait for one computation. A question that cannot be
answered raises :class:`~ar3cli.errors.UserError` (a pybullet crash, no collision geometry, a
robot that did not load), and that error is remembered as an answer is. Questions live in their
own modules (``findings``, ``facts``, ``pictures``, ``collisions``, ``kinematics``,
``cross_check``, ``verdict``) and a new one is a new function anywhere above this layer's
features: nothing lists them.

Work that must stay alive across questions (a pybullet child kept open while a viewer's sliders
move) is a resource: :meth:`RobotAnalysis.keep` opens it once per analysis and
:meth:`RobotAnalysis.close` closes it (``with RobotAnalysis.load(...) as analysis:`` does too).
"""

from __future__ import annotations

import functools
import os
import threading
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

from ar3cli.analysis.dependencies import Dependencies, of_load, robot_file_state
from ar3cli.analysis.settings import AnalysisSettings
from ar3cli.errors import UserError
from ar3cli.urdf.model import Model

if TYPE_CHECKING:
    from ar3cli.lint.reuse import Carry, Reuse
    from ar3cli.urdf.model_edit import Edit

T = TypeVar("T")
Q = TypeVar("Q", bound=Callable[..., Any])


class Closable(Protocol):
    def close(self) -> None: ...


@dataclass
class _Slot:
    """One answer: computed once under its own lock (two threads asking wait for one computation)."""

    lock: threading.RLock = field(default_factory=threading.RLock)
    done: bool = False
    value: Any = None
    error: UserError | None = None


class RobotAnalysis:
    """One load of one robot file and the answers computed from it.

    Build it with :meth:`load`. ``model`` is None when the file did not load; ``load_error`` then
    says why (the one-line error every command prints), :meth:`require_model` raises it, and the
    lint questions answer with the F finding lint-urdf reports for such a file.
    """

    def __init__(self, path: Path, settings: AnalysisSettings, source: bytes | None, model: Model | None,
                 load_error: UserError | None, dependencies: Dependencies) -> None:
        self.path = path
        self.settings = settings
        self.source = source
        """The bytes that stood in for the file (an editor's buffer), None when it was read from disk."""
        self.model = model
        self.load_error = load_error
        self.dependencies = dependencies
        self.edit: Edit | None = None
        """How the model was made from the earlier analysis' (an editor's keystroke), or None: a load."""
        self.lint_reuse: Reuse | None = None
        """The earlier check's work the static findings may reuse (:mod:`ar3cli.lint.reuse`), until they are asked."""
        self.lint_carry: Carry | None = None
        """What the static findings leave for the check after the next edit (with ``load(..., editing=True)``)."""
        self.editing = False
        """Loaded for an editor: the next buffer is expected to be an edit of this one."""
        self._answers: dict[Hashable, _Slot] = {}
        self._resources: list[Closable] = []
        self._lock = threading.Lock()
        self._closed = False

    # ---- loading -------------------------------------------------------------------------------
    @classmethod
    def load(cls, path: str | Path, settings: AnalysisSettings | None = None, text: str | bytes | None = None,
             earlier: RobotAnalysis | None = None, editing: bool = False) -> RobotAnalysis:
        """Read ``path`` (URDF or xacro) with ``settings``, or analyse ``text`` as its content (an
        unsaved buffer: ``package://``, relative meshes and xacro includes still start at ``path``).

        Bad input never raises: a file that does not load is an analysis without a model. The same
        limits as lint apply: the capped reader (and the same cap on ``text``), no entities, xacro in
        the process's policy (safe mode unless the front-end chose trusted) in a limited child.
        ``earlier`` is the analysis this one replaces: a load that fails keeps watching its files.
        ``editing`` (an editor's buffer, checked again on each keystroke): when ``text`` is ``earlier``'s with
        its elements kept (a value, a line break, an indent, a comment changed) and no file it read changed
        since, the model is made from ``earlier``'s (:func:`~ar3cli.urdf.model_edit.edited`, which consumes it)
        and the static findings reuse ``earlier``'s work (:mod:`ar3cli.lint.reuse`); the same model and
        findings as a load.
        """
        from ar3cli.infra.safe_read import MAX_FILE_BYTES
        from ar3cli.urdf.model import load_model

        path = Path(path)
        settings = settings or AnalysisSettings()
        source = text.encode("utf-8") if isinstance(text, str) else text
        robot_file = robot_file_state(path) if source is None else {}
        model, error = None, None
        if editing and earlier is not None and source is not None and len(source) <= MAX_FILE_BYTES:
            try:
                edited = cls._edited(path, settings, source, earlier)
            except Exception:  # noqa: BLE001 - a bug in the shortcut costs its speed, never the check: load in full
                edited = None
            if edited is not None:
                return edited
        try:
            if source is not None and len(source) > MAX_FILE_BYTES:
                raise UserError(f"{path}: {len(source) / 1e6:.0f} MB, larger than the {MAX_FILE_BYTES >> 20} MB "
                                "limit for robot descriptions")
            model = load_model(path, settings.packages, settings.xacro_args, source=source)
        except UserError as exc:
            error = exc
        except RecursionError:
            error = UserError(f"{path}: document nested too deeply to parse")
        analysis = cls(path, settings, source, model, error, of_load(path, model, robot_file,
                                                                     earlier.dependencies if earlier else None))
        analysis.editing = editing
        return analysis

    @classmethod
    def _edited(cls, path: Path, settings: AnalysisSettings, source: bytes,
                earlier: RobotAnalysis) -> RobotAnalysis | None:
        """The analysis of ``source`` made from ``earlier``'s model by :func:`~ar3cli.urdf.model_edit.edited`, or
        None (another file, other settings, a file it read changed, or not an edit that function takes)."""
        from ar3cli.lint.reuse import Reuse
        from ar3cli.urdf.model_edit import edited

        if earlier.model is None or earlier.path != path or earlier.settings is not settings or earlier.changed():
            return None
        edit = edited(earlier.model, source)
        if edit is None:
            return None
        analysis = cls(path, settings, source, edit.model, None, of_load(path, edit.model, {}, earlier.dependencies))
        analysis.edit, analysis.editing = edit, True
        if earlier.lint_carry is not None:
            analysis.lint_reuse = Reuse(earlier.lint_carry, edit)
        return analysis

    def require_model(self) -> Model:
        """The model; the load's one-line error (exit 2) when the file did not load."""
        if self.model is None:
            raise self.load_error or UserError(f"{self.path}: not loaded")
        return self.model

    def changed(self) -> list[Path]:
        """The files this load depended on that changed since (empty: nothing to reload)."""
        return self.dependencies.changed()

    def reloaded(self, text: str | bytes | None = None) -> RobotAnalysis:
        """A new analysis of the same path and settings (from disk, or from ``text``). This one
        stays as it was, answers and resources included: close it when it is no longer shown."""
        return RobotAnalysis.load(self.path, self.settings, text, earlier=self)

    # ---- answers -------------------------------------------------------------------------------
    def answer(self, key: Hashable, compute: Callable[[], T]) -> T:
        """The answer stored under ``key``, computed by ``compute()`` the first time (a UserError
        it raises is stored and raised again). :func:`question` calls this; call it directly for an
        answer that is not a function of the analysis alone."""
        with self._lock:
            slot = self._answers.setdefault(key, _Slot())
        with slot.lock:
            if not slot.done:
                try:
                    slot.value = compute()
                except UserError as exc:
                    slot.error = exc
                slot.done = True
        if slot.error is not None:
            raise slot.error
        return slot.value

    def answered(self, key: Hashable) -> bool:
        """Whether ``key`` has been answered already (a page can show what is there, cheaply)."""
        slot = self._answers.get(key)
        return slot is not None and slot.done

    def keep(self, key: Hashable, open_resource: Callable[[], T]) -> T:
        """A resource opened once per analysis (``open_resource()``, an object with ``close()``),
        closed by :meth:`close`. A closed analysis opens none (RuntimeError)."""
        def opened() -> T:
            if self._closed:
                raise RuntimeError(f"{self.path}: the analysis is closed")
            resource = open_resource()
            with self._lock:
                self._resources.append(resource)  # type: ignore[arg-type]
            return resource

        return self.answer(("resource", key), opened)

    def close(self) -> None:
        """Close the resources :meth:`keep` opened, newest first; answers stay readable."""
        with self._lock:
            self._closed = True
            resources, self._resources = self._resources[::-1], []
        for resource in resources:
            resource.close()

    def __enter__(self) -> RobotAnalysis:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    @property
    def shown_path(self) -> str:
        """The path as findings name it (relative to the current directory when below it)."""
        from ar3cli.lint.engine import display_path

        return display_path(self.path)

    def __repr__(self) -> str:
        state = "loaded" if self.model is not None else f"not loaded: {self.load_error}"
        return f"RobotAnalysis({os.fspath(self.path)!r}, {state}, {len(self._answers)} answers)"


def question(function: Q) -> Q:
    """Make ``function(analysis, *args)`` a question: answered once per analysis and arguments
    (hashable), from any thread. The undecorated function is ``.compute``."""
    name = f"{function.__module__}.{function.__qualname__}"

    @functools.wraps(function)
    def asked(analysis: RobotAnalysis, *args: Hashable) -> Any:
        return analysis.answer((name, args), lambda: function(analysis, *args))

    asked.compute = function  # type: ignore[attr-defined]
    return asked  # type: ignore[return-value]
