"""The live viewer: one robot file on a viser server, drawn with what ar3cli knows, redrawn when it changes.

:class:`Viewer` holds what is on screen: the last analysis that loaded (``shown``), the last load
(``latest``, which may have failed), the joint values by name, the scene and the panel. Work happens
on three kinds of threads, and every change of that state takes the viewer's lock:

- the main thread polls the files the load depended on (:meth:`Viewer.poll`, every
  :data:`POLL_SECONDS`) and reloads: the new robot is drawn with the slider values kept by joint name,
  or, when it does not load, the last good robot stays on screen with the error in the status. After
  each load it runs the simulated lint (``lint-urdf --sim``'s P rules, in a pybullet child, 1-3 s on
  the largest robots) and replaces the static findings with the full set: there, Ctrl-C and SIGTERM
  stop that child and remove its folder as in every command;
- viser's threads run the panel's callbacks (sliders, buttons, check boxes, clicks);
- the contact worker (:class:`ContactWorker`) answers "which links touch now?" through each
  analysis's kept pybullet child, the latest pose first (slider moves in between are skipped), and
  closes the analyses no longer shown (so a child is never closed while it answers); it is the
  thread that forks those children, and lives as long as they do.

A pybullet crash or a load that fails is a line in the status, never the end of the viewer.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Any

from ar3cli.errors import UserError
from ar3cli.view import describe
from ar3cli.view.scene import Layers, RobotScene

if TYPE_CHECKING:
    from pathlib import Path

    from ar3cli.analysis.contacts import Contacts
    from ar3cli.analysis.robot import RobotAnalysis

POLL_SECONDS = 0.25
"""How often the files are checked for changes (a ``stat`` each): a save is seen within this."""
SETTLE_SECONDS = 0.1
"""Wait after a change is seen before reading: an editor's save can be several writes."""


class Viewer:
    """One robot file on a viser ``server``; build it with the first analysis, then :meth:`poll`."""

    def __init__(self, server: Any, analysis: RobotAnalysis, seed: int = 0,
                 log: Callable[[str], None] | None = None) -> None:
        import numpy as np

        from ar3cli.output.report import log as stderr_log
        from ar3cli.view.panel import Banners, Panel

        self.server = server
        self.log = log or stderr_log
        self.path_shown = analysis.shown_path
        self._lock = threading.RLock()
        self._quiet = False
        self.layers = Layers()
        self.latest: RobotAnalysis = analysis
        self.shown: RobotAnalysis | None = None
        self.scene: RobotScene | None = None
        self.values: dict[str, float] = {}
        self.rng = np.random.default_rng(seed)
        self.placed = None
        self.counts: dict[str, int] | None = None
        self.simulated = False
        self.lint_error: str | None = None
        self.contacts: Contacts | None = None
        self.contact_error: str | None = None
        self.load_error: str | None = None
        self.selected: str | None = None
        self.loads = 0
        """Loads drawn (the first one and every reload that loaded)."""
        self._unlinted: RobotAnalysis | None = None
        """A load drawn with its static findings only: the next :meth:`poll` runs the simulated lint."""
        self.panel = Panel(server.gui, self.layers, self._layers_changed, self.home, self.random_pose, seed)
        self.banners = Banners(server)
        self.worker = ContactWorker(self._contacts_found)
        self.worker.start()
        self.load(analysis)

    # ---- loading ------------------------------------------------------------------------------
    def poll(self) -> bool:
        """Run the simulated lint of the load just drawn, if any; then reload when a file the last load
        depended on changed (True when it did)."""
        unlinted, self._unlinted = self._unlinted, None
        if unlinted is not None:
            self._simulated_lint(unlinted)
        changed = self.latest.changed()
        if not changed:
            return False
        time.sleep(SETTLE_SECONDS)
        self.load(self.latest.reloaded(), changed)
        return True

    def load(self, analysis: RobotAnalysis, changed: Iterable[Path] = ()) -> None:
        """Show ``analysis``; when it did not load, keep what is shown and say why."""
        names = ", ".join(path.name for path in list(changed)[:3])
        reason = f" ({names} changed)" if names else ""
        if analysis.model is None:
            message = analysis.load_error.message if analysis.load_error else "not loaded"
            self._failed(analysis, message)
            self.log(f"{self.path_shown}: does not load{reason}; "
                     f"{'the last good robot stays on screen' if self.shown else 'nothing to show yet'}: {message}")
            return
        try:
            drawn = self._draw(analysis)
        except UserError as exc:
            self._failed(analysis, exc.message)
            self.log(f"{self.path_shown}: cannot be drawn{reason}: {exc.message}")
            return
        verb = "reloaded" if self.loads > 1 else "drew"
        self.log(f"{self.path_shown}: {verb} {len(analysis.model.links)} links in {drawn:.2f} s{reason}; "
                 f"lint: {describe.counted(self.counts or {})} (static checks)")

    def _failed(self, analysis: RobotAnalysis, message: str) -> None:
        with self._lock:
            previous, self.latest = self.latest, analysis
            self.load_error = message
            self._refresh_status()
            kept = "the last good robot stays on screen" if self.shown is not None else "nothing to show yet"
            self.banners.show("load", f"{self.path_shown} does not load ({kept})", message)
        if previous is not self.shown and previous is not analysis:
            previous.close()  # a failed load holds no pybullet child: closing it here is safe

    def _draw(self, analysis: RobotAnalysis) -> float:
        """Draw ``analysis`` in place of what is shown; the seconds it took."""
        from ar3cli.analysis.findings import static_findings
        from ar3cli.analysis.inertia_boxes import inertia_boxes
        from ar3cli.analysis.link_findings import place_findings
        from ar3cli.analysis.meshes import link_meshes
        from ar3cli.analysis.poses import posing

        start = time.perf_counter()
        # the slow answers first, outside the lock (each is kept by the analysis): the old robot still moves
        link_meshes(analysis)
        inertia_boxes(analysis)
        posed = posing(analysis)
        lint = static_findings(analysis)
        placed = place_findings(analysis, lint.findings)
        with self._lock:
            previous, old = self.latest, self.shown
            self.values = posed.kept(self.values)
            if self.scene is not None:
                self.scene.remove()
            self.scene = RobotScene(self.server.scene, analysis, self.layers, self._clicked)
            self.scene.aim(self.server.initial_camera)
            self.shown = self.latest = analysis
            self.loads += 1
            self.load_error = self.contact_error = self.lint_error = None
            self.contacts = None
            self.banners.clear("load")
            self.banners.clear("contacts")
            self._set_findings(placed, lint.summary, simulated=False)
            self.scene.pose(self.values)
            self.panel.set_controls(posed, self.values, self._slider_moved)
            self.panel.notes.content = describe.notes([*posed.notes, *link_meshes(analysis).notes])
            self._refresh_status()
            self._ask_contacts(home=True)
        for retired in {previous, old} - {analysis, None}:
            self.worker.retire(retired)  # type: ignore[arg-type]
        self._unlinted = analysis
        return time.perf_counter() - start

    def _simulated_lint(self, analysis: RobotAnalysis) -> None:
        """The static and the PyBullet rules, then the panel and the colours updated."""
        from ar3cli.analysis.findings import findings
        from ar3cli.analysis.link_findings import place_findings

        try:
            answer = findings(analysis)
        except UserError:
            return
        placed = place_findings(analysis, answer.findings)
        with self._lock:
            if analysis is not self.shown:
                return
            self.lint_error = answer.result.error
            self._set_findings(placed, answer.summary, simulated=True)
            self._refresh_status()
        if answer.result.error:
            self.log(f"{self.path_shown}: lint: {describe.counted(answer.summary)} (the simulated checks did not run: "
                     f"{answer.result.error})")
        else:
            self.log(f"{self.path_shown}: lint with the simulated checks: {describe.counted(answer.summary)}")

    def _set_findings(self, placed, summary: Mapping[str, Any], simulated: bool) -> None:
        """(Under the lock) the findings on the links, in the panel and in the colours."""
        self.placed = placed
        self.counts = {name: int(summary.get(name, 0)) for name in ("error", "warning", "info")}
        self.simulated = simulated
        self.panel.findings.content = describe.findings_list(placed, self.shown.shown_path if self.shown else "")
        if self.scene is not None:
            self.scene.colour(severity={link: placed.worst(link) for link in placed.by_link})
        self._refresh_selected()

    # ---- moving -------------------------------------------------------------------------------
    def _slider_moved(self, name: str, value: float) -> None:
        with self._lock:
            if self._quiet or self.scene is None or name not in self.values:
                return
            self.values[name] = float(value)
            self.scene.pose(self.values)
            self._ask_contacts()

    def move(self, values: Mapping[str, float]) -> None:
        """Set the joints named in ``values`` (others keep theirs), sliders included."""
        with self._lock:
            if self.shown is None or self.scene is None:
                return
            from ar3cli.analysis.poses import posing

            posed = posing(self.shown)
            for name, value in values.items():
                control = posed.control(name)
                if control is not None:
                    self.values[name] = control.clamp(float(value))
            self._quiet = True
            try:
                self.panel.set_values(self.values)
            finally:
                self._quiet = False
            self.scene.pose(self.values)
            self._ask_contacts()

    def home(self) -> None:
        """Every joint at home."""
        from ar3cli.analysis.poses import posing

        with self._lock:
            if self.shown is not None:
                self.move(posing(self.shown).home())

    def random_pose(self) -> None:
        """The next pose of the seeded random sequence."""
        from ar3cli.analysis.poses import posing

        with self._lock:
            if self.shown is not None:
                self.move(posing(self.shown).random(self.rng))

    def _ask_contacts(self, home: bool = False) -> None:
        """(Under the lock) ask the worker which links touch at the current pose."""
        from ar3cli.analysis.poses import posing

        if self.shown is not None:
            self.worker.request(self.shown, posing(self.shown).joint_values(self.values), home)

    def _contacts_found(self, analysis: RobotAnalysis, found: Contacts | None, error: str | None, home: bool) -> None:
        """(The worker's thread) colour the pairs in contact; say so when it is the home pose of a load."""
        with self._lock:
            if analysis is not self.shown or self.scene is None:
                return
            self.contacts, self.contact_error = found, error
            self.scene.colour(contacts=found.links() if found is not None else set())
            if error is not None:
                self.banners.show("contacts", "Contacts not checked", error)
            self._refresh_status()
            self._refresh_selected()
        if home and error is not None:
            self.log(f"{self.path_shown}: contacts not checked: {error}")
        elif home and found is not None:
            pairs = ", ".join(f"{a}-{b}" for a, b in found.pairs) or "none"
            self.log(f"{self.path_shown}: contacts at home: {len(found.pairs)} pair(s): {pairs}")

    # ---- the panel ----------------------------------------------------------------------------
    def _layers_changed(self, layers: Layers) -> None:
        with self._lock:
            self.layers = layers
            if self.scene is not None:
                self.scene.show(layers)

    def _clicked(self, link: str) -> None:
        with self._lock:
            self.selected = link
            self._refresh_selected()

    def _refresh_selected(self) -> None:
        if self.selected is None or self.shown is None:
            return
        found = self.placed.by_link.get(self.selected, []) if self.placed is not None else []
        touching = {b if a == self.selected else a for a, b in (self.contacts.pairs if self.contacts else ())
                    if self.selected in (a, b)}
        self.panel.selected.content = describe.link_card(self.shown, self.selected, found, touching,
                                                         self.shown.shown_path)

    def _refresh_status(self) -> None:
        model = self.shown.model if self.shown is not None else None
        self.panel.status.content = describe.status(describe.Status(
            self.path_shown, len(model.links) if model else 0, len(model.joints) if model else 0, self.counts,
            self.simulated, self.lint_error, self.contacts, self.contact_error, self.load_error))

    # ---- the end ------------------------------------------------------------------------------
    def close(self) -> None:
        """Stop the worker, closing every pybullet child it opened."""
        self.worker.stop()
        with self._lock:
            analyses = {self.shown, self.latest} - {None}
        for analysis in analyses:
            analysis.close()  # type: ignore[union-attr]


class ContactWorker(threading.Thread):
    """The thread that asks each analysis's kept pybullet child which links touch, latest pose first,
    and closes the analyses it is handed back (between questions, never during one)."""

    def __init__(self, found: Callable[[RobotAnalysis, Contacts | None, str | None, bool], None]) -> None:
        super().__init__(name="ar3cli-view-contacts", daemon=True)
        self._found = found
        self._wake = threading.Condition()
        self._pending: tuple[RobotAnalysis, dict[str, float], bool] | None = None
        self._retired: list[RobotAnalysis] = []
        self._stopping = False

    def request(self, analysis: RobotAnalysis, values: Mapping[str, float], home: bool = False) -> None:
        """Check ``values`` next (a request not yet started is replaced; a home request stays marked)."""
        with self._wake:
            if self._pending is not None and self._pending[0] is analysis:
                home = home or self._pending[2]
            self._pending = (analysis, dict(values), home)
            self._wake.notify()

    def retire(self, analysis: RobotAnalysis) -> None:
        """Close ``analysis`` (its pybullet child) once no question to it is running."""
        with self._wake:
            self._retired.append(analysis)
            self._wake.notify()

    def stop(self) -> None:
        """End the thread after the question it is answering; the retired analyses are closed."""
        with self._wake:
            self._stopping = True
            self._wake.notify()
        if self.is_alive():
            self.join()
        self._close_retired()

    def run(self) -> None:
        from ar3cli.analysis.contacts import contacts

        while True:
            with self._wake:
                while not (self._stopping or self._pending or self._retired):
                    self._wake.wait()
                if self._stopping:
                    return
                pending, self._pending = self._pending, None
            self._close_retired()
            if pending is None:
                continue
            analysis, values, home = pending
            try:
                found, error = contacts(analysis, values), None
            except UserError as exc:
                found, error = None, exc.message
            except RuntimeError as exc:  # the analysis was closed meanwhile (a reload): nothing to show
                if "closed" not in str(exc):
                    raise
                continue
            self._found(analysis, found, error, home)

    def _close_retired(self) -> None:
        with self._wake:
            retired, self._retired = self._retired, []
        for analysis in retired:
            analysis.close()
