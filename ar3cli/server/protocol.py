"""The language server itself: pygls handlers wired to the checks and the features of this package.

Threads: pygls reads and answers on its event loop. A check (load, lint, diagnostics) runs on one
worker thread, so the loop keeps reading keystrokes meanwhile; the PyBullet rules run on a second
one (in a forked child, as everywhere), so a slow simulation never delays a keystroke's check.
A check that finishes after its document changed again is dropped (its positions are stale) and
the newest text is checked next. Hover, outline, definitions, completion and code actions answer
on the loop from the latest analysis and the buffer as it is.

Robustness: every handler catches what it raises, logs it (the editor's log and stderr) and
answers with nothing; a check that fails publishes one diagnostic saying so. A bad file is a finding.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import logging
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

from lsprotocol import types
from pygls.lsp.server import LanguageServer
from pygls.uris import from_fs_path, to_fs_path

from ar3cli import __version__
from ar3cli.server.checks import Checked, Snapshot, check, sim_check
from ar3cli.server.diagnostics import problem
from ar3cli.server.documents import Document, Documents
from ar3cli.server.options import ServerOptions

T = TypeVar("T")
ROBOT_SUFFIXES = (".urdf", ".xacro")
WATCHED = "**/*.{urdf,xacro,yaml,yml,stl,STL,dae,DAE,obj,OBJ,toml,xml}"
"""Files whose change may change a check: robot files and their includes, meshes (a missing one that
appears), pyproject.toml (the configuration), package.xml (a package's name)."""
logger = logging.getLogger("ar3cli.server")


class RobotLanguageServer(LanguageServer):
    """pygls' server with ar3cli's state: the options, the open robot files, the worker threads."""

    def __init__(self, options: ServerOptions) -> None:
        super().__init__("ar3cli", __version__, text_document_sync_kind=types.TextDocumentSyncKind.Incremental)
        self.options = options
        self.settings, _ = options.analysis_settings(Path.cwd())
        self.documents = Documents()
        self.checker = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="ar3cli-check")
        self.simulator = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="ar3cli-sim")
        self.timers: dict[str, asyncio.TimerHandle] = {}
        self.running: set[str] = set()
        self.again: set[str] = set()
        self.forced: set[str] = set()
        self.simulating: set[str] = set()

    # ---- helpers ---------------------------------------------------------------------------------
    @property
    def encoding(self) -> str:
        kind = self.workspace.position_encoding
        return str(getattr(kind, "value", kind) or "utf-16")

    def say(self, message: str, level: types.MessageType = types.MessageType.Log) -> None:
        """One line in the editor's log (and on stderr)."""
        logger.log(logging.WARNING if level <= types.MessageType.Warning else logging.INFO, message)
        with contextlib.suppress(Exception):  # the client is gone: stderr has it
            self.window_log_message(types.LogMessageParams(level, message))

    def take_client_settings(self, settings) -> None:
        """The editor's settings (initializationOptions or didChangeConfiguration) over the command line's; a
        setting refused is one warning line in the editor's log."""
        self.options, refused = self.options.with_client_settings(settings)
        for line in refused:
            self.say(line, types.MessageType.Warning)

    def text(self, uri: str) -> str | None:
        """The buffer's text (None when it is not open)."""
        try:
            return self.workspace.get_text_document(uri).source
        except Exception:  # noqa: BLE001 - pygls raises various errors for an unknown document
            return None

    def text_of(self, path: str) -> str | None:
        """A file's text: its buffer when open, else the disk (through the capped reader)."""
        uri = from_fs_path(path)
        if uri is not None and uri in self.workspace.text_documents:
            return self.workspace.get_text_document(uri).source
        from ar3cli.server.checks import read_text

        return read_text(Path(path))

    def version_of(self, uri: str) -> int | None:
        document = self.workspace.text_documents.get(uri)
        return document.version if document is not None else None

    # ---- checks ----------------------------------------------------------------------------------
    def schedule(self, uri: str, delay_ms: int = 0, force: bool = False) -> None:
        """Check ``uri`` after ``delay_ms`` without a newer request (a pause in typing)."""
        if force:
            self.forced.add(uri)
        timer = self.timers.pop(uri, None)
        if timer is not None:
            timer.cancel()
        if delay_ms <= 0:
            self._start(uri)
        else:
            self.timers[uri] = asyncio.get_running_loop().call_later(delay_ms / 1000, self._start, uri)

    def _start(self, uri: str) -> None:
        self.timers.pop(uri, None)
        if uri in self.running:
            self.again.add(uri)
            return
        self.running.add(uri)
        asyncio.ensure_future(self._check(uri))

    async def _check(self, uri: str) -> None:
        try:
            document = self.documents.open.get(uri)
            text = self.text(uri)
            if document is None or text is None:
                return
            snapshot = Snapshot(uri, document.path, self.version_of(uri), text)
            earlier = document.checked
            if earlier is not None and uri not in self.forced and earlier.snapshot.text == text and \
                    earlier.snapshot.version == snapshot.version:
                return
            self.forced.discard(uri)
            if self.documents.includers(document.path):
                checked = Checked(snapshot, None, includes=earlier.includes if earlier else frozenset(),
                                  standalone=False)
            else:
                checked = await asyncio.get_running_loop().run_in_executor(
                    self.checker, check, snapshot, self.settings, earlier, self.encoding)
            for note in checked.notes:
                self.say(note, types.MessageType.Warning)
            if self.version_of(uri) != snapshot.version or uri not in self.documents.open:
                return  # typed meanwhile: the newer text is checked next
            self.publish(self.documents.record(checked))
        except Exception as exc:  # noqa: BLE001 - a bug in ar3cli must not end the server
            self._failed(uri, exc)
        finally:
            self.running.discard(uri)
            if uri in self.again:
                self.again.discard(uri)
                self._start(uri)

    def _failed(self, uri: str, exc: BaseException) -> None:
        message = f"ar3cli could not check this file: internal error {type(exc).__name__}: {exc} (a bug in ar3cli: " \
                  "please report it with the server's log)"
        logger.exception("checking %s", uri)
        self.say(message, types.MessageType.Error)
        document = self.documents.open.get(uri)
        if document is not None:
            snapshot = Snapshot(uri, document.path, self.version_of(uri), self.text(uri) or "")
            self.publish(self.documents.record(Checked(snapshot, None, {str(document.path): [problem(message)]})))

    def diagnostics_on(self, path: str) -> list[types.Diagnostic]:
        """Every diagnostic published on ``path`` now."""
        return self.documents.diagnostics_for(path, {uri: self.version_of(uri) for uri in self.documents.open})

    def publish(self, files: set[str]) -> None:
        versions = {uri: self.version_of(uri) for uri in self.documents.open}
        owners = {str(document.path): document for document in self.documents.open.values()}
        for path in sorted(files):
            uri = from_fs_path(path)
            if uri is None:
                continue
            owner = owners.get(path)
            version = owner.checked.snapshot.version if owner is not None and owner.checked is not None \
                and owner.checked.standalone else None
            self.text_document_publish_diagnostics(types.PublishDiagnosticsParams(
                uri, self.documents.diagnostics_for(path, versions), version))

    def recheck_changed(self, except_uri: str | None = None) -> None:
        """Check again every open document whose files changed on disk (an include saved, a mesh added)."""
        for document in list(self.documents.open.values()):
            dependencies = document.checked.dependencies if document.checked is not None else None
            if document.uri != except_uri and dependencies is not None and dependencies.changed():
                self.schedule(document.uri, force=True)

    def simulate(self, uri: str) -> None:
        """The PyBullet rules on the saved file, on their own thread (``sim`` setting)."""
        document = self.documents.open.get(uri)
        if not self.options.sim or document is None or uri in self.simulating:
            return
        if document.checked is not None and not document.checked.standalone:
            return
        version = self.version_of(uri)
        self.simulating.add(uri)
        future = asyncio.get_running_loop().run_in_executor(self.simulator, sim_check, document.path, self.settings,
                                                            self.encoding)

        def done(finished: asyncio.Future) -> None:
            self.simulating.discard(uri)
            try:
                diagnostics, error, notes = finished.result()
            except Exception as exc:  # noqa: BLE001 - see _failed
                self.say(f"{document.path}: the PyBullet checks failed: {type(exc).__name__}: {exc}",
                         types.MessageType.Error)
                return
            for note in notes:
                self.say(note, types.MessageType.Warning)
            if error:
                self.say(f"{document.path}: {error}", types.MessageType.Warning)
            self.publish(self.documents.record_sim(uri, version, diagnostics, error))

        future.add_done_callback(done)

    async def analyses(self, document: Document) -> list[Any]:
        """The analyses for a feature on ``document``; its own is made again when it was let go."""
        found = self.documents.analyses(document)
        if found or not document.released:
            return found
        text = self.text(document.uri)
        if text is None:
            return []
        snapshot = Snapshot(document.uri, document.path, self.version_of(document.uri), text)
        checked = await asyncio.get_running_loop().run_in_executor(self.checker, check, snapshot, self.settings,
                                                                   document.checked, self.encoding)
        if self.version_of(document.uri) == snapshot.version:
            self.publish(self.documents.record(checked))
        return [checked.analysis] if checked.analysis is not None and checked.analysis.model is not None else []

    def related(self, document: Document, analyses: list[Any]) -> list[str]:
        """The files a xacro definition may be in: those ``document`` includes, those including it,
        and what they include."""
        names: list[str] = []
        for analysis in analyses:
            expansion = analysis.model.expansion if analysis.model is not None else None
            names += [os.path.abspath(name) for name in (expansion.included if expansion else [])]
            names.append(str(analysis.path))
        if document.checked is not None:
            names += sorted(document.checked.includes)
        return [name for name in dict.fromkeys(names) if name != str(document.path)]

    def reload_settings(self) -> None:
        self.settings, error = self.options.analysis_settings(Path.cwd())
        if error:
            self.say(f"{error}; checking with every rule until it is fixed", types.MessageType.Error)
            self.window_show_message(types.ShowMessageParams(types.MessageType.Error, f"ar3cli: {error}"))
        for uri in list(self.documents.open):
            self.schedule(uri, force=True)


def robot_path(uri: str) -> Path | None:
    """The file a URI names when it is a local .urdf or .xacro file (other schemes have no path)."""
    if not uri.startswith("file:"):
        return None
    path = to_fs_path(uri)
    if not path or not path.lower().endswith(ROBOT_SUFFIXES):
        return None
    return Path(os.path.abspath(path))


def guarded(default: Callable[[], T]) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """A handler that logs what it raises and answers ``default()`` instead."""
    import functools
    import inspect

    def wrap(handler: Callable[..., Any]) -> Callable[..., Any]:
        if inspect.iscoroutinefunction(handler):
            @functools.wraps(handler)
            async def guarded_async(server: RobotLanguageServer, params: Any) -> Any:
                try:
                    return await handler(server, params)
                except Exception as exc:  # noqa: BLE001 - a bug in ar3cli must not end the server
                    logger.exception("%s", handler.__name__)
                    server.say(f"ar3cli: {handler.__name__} failed: {type(exc).__name__}: {exc}", types.MessageType.Error)
                    return default()
            return guarded_async

        @functools.wraps(handler)
        def guarded_sync(server: RobotLanguageServer, params: Any) -> Any:
            try:
                return handler(server, params)
            except Exception as exc:  # noqa: BLE001 - see above
                logger.exception("%s", handler.__name__)
                server.say(f"ar3cli: {handler.__name__} failed: {type(exc).__name__}: {exc}", types.MessageType.Error)
                return default()
        return guarded_sync

    return wrap


def build(options: ServerOptions) -> RobotLanguageServer:
    """The server with every handler registered."""
    server = RobotLanguageServer(options)

    @server.feature(types.INITIALIZE)
    @guarded(lambda: None)
    def initialize(ls: RobotLanguageServer, params: types.InitializeParams) -> None:
        ls.take_client_settings(params.initialization_options)
        folders = [folder.uri for folder in params.workspace_folders or []]
        root = params.root_uri or (folders[0] if folders else None) or \
            (from_fs_path(params.root_path) if params.root_path else None)
        folder = to_fs_path(root) if root and root.startswith("file:") else None
        if folder and os.path.isdir(folder):
            os.chdir(folder)  # findings name files relative to it, [tool.ar3cli] is found from it: lint-urdf run there
        ls.settings, error = ls.options.analysis_settings(Path.cwd())
        if error:
            ls.say(f"{error}; checking with every rule until it is fixed", types.MessageType.Error)

    @server.feature(types.INITIALIZED)
    @guarded(lambda: None)
    async def initialized(ls: RobotLanguageServer, params: types.InitializedParams) -> None:
        capabilities = ls.client_capabilities.workspace
        watched = capabilities.did_change_watched_files if capabilities is not None else None
        if watched is None or not watched.dynamic_registration:
            return  # included files are then checked again when the editor saves them
        try:
            await ls.client_register_capability_async(types.RegistrationParams([types.Registration(
                "ar3cli-watched-files", types.WORKSPACE_DID_CHANGE_WATCHED_FILES,
                types.DidChangeWatchedFilesRegistrationOptions([types.FileSystemWatcher(glob_pattern=WATCHED)]))]))
        except Exception as exc:  # noqa: BLE001 - an editor that refuses: saves in the editor still count
            ls.say(f"the editor does not watch files for ar3cli ({exc}); changes saved outside it are seen "
                   "when a file is next checked")

    @server.feature(types.TEXT_DOCUMENT_DID_OPEN)
    @guarded(lambda: None)
    def did_open(ls: RobotLanguageServer, params: types.DidOpenTextDocumentParams) -> None:
        path = robot_path(params.text_document.uri)
        if path is not None:
            ls.documents.add(params.text_document.uri, path)
            ls.schedule(params.text_document.uri)

    @server.feature(types.TEXT_DOCUMENT_DID_CHANGE)
    @guarded(lambda: None)
    def did_change(ls: RobotLanguageServer, params: types.DidChangeTextDocumentParams) -> None:
        if params.text_document.uri in ls.documents.open:
            ls.schedule(params.text_document.uri, ls.options.debounce_ms)

    @server.feature(types.TEXT_DOCUMENT_DID_SAVE)
    @guarded(lambda: None)
    def did_save(ls: RobotLanguageServer, params: types.DidSaveTextDocumentParams) -> None:
        uri = params.text_document.uri
        if uri in ls.documents.open:
            ls.schedule(uri)
            ls.simulate(uri)
        ls.recheck_changed(except_uri=uri)

    @server.feature(types.TEXT_DOCUMENT_DID_CLOSE)
    @guarded(lambda: None)
    def did_close(ls: RobotLanguageServer, params: types.DidCloseTextDocumentParams) -> None:
        uri = params.text_document.uri
        timer = ls.timers.pop(uri, None)
        if timer is not None:
            timer.cancel()
        changed, orphans = ls.documents.remove(uri)
        ls.publish(changed)
        for orphan in orphans:
            ls.schedule(orphan, force=True)

    @server.feature(types.WORKSPACE_DID_CHANGE_WATCHED_FILES)
    @guarded(lambda: None)
    def did_change_watched_files(ls: RobotLanguageServer, params: types.DidChangeWatchedFilesParams) -> None:
        if any(change.uri.endswith("/pyproject.toml") for change in params.changes):
            ls.reload_settings()
        else:
            ls.recheck_changed()

    @server.feature(types.WORKSPACE_DID_CHANGE_CONFIGURATION)
    @guarded(lambda: None)
    def did_change_configuration(ls: RobotLanguageServer, params: types.DidChangeConfigurationParams) -> None:
        ls.take_client_settings(params.settings)

    @server.feature(types.SHUTDOWN)
    def shutdown(ls: RobotLanguageServer, params: Any) -> None:
        for timer in ls.timers.values():
            timer.cancel()
        ls.checker.shutdown(wait=False, cancel_futures=True)
        ls.simulator.shutdown(wait=False, cancel_futures=True)

    _features(server)
    return server


def _features(server: RobotLanguageServer) -> None:
    """Hover, outline, definitions, completion and code actions."""
    from ar3cli.server import actions, completion, hover, navigation

    def document_of(ls: RobotLanguageServer, uri: str) -> tuple[Document | None, str | None]:
        document = ls.documents.open.get(uri)
        return document, ls.text(uri) if document is not None else None

    @server.feature(types.TEXT_DOCUMENT_HOVER)
    @guarded(lambda: None)
    async def on_hover(ls: RobotLanguageServer, params: types.HoverParams) -> types.Hover | None:
        document, text = document_of(ls, params.text_document.uri)
        if document is None or text is None:
            return None
        return hover.hover(text, params.position, ls.encoding, ls.diagnostics_on(str(document.path)),
                           await ls.analyses(document))

    @server.feature(types.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
    @guarded(list)
    async def on_symbols(ls: RobotLanguageServer, params: types.DocumentSymbolParams) -> list[types.DocumentSymbol]:
        document, text = document_of(ls, params.text_document.uri)
        if document is None or text is None:
            return []
        own = [analysis for analysis in await ls.analyses(document) if analysis.path == document.path]
        if not own:
            return []
        analysed = own[0].source.decode("utf-8", "replace") if own[0].source is not None else text
        return navigation.document_symbols(own[0], analysed, ls.encoding)

    @server.feature(types.TEXT_DOCUMENT_DEFINITION)
    @guarded(list)
    async def on_definition(ls: RobotLanguageServer, params: types.DefinitionParams) -> list[types.Location]:
        document, text = document_of(ls, params.text_document.uri)
        if document is None or text is None:
            return []
        analyses = await ls.analyses(document)
        return navigation.definition(document.path, text, params.position, ls.encoding, analyses,
                                     ls.related(document, analyses), ls.text_of)

    @server.feature(types.TEXT_DOCUMENT_COMPLETION,
                    types.CompletionOptions(trigger_characters=["<", " ", '"', "'"]))
    @guarded(lambda: None)
    async def on_completion(ls: RobotLanguageServer, params: types.CompletionParams) -> types.CompletionList | None:
        document, text = document_of(ls, params.text_document.uri)
        if document is None or text is None:
            return None
        analyses = await ls.analyses(document)
        xacro_texts = None
        if document.path.suffix.lower() == ".xacro":
            xacro_texts = [text, *(content for name in ls.related(document, analyses)
                                   if (content := ls.text_of(name)) is not None)]
        return completion.completions(text, params.position, ls.encoding, analyses, xacro_texts)

    @server.feature(types.TEXT_DOCUMENT_CODE_ACTION,
                    types.CodeActionOptions(code_action_kinds=[types.CodeActionKind.QuickFix]))
    @guarded(list)
    async def on_code_action(ls: RobotLanguageServer, params: types.CodeActionParams) -> list[types.CodeAction]:
        document, text = document_of(ls, params.text_document.uri)
        if document is None or text is None:
            return []
        wanted = [item for item in params.context.diagnostics if item.source == "ar3cli" and item.code]
        own = [analysis for analysis in await ls.analyses(document) if analysis.path == document.path]
        return [*actions.fix_actions(params.text_document.uri, text, own[0] if own else None, wanted, ls.encoding),
                *actions.ignore_actions(params.text_document.uri, text, wanted, ls.encoding)]
