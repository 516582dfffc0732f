"""The viewer's control panel: viser GUI elements and nothing else (what they say comes from
:mod:`ar3cli.view.describe`, what they do from the :class:`~ar3cli.view.viewer.Viewer`).

Top to bottom: the status (file, findings, contacts now, banners), what is shown (check boxes), the
joints (``home``, ``random pose`` and one slider per joint a user moves), the findings, the link last
clicked, and the colours' legend with what is drawn differently from the file.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from ar3cli.view import describe
from ar3cli.view.scene import Layers
from ar3cli.view.text import label

if TYPE_CHECKING:
    from ar3cli.analysis.poses import JointControl, Posing

LAYER_BOXES = (("visual", "visual geometry"), ("collision", "collision geometry (translucent)"),
               ("frames", "link frames"), ("axes", "joint axes"), ("inertia", "inertia boxes"),
               ("centre_of_mass", "centres of mass"), ("findings", "colour links by findings"))
"""(the :class:`~ar3cli.view.scene.Layers` field, its check box's label)."""
SLIDER_STEPS = 2000
"""A slider's step is the power of ten nearest to its range / this (0.001 rad for a full turn)."""


class Panel:
    """The GUI of one viewer; the callbacks run on viser's threads."""

    def __init__(self, gui: Any, layers: Layers, on_layers: Callable[[Layers], None], on_home: Callable[[], None],
                 on_random: Callable[[], None], seed: int) -> None:
        self.gui = gui
        gui.configure_theme(control_width="large", show_share_button=False, show_logo=False)
        gui.set_panel_label("ar3cli view")
        self.status = gui.add_markdown("Loading\u2026", order=0)
        self.boxes: dict[str, Any] = {}
        with gui.add_folder("Show", order=1):
            for field, text in LAYER_BOXES:
                box = gui.add_checkbox(text, getattr(layers, field))
                box.on_update(lambda _event: on_layers(self.layers()))
                self.boxes[field] = box
        self.joints = gui.add_folder("Joints", order=2)
        with self.joints:
            gui.add_button("home", hint="Every joint at 0, or mid-range where 0 is outside its limits").on_click(
                lambda _event: on_home())
            gui.add_button("random pose", hint=f"Uniform in every joint's range; the n-th press is the same for "
                                               f"--seed {seed}").on_click(lambda _event: on_random())
        self.sliders: dict[str, Any] = {}
        with gui.add_folder("Findings", order=3):
            self.findings = gui.add_markdown("Linting\u2026")
        with gui.add_folder("Selected link", order=4):
            self.selected = gui.add_markdown("Click a link to see its facts and findings.")
        with gui.add_folder("Legend and notes", order=5, expand_by_default=False):
            gui.add_markdown(describe.legend())
            self.notes = gui.add_markdown(describe.notes([]))

    def layers(self) -> Layers:
        """What the check boxes ask to show."""
        return Layers(**{field: bool(box.value) for field, box in self.boxes.items()})

    def set_controls(self, posing: Posing, values: Mapping[str, float],
                     on_slider: Callable[[str, float], None]) -> None:
        """One slider per control of ``posing`` at ``values`` (the previous sliders removed)."""
        for slider in self.sliders.values():
            slider.remove()
        self.sliders = {}
        with self.joints:
            for control in posing.controls:
                slider = self.gui.add_slider(label(control.name), min=control.lower, max=control.upper,
                                             step=slider_step(control), initial_value=values[control.name],
                                             hint=_hint(control), disabled=not control.upper > control.lower)
                slider.on_update(lambda _event, name=control.name, slider=slider: on_slider(name, slider.value))
                self.sliders[control.name] = slider

    def set_values(self, values: Mapping[str, float]) -> None:
        """Move the sliders to ``values`` (their callbacks run: the caller ignores them meanwhile)."""
        for name, value in values.items():
            slider = self.sliders.get(name)
            if slider is not None:
                slider.value = value


class Banners:
    """Notifications on every open page, and on each page that opens later, while something is wrong
    (the file does not load, pybullet crashed): seen wherever the panel is scrolled. One per topic;
    the text is plain (viser shows a notification's body as text), one line, shortened."""

    def __init__(self, server: Any) -> None:
        import threading

        self.server = server
        self._lock = threading.Lock()
        self.shown: dict[str, tuple[str, str]] = {}
        self._handles: dict[str, list[Any]] = {}
        server.on_client_connect(self._connected)

    def show(self, topic: str, title: str, body: str) -> None:
        """Show (or replace) the banner of ``topic`` on every page."""
        text = (label(title, 120), label(body, 600))
        with self._lock:
            if self.shown.get(topic) == text:
                return
            self._remove(topic)
            self.shown[topic] = text
            self._handles[topic] = [self._add(client, *text) for client in self.server.get_clients().values()]

    def clear(self, topic: str) -> None:
        with self._lock:
            self.shown.pop(topic, None)
            self._remove(topic)

    def _remove(self, topic: str) -> None:
        for handle in self._handles.pop(topic, []):
            handle.remove()

    def _connected(self, client: Any) -> None:
        with self._lock:
            for topic, text in self.shown.items():
                self._handles.setdefault(topic, []).append(self._add(client, *text))

    @staticmethod
    def _add(client: Any, title: str, body: str) -> Any:
        return client.add_notification(title, body, with_close_button=True, color="red")


def slider_step(control: JointControl) -> float:
    """The power of ten nearest to the range / :data:`SLIDER_STEPS` (a zero range: 1e-6)."""
    span = control.upper - control.lower
    if not span > 0 or not math.isfinite(span):
        return 1e-6
    return 10.0 ** round(math.log10(span / SLIDER_STEPS))


def _hint(control: JointControl) -> str:
    unit = "m" if control.type == "prismatic" else "rad"
    kind = "limits" if control.limited else ("unlimited: shown over one turn" if control.type != "prismatic"
                                             else "unlimited: shown over +-1 m")
    return f"{label(control.name, 200)}: {control.type}, {kind} {control.lower:.4g} .. {control.upper:.4g} {unit}"
