"""The robot files open in the editor, their latest checks, and the diagnostics of every file they touch.

A diagnostic belongs to a file, and several checks may speak of one file: a xacro macro file is
included by the open robot files that use it, and the findings each of them locates there are
published on it together (:meth:`Documents.diagnostics_for`). A file that an open document includes
is checked through it (expanded alone, a macro file says nothing useful), so its own check is
dropped once an includer's check names it, and redone when the last includer closes.

Memory stays bounded over a long day: a closed document is forgotten with its analysis, and only
the :data:`KEPT_ANALYSES` most recently used documents keep their analysis (the model, for hover,
definitions and fixes); the others keep their diagnostics and are analysed again when asked.
Everything here runs on the server's event loop thread; the checks themselves run elsewhere and
are handed in finished (:meth:`Documents.record`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ar3cli.server.checks import Checked
from ar3cli.server.diagnostics import key, problem

if TYPE_CHECKING:
    from lsprotocol import types

    from ar3cli.analysis.robot import RobotAnalysis

KEPT_ANALYSES = 8
"""Open documents that keep their analysis (the most recently used ones). A 300-link robot's model
is a few MB; an editing day opens dozens of files and works in a few."""


@dataclass
class Document:
    """One open robot file."""

    uri: str
    path: Path
    checked: Checked | None = None
    """The latest check whose diagnostics are published."""
    loaded: RobotAnalysis | None = None
    """The latest analysis that loaded (hover, definitions and the outline keep working while the
    buffer is half-typed and does not parse)."""
    sim: tuple[int | None, dict[str, list[types.Diagnostic]]] | None = None
    """The PyBullet rules' diagnostics and the version they were made for (the saved one)."""
    used: int = 0
    released: bool = False
    """Its analysis was let go to bound memory (a feature asking for it makes it again)."""


@dataclass
class Documents:
    """The open robot files, by URI."""

    open: dict[str, Document] = field(default_factory=dict)
    _clock: itertools.count = field(default_factory=itertools.count)

    def add(self, uri: str, path: Path) -> Document:
        document = self.open.get(uri) or Document(uri, path)
        self.open[uri] = document
        self.touch(document)
        return document

    def touch(self, document: Document) -> None:
        document.used = next(self._clock)

    def remove(self, uri: str) -> tuple[set[str], list[str]]:
        """Forget ``uri``: (the files whose diagnostics change, the open documents to check again
        because no open file includes them any more)."""
        document = self.open.pop(uri, None)
        if document is None:
            return set(), []
        changed = self._files_of(document) | {str(document.path)}
        orphans = [other.uri for other in self.open.values()
                   if not self.includers(other.path) and (other.checked is None or not other.checked.standalone)]
        return changed, orphans

    def includers(self, path: Path) -> list[Document]:
        """The open documents whose latest check read ``path`` as a xacro include."""
        name = str(path)
        return [document for document in self.open.values()
                if document.checked is not None and name in document.checked.includes]

    def record(self, checked: Checked) -> set[str]:
        """Keep a finished check (if its document is still open and the check is its newest); the
        files whose diagnostics may have changed."""
        document = self.open.get(checked.snapshot.uri)
        if document is None:
            return set()
        changed = self._files_of(document) | set(checked.diagnostics) | {str(document.path)}
        document.checked = checked
        document.released = False
        if checked.analysis is not None and checked.analysis.model is not None:
            document.loaded = checked.analysis
        for other in self.open.values():  # a file this one includes is checked through it from now on
            if other is not document and str(other.path) in checked.includes and other.checked is not None \
                    and other.checked.standalone:
                changed |= self._files_of(other)
                other.checked = Checked(other.checked.snapshot, None, includes=other.checked.includes,
                                        standalone=False)
        self.touch(document)
        self._bound()
        return changed

    def record_sim(self, uri: str, version: int | None, diagnostics: dict[str, list[types.Diagnostic]],
                   error: str | None) -> set[str]:
        """Keep the PyBullet rules' diagnostics of the saved ``version``; the files they touch."""
        document = self.open.get(uri)
        if document is None:
            return set()
        if error is not None:
            diagnostics = {**diagnostics, str(document.path): [
                *diagnostics.get(str(document.path), []),
                problem(f"the PyBullet checks did not run to the end: {error}")]}
        old = set(document.sim[1]) if document.sim else set()
        document.sim = (version, diagnostics)
        return old | set(diagnostics)

    def diagnostics_for(self, path: str, versions: dict[str, int | None]) -> list[types.Diagnostic]:
        """Every open document's diagnostics on ``path``, each once; the PyBullet ones only while
        their document is still at the version that was saved (``versions``: URI -> current version)."""
        found: dict[tuple, types.Diagnostic] = {}
        for document in self.open.values():
            if document.checked is not None:
                for item in document.checked.diagnostics.get(path, []):
                    found.setdefault(key(item), item)
            if document.sim is not None and document.sim[0] == versions.get(document.uri):
                for item in document.sim[1].get(path, []):
                    found.setdefault(key(item), item)
        return list(found.values())

    def analyses(self, document: Document) -> list[RobotAnalysis]:
        """The analyses that know about ``document``'s robot: its own latest loaded one, then those of
        the open files that include it (a macro file's links are named in theirs)."""
        self.touch(document)
        own = [document.loaded] if document.loaded is not None else []
        return own + [other.loaded for other in self.includers(document.path) if other.loaded is not None]

    def _files_of(self, document: Document) -> set[str]:
        files = set(document.checked.diagnostics) if document.checked is not None else set()
        return files | (set(document.sim[1]) if document.sim is not None else set())

    def _bound(self) -> None:
        """Only the :data:`KEPT_ANALYSES` most recently used documents keep their analysis."""
        holding = sorted((document for document in self.open.values() if document.loaded is not None
                          or (document.checked is not None and document.checked.analysis is not None)),
                         key=lambda document: document.used, reverse=True)
        for document in holding[KEPT_ANALYSES:]:
            document.loaded, document.released = None, True
            if document.checked is not None:
                document.checked.analysis = None
