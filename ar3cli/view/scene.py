"""One load of a robot as viser scene nodes: built once, then moved, recoloured and shown or hidden.

Every link is a frame node (``/robot/l<index>``: viser names are built from positions, never from
names in the file) placed at its world pose; under it hang its visual and collision meshes
(:func:`ar3cli.analysis.meshes.link_meshes`, already in the link frame), its equivalent inertia box
and centre-of-mass sphere (:func:`ar3cli.analysis.inertia_boxes.inertia_boxes`) and the axis of the
joint that moves it (the joint frame is the child link's frame). A pose moves only the link frames.

Colours say what ar3cli knows: a link in contact with another at the current pose is red; otherwise,
when findings are shown, a link with findings takes the colour of the worst one (:data:`SEVERITY_RGB`);
otherwise its visual keeps the file's colour (:data:`DEFAULT_RGB` where the file gives none) and its
collision geometry is translucent teal.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ar3cli.findings import Severity

if TYPE_CHECKING:
    from ar3cli.analysis.robot import RobotAnalysis

Rgb = tuple[int, int, int]

DEFAULT_RGB: Rgb = (185, 188, 195)
"""A visual whose file gives it no colour."""
COLLISION_RGB: Rgb = (40, 175, 165)
COLLISION_OPACITY = 0.45
CONTACT_RGB: Rgb = (230, 25, 25)
"""Links in contact at the current pose: the red of render's and report's pictures."""
SEVERITY_RGB: Mapping[Severity, Rgb] = {Severity.ERROR: (205, 55, 200), Severity.WARNING: (245, 185, 20)}
"""A link with findings, by the worst of them: magenta for an error, amber for a warning (red is for
contacts). A link whose worst finding is an info keeps its colour: info findings are notes (I007
"no <dynamics>" on every wheel of pybullet_data's r2d2), and a robot painted all over for them
would hide the links that are wrong; they are listed in the panel and on a click like the others."""
INERTIA_RGB: Rgb = (110, 95, 225)
INERTIA_PROBLEM_RGB: Rgb = (230, 25, 25)
INERTIA_OPACITY = 0.35
COM_RGB: Rgb = (25, 25, 25)
AXIS_RGB = {"revolute": (235, 120, 20), "continuous": (235, 120, 20), "prismatic": (30, 150, 240)}
FRAME_SHARE = 0.06
"""Link frame axes are this share of the robot's size long (joint axis arrows twice that)."""
MIN_MARKER_SHARE = 0.004
"""A centre-of-mass sphere is at least this share of the robot's size (a 1 g link stays visible)."""
CAMERA_DISTANCE = 1.0
"""The camera stands this many robot sizes (the diagonal of its box at home) from the robot's centre:
with viser's 75 degree field of view the whole robot is in the picture."""
DEFAULT_SIZE_M = 1.0
"""The robot's size when nothing has a mesh (for frame and arrow lengths)."""


@dataclass
class Layers:
    """What is shown (the panel's check boxes)."""

    visual: bool = True
    collision: bool = False
    frames: bool = False
    axes: bool = False
    inertia: bool = False
    centre_of_mass: bool = False
    findings: bool = True


@dataclass
class _LinkNodes:
    frame: Any
    visuals: list[tuple[Any, Rgb]] = field(default_factory=list)
    collisions: list[Any] = field(default_factory=list)
    extras: dict[str, Any] = field(default_factory=dict)
    """``inertia``, ``com`` and ``axis`` nodes where the link has them."""


class RobotScene:
    """The nodes of one analysed robot under ``root``; :meth:`remove` takes them all away."""

    def __init__(self, scene: Any, analysis: RobotAnalysis, layers: Layers,
                 clicked: Callable[[str], None], root: str = "/robot") -> None:
        from ar3cli.analysis.inertia_boxes import inertia_boxes
        from ar3cli.analysis.meshes import link_meshes
        from ar3cli.analysis.poses import posing

        self.scene, self.root, self.layers = scene, root, layers
        model = analysis.require_model()
        meshes = link_meshes(analysis)
        self.posing = posing(analysis)
        self.centre, self.size = _extent(meshes, self.posing.frames(self.posing.home()))
        boxes = {box.link: box for box in inertia_boxes(analysis)}
        axes = {joint.child: joint for joint in model.joints if joint.child is not None and
                joint.type in AXIS_RGB and joint.name not in self.posing.followers}
        self.links: dict[str, _LinkNodes] = {}
        self._severity: dict[str, Severity] = {}
        self._contacts: set[str] = set()
        for index, link in enumerate(model.links):
            if link.name in self.links:
                continue  # a duplicate name (S-rules): pybullet and every tool keep the first
            name = f"{root}/l{index}"
            nodes = _LinkNodes(scene.add_frame(name, show_axes=layers.frames, axes_length=FRAME_SHARE * self.size,
                                               axes_radius=FRAME_SHARE * self.size / 20, origin_radius=0.0))
            for number, part in enumerate(meshes.of(link.name)):
                colour = _rgb(part.rgba) if part.rgba is not None else DEFAULT_RGB
                if part.role == "visual":
                    opacity = part.rgba[3] if part.rgba is not None and part.rgba[3] < 1.0 else None
                    handle = scene.add_mesh_simple(f"{name}/v{number}", part.vertices, part.faces, color=colour,
                                                   opacity=opacity, side="double", visible=layers.visual)
                    nodes.visuals.append((handle, colour))
                else:
                    handle = scene.add_mesh_simple(f"{name}/c{number}", part.vertices, part.faces,
                                                   color=COLLISION_RGB, opacity=COLLISION_OPACITY, side="double",
                                                   visible=layers.collision, cast_shadow=False)
                    nodes.collisions.append(handle)
                handle.on_click(lambda _event, link=link.name: clicked(link))
            box = boxes.get(link.name)
            if box is not None:
                wxyz = _wxyz(box.rotation)
                nodes.extras["inertia"] = scene.add_box(
                    f"{name}/inertia", color=INERTIA_PROBLEM_RGB if box.problem else INERTIA_RGB,
                    dimensions=tuple(max(edge, 1e-6) for edge in box.size), wireframe=bool(box.problem),
                    opacity=None if box.problem else INERTIA_OPACITY, wxyz=wxyz, position=box.centre,
                    visible=layers.inertia, cast_shadow=False)
                nodes.extras["com"] = scene.add_icosphere(
                    f"{name}/com", radius=max(box.marker_radius, MIN_MARKER_SHARE * self.size), color=COM_RGB,
                    subdivisions=2, position=box.centre, visible=layers.centre_of_mass, cast_shadow=False)
            joint = axes.get(link.name)
            if joint is not None and link.name in axes:
                direction = _unit(joint.axis)
                if direction is not None:
                    length = 2 * FRAME_SHARE * self.size
                    nodes.extras["axis"] = scene.add_arrows(
                        f"{name}/axis", points=[[(0.0, 0.0, 0.0), tuple(length * v for v in direction)]],
                        colors=AXIS_RGB[joint.type], shaft_radius=length / 40, head_radius=length / 15,
                        head_length=length / 5, visible=layers.axes)
            self.links[link.name] = nodes

    # ---- pose and colours ------------------------------------------------------------------------
    def pose(self, values: Mapping[str, float]) -> None:
        """Move every link frame to its place at the controls' ``values``."""
        frames = self.posing.frames(values)
        for link, nodes in self.links.items():
            frame = frames.get(link)
            if frame is None:
                nodes.frame.visible = False  # not reached from a root: Posing.notes says so
                continue
            nodes.frame.position = tuple(frame[:3, 3].tolist())
            nodes.frame.wxyz = _wxyz(frame[:3, :3])

    def colour(self, severity: Mapping[str, Severity] | None = None, contacts: set[str] | None = None) -> None:
        """Recolour: ``severity`` (the worst finding per link) and ``contacts`` (links in contact now),
        each kept from the last call when None."""
        if severity is not None:
            self._severity = dict(severity)
        if contacts is not None:
            self._contacts = set(contacts)
        for link, nodes in self.links.items():
            state = self.state_colour(link)
            for handle, own in nodes.visuals:
                _set_colour(handle, state or own)
            for handle in nodes.collisions:
                _set_colour(handle, state or COLLISION_RGB)

    def state_colour(self, link: str) -> Rgb | None:
        """What ar3cli's knowledge paints ``link`` (contact, then the worst finding), None: its own colour."""
        if link in self._contacts:
            return CONTACT_RGB
        severity = self._severity.get(link)
        return SEVERITY_RGB.get(severity) if severity is not None and self.layers.findings else None  # type: ignore[call-overload]

    def show(self, layers: Layers) -> None:
        """Show and hide the node kinds as ``layers`` says."""
        self.layers = layers
        for nodes in self.links.values():
            nodes.frame.show_axes = layers.frames
            for handle, _ in nodes.visuals:
                handle.visible = layers.visual
            for handle in nodes.collisions:
                handle.visible = layers.collision
            for kind, shown in (("inertia", layers.inertia), ("com", layers.centre_of_mass), ("axis", layers.axes)):
                if kind in nodes.extras:
                    nodes.extras[kind].visible = shown
        self.colour()

    def aim(self, camera: Any) -> None:
        """Point ``camera`` (viser's initial camera: new clients and "Reset View") at the whole robot."""
        direction = (1.0, 1.0, 0.75)
        norm = math.sqrt(sum(v * v for v in direction))
        camera.look_at = self.centre
        camera.position = tuple(c + CAMERA_DISTANCE * self.size * v / norm for c, v in zip(self.centre, direction))

    def remove(self) -> None:
        """Take every node of this robot out of the scene."""
        for nodes in self.links.values():
            nodes.frame.remove()  # its children go with it
        self.links = {}


def _set_colour(handle: Any, colour: Rgb) -> None:
    if tuple(handle.color) != colour:
        handle.color = colour


def _rgb(rgba) -> Rgb:
    return tuple(int(round(255 * min(max(v, 0.0), 1.0))) for v in rgba[:3])  # type: ignore[return-value]


def _unit(vector) -> tuple[float, float, float] | None:
    norm = math.sqrt(sum(v * v for v in vector))
    return tuple(v / norm for v in vector) if math.isfinite(norm) and norm > 0 else None  # type: ignore[return-value]


def _wxyz(rotation) -> tuple[float, float, float, float]:
    """The unit quaternion (w, x, y, z) of a rotation matrix."""
    import numpy as np
    from viser.transforms import SO3

    return tuple(SO3.from_matrix(np.asarray(rotation, dtype=float)).wxyz.tolist())  # type: ignore[return-value]


def _extent(meshes, frames) -> tuple[tuple[float, float, float], float]:
    """The centre and the diagonal of the box around every part at the pose ``frames`` (the world
    origin and :data:`DEFAULT_SIZE_M` without geometry): where the camera looks, and what frames,
    arrows and markers are scaled to."""
    import numpy as np

    corners = []
    for part in meshes.parts:
        frame = frames.get(part.link)
        if frame is not None and len(part.vertices):
            low, high = part.vertices.min(axis=0), part.vertices.max(axis=0)
            box = np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])])
            corners.append(box @ frame[:3, :3].T + frame[:3, 3])
    if not corners:
        return (0.0, 0.0, 0.0), DEFAULT_SIZE_M
    points = np.concatenate(corners)
    low, high = points.min(axis=0), points.max(axis=0)
    diagonal = float(np.linalg.norm(high - low))
    if not (math.isfinite(diagonal) and diagonal > 0):
        return (0.0, 0.0, 0.0), DEFAULT_SIZE_M
    return tuple(((low + high) / 2).tolist()), diagonal  # type: ignore[return-value]
