"""Offscreen pictures of a robot with PyBullet's TinyRenderer (CPU only, no display needed).

The camera frames the robot's bounding box at the chosen configuration. Optionally the collision
geometry is drawn (in blue, in place of the visual geometry: TinyRenderer has no transparency, so a
true overlay z-fights with the visual surfaces it coincides with), and links that interpenetrate a
link they are not adjacent to are drawn red, by :func:`ar3cli.sim.adjacency.nonadjacent_collisions`:
at the home pose the picture shows exactly what ``lint-urdf --sim`` (P002) and sample-collisions
("default") report.
"""

from __future__ import annotations

import copy
import io
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.infra.atomic import atomic_write
from ar3cli.urdf.model import Model

CONTACT_RGBA = (0.9, 0.1, 0.1, 1.0)
COLLISION_RGBA = "0.15 0.55 0.95 1"


@dataclass
class RenderResult:
    """What was drawn: the file, the image size, the joint values used, the links in contact and the
    visuals that could not be drawn (one warning each: a picture that leaves parts out says so, in
    JSON too)."""

    path: Path
    width: int
    height: int
    configuration: dict[str, float]
    contacts: list[tuple[str, str, float]] = field(default_factory=list)
    not_drawn: list[str] = field(default_factory=list)
    collisions_left_out: list[dict] = field(default_factory=list)
    """Collision shapes pybullet cannot load (:class:`~ar3cli.sim.loadable_copy.LeftOut`): their contacts are not checked."""

    def to_dict(self) -> dict:
        return {"path": str(self.path), "width": self.width, "height": self.height,
                "configuration": self.configuration,
                "contacts": [{"link_a": a, "link_b": b, "depth_m": d} for a, b, d in self.contacts],
                "visuals_not_drawn": self.not_drawn, "collisions_left_out": self.collisions_left_out}


def parse_configuration(text: str | None) -> dict[str, float]:
    """``"joint_1=0.3,joint_2=-0.5"`` (radians or metres) -> mapping; raises UserError when malformed."""
    values: dict[str, float] = {}
    for item in (text or "").split(","):
        if not item.strip():
            continue
        name, sep, value = item.partition("=")
        try:
            number = float(value)
        except ValueError:
            sep = ""
        if not sep or not name.strip() or not math.isfinite(number):
            raise UserError(f"--config expects NAME=VALUE[,NAME=VALUE...] with finite numbers, got {item.strip()!r}")
        values[name.strip()] = number
    return values


def showing_collision_geometry(model: Model) -> Model:
    """A copy of ``model`` whose links *show* their collision shapes (in blue) instead of their visuals."""
    from lxml import etree

    root = copy.deepcopy(model.root)
    for link in root.iter("link"):
        for visual in link.findall("visual"):
            link.remove(visual)
        for collision in link.findall("collision"):
            visual = etree.SubElement(link, "visual")
            for child in collision:
                if child.tag in ("origin", "geometry"):
                    visual.append(copy.deepcopy(child))
            material = etree.SubElement(visual, "material", name="ar3cli_collision_geometry")
            etree.SubElement(material, "color", rgba=COLLISION_RGBA)
    overlay = copy.copy(model)
    overlay.root = root
    return overlay




def drawable_visuals(model: Model) -> tuple[Model, list[str]]:
    """``model``, or a copy whose visuals pybullet cannot load are replaced, and one warning per replacement.

    One unloadable visual (a ``.glb``, a missing mesh) makes pybullet refuse the whole robot, while
    everything else could be drawn: the visual is taken out and its link shows its collision shapes
    instead (in the collision colour), or nothing when they cannot be drawn either.
    """
    from lxml import etree

    from ar3cli.sim.loadable_copy import unloadable_mesh_reason, user_place

    def undrawable_reason(shape: Any) -> str | None:
        geometry = shape.element.find("geometry")
        reasons = (unloadable_mesh_reason(element, model.resolver) for element in (geometry if geometry is not None else ()))
        return next((reason for reason in reasons if reason is not None), None)

    broken = [(link, shape, reason) for link in model.links for shape in link.visuals
              if (reason := undrawable_reason(shape)) is not None]
    if not broken:
        return model, []
    root = copy.deepcopy(model.root)
    twin = dict(zip(model.root.iter(), root.iter()))
    warnings, replaced = [], set()
    for link, shape, reason in broken:
        twin[shape.element].getparent().remove(twin[shape.element])
        drawable = [c for c in link.collisions if undrawable_reason(c) is None and c.element.find("geometry") is not None]
        if drawable and link.name not in replaced:
            replaced.add(link.name)
            for collision in drawable:
                visual = etree.SubElement(twin[link.element], "visual")
                for child in collision.element:
                    if child.tag in ("origin", "geometry"):
                        visual.append(copy.deepcopy(child))
                material = etree.SubElement(visual, "material", name="ar3cli_collision_geometry")
                etree.SubElement(material, "color", rgba=COLLISION_RGBA)
        instead = "drawn as its collision shape instead" if drawable else "left out"
        place = user_place(model, shape.element)
        where = f" ({place.file}:{place.line})" if place is not None else ""
        warnings.append(f"render: warning: link '{link.name}'{where}: a visual cannot be drawn ({reason}); {instead}")
    overlay = copy.copy(model)
    overlay.root = root
    return overlay, warnings


WARNING_LINES = 2
"""At most this many warning lines on stderr: a robot whose every mesh is unreadable (Talos with
``package:///``: 45 visuals) gets the first and a count, not a screenful; JSON lists them all."""


def _warning_lines(warnings: list[str]) -> list[str]:
    """``warnings``, or the first ones and one line counting the rest (``visuals_not_drawn`` has them all)."""
    if len(warnings) <= WARNING_LINES:
        return warnings
    shown = warnings[:WARNING_LINES - 1]
    return [*shown, f"render: warning: and {len(warnings) - len(shown)} more visual(s) cannot be drawn "
                    "(--format json lists each in visuals_not_drawn)"]


View = tuple[Path, float, float]
"""One picture: (PNG file to write, camera yaw, camera pitch), degrees."""


def draw_robot(model: Model, output: Path, configuration: Mapping[str, float] | None = None,
               width: int = 800, height: int = 600, yaw_deg: float = 45.0, pitch_deg: float = -20.0,
               show_collision: bool = False, show_contacts: bool = True,
               warn: Callable[[str], None] | None = None) -> RenderResult:
    """Draw ``model`` at ``configuration`` (default: home pose) into the PNG file ``output``.

    ``warn`` receives the warning lines about visuals that could not be drawn (:func:`drawable_visuals`;
    at most :data:`WARNING_LINES`, the result's ``not_drawn`` lists each).
    """
    result = draw_views(model, [(output, yaw_deg, pitch_deg)], configuration, width, height, show_collision,
                        show_contacts, warn)[0]
    if isinstance(result, UserError):
        raise result
    return result


def draw_views(model: Model, views: Sequence[View], configuration: Mapping[str, float] | None = None,
               width: int = 800, height: int = 600, show_collision: bool = False, show_contacts: bool = True,
               warn: Callable[[str], None] | None = None) -> list[RenderResult | UserError]:
    """Draw ``model`` once per view, all in one pybullet child (the report's three sides load the robot
    once, not three times): per view its RenderResult, or the UserError of a picture that shows no
    robot. What makes every view impossible (no drawable visual, a model pybullet refuses) raises."""
    from PIL import Image

    from ar3cli.sim.loadable_copy import left_out_summary, unloadable_shapes
    from ar3cli.sim.session import run_pybullet

    if not 16 <= width <= 4096 or not 16 <= height <= 4096:
        raise UserError(f"image size {width}x{height} is out of range (16..4096 pixels per side)")
    for output, _yaw, _pitch in views:
        if not output.parent.is_dir():
            raise UserError(f"-o {output}: folder {output.parent} does not exist")
    shown, warnings = model, []
    if not show_collision:
        shown, warnings = drawable_visuals(model)
        for line in _warning_lines(warnings) if warn is not None else ():
            warn(line)
        if warnings and shown.root.find("link/visual") is None:
            collision = any(link.collisions for link in model.links)
            raise UserError(f"{model.path}: no visual geometry can be drawn ({len(warnings)} visual(s) left out, see the "
                            "warnings above); " + ("try --collision" if collision else "no link has <collision> either"))
    left_out = unloadable_shapes(shown, roles=("collision",))
    if left_out and warn is not None:
        drawn = "not drawn, and " if show_collision else ""
        warn(f"render: warning: {left_out_summary(left_out)}: pybullet cannot load it; {drawn}"
             "contacts with it are not checked")
    cameras = [(yaw, pitch) for _output, yaw, pitch in views]
    pictures, values, contacts = run_pybullet(
        lambda: _draw(shown, configuration or {}, width, height, cameras, show_collision, show_contacts), model)
    not_drawn = [warning.removeprefix("render: warning: ") for warning in warnings]
    results: list[RenderResult | UserError] = []
    for (output, _yaw, _pitch), rgb in zip(views, pictures):
        if picture_is_empty(rgb):
            results.append(UserError(f"{model.path}: the picture shows no robot: "
                                     f"{_why_nothing_shows(model, show_collision)}"))
            continue
        buffer = io.BytesIO()
        Image.fromarray(rgb).save(buffer, format="PNG")
        atomic_write(output, buffer.getvalue())
        results.append(RenderResult(output, width, height, values, contacts, not_drawn,
                                    [item.to_dict() for item in left_out]))
    return results


def _draw(model: Model, configuration: Mapping[str, float], width: int, height: int,
          cameras: Sequence[tuple[float, float]], show_collision: bool,
          show_contacts: bool) -> tuple[list[Any], dict[str, float], list]:
    """In pybullet: one RGB picture per camera (yaw, pitch), the joint values drawn, and the links in
    contact (drawn red)."""
    from ar3cli.infra.isolation import report_stage
    from ar3cli.sim.adjacency import nonadjacent_collisions
    from ar3cli.sim.session import SELF_COLLISION_ALL_PAIRS, Session

    with Session() as session:
        drawn = showing_collision_geometry(model) if show_collision else model
        body = session.load(drawn, self_collision=SELF_COLLISION_ALL_PAIRS, leave_out_unloadable=True)
        joints = {joint.name: joint for joint in body.actuated_joints}
        unknown = sorted(set(configuration) - set(joints))
        if unknown:
            raise UserError(f"--config names unknown joints: {listed(unknown)} "
                            f"(movable joints: {listed(joints) or 'none'})")
        values = configuration_with_mimics(body, configuration)
        body.set_positions(values)
        contacts = nonadjacent_collisions(body, model) if show_contacts else []
        for link_name in {name for a, b, _ in contacts for name in (a, b)}:
            session.p.changeVisualShape(body.id, body.link_index[link_name], rgbaColor=CONTACT_RGBA,
                                        physicsClientId=session.client)
        report_stage("rendering it")
        box = drawn_box(body, show_collision)
        return [_snapshot(session, box, width, height, yaw, pitch) for yaw, pitch in cameras], values, contacts


def _why_nothing_shows(model: Model, show_collision: bool) -> str:
    """The likeliest reason pybullet drew nothing, from what the model has to draw."""
    has_visual = any(link.visuals for link in model.links)
    has_collision = any(link.collisions for link in model.links)
    if not has_visual and not has_collision:
        return "no link has <visual> or <collision> geometry, so there is nothing to draw"
    if show_collision and not has_collision:
        return "no link has <collision> geometry (drop --collision to draw the visual geometry)"
    other = "" if show_collision or not has_collision else "try --collision, or "
    return (f"pybullet drew none of its geometry (a mesh it cannot read, or a flat shape seen from "
            f"behind or edge-on); {other}another --yaw/--pitch")


def picture_is_empty(rgb) -> bool:
    """True when every pixel has the background's colour: pybullet drew nothing of the robot."""
    return bool((rgb == rgb[0, 0]).all())


def configuration_with_mimics(body, configuration: Mapping[str, float]) -> dict[str, float]:
    """Every movable joint's value: the given ones, the other driving joints at home, and mimic
    joints following their source unless given explicitly (a robot cannot be in any other state)."""
    import numpy as np

    from ar3cli.sim.sampling import joint_space

    space = joint_space(body)
    driving = [configuration.get(name, space.home[index]) for index, name in zip(space.driving, space.driving_names)]
    values = space.as_dict(space.fill(np.array([driving], dtype=float))[0])
    values.update(configuration)
    return values


def drawn_box(body, show_collision: bool):
    """World (low, high) corners around what the picture shows: each link's drawn shapes (visual,
    or collision with ``--collision``) boxed in its frame and moved to the link's pose.

    pybullet's ``getAABB`` cannot be used: it boxes the *collision* shapes only, so a link drawn
    from its visual alone (pybullet_data's sphere2red_nocol) gets a millimetre box and the camera
    ends up inside the robot. A link whose shapes have no known box (an unreadable mesh) falls back
    to its ``getAABB``.
    """
    import numpy as np

    from ar3cli.urdf.bounds import shape_bounds

    p, client = body.session.p, body.session.client
    corners = []
    for name, (position, orientation) in body.link_frames().items():
        link = body.model.link(name)
        shapes = () if link is None else (link.collisions if show_collision else link.visuals or link.collisions)
        boxes = [box for box in map(shape_bounds, shapes) if box is not None]
        if not boxes and shapes:
            corners += list(p.getAABB(body.id, body.link_index[name], physicsClientId=client))
            continue
        rotation = np.reshape(p.getMatrixFromQuaternion(orientation), (3, 3))
        for low, high in boxes:
            local = np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])])
            corners += list(local @ rotation.T + np.asarray(position))
    if not corners:  # nothing with a box at all: frame the links' origins
        corners = [position for position, _ in body.link_frames().values()]
    points = np.asarray(corners, dtype=float)
    return points.min(axis=0), points.max(axis=0)


def _snapshot(session, box, width: int, height: int, yaw_deg: float, pitch_deg: float):
    """RGB array of the robot, camera aimed at the centre of ``box`` (world low and high corners)."""
    import numpy as np

    p, client = session.p, session.client
    lows, highs = box
    target = (lows + highs) / 2.0
    extent = float(np.linalg.norm(highs - lows))
    fov = 45.0
    distance = max(extent, 0.05) / (2.0 * math.tan(math.radians(fov) / 2.0)) * 1.1  # room for perspective
    view = p.computeViewMatrixFromYawPitchRoll(target.tolist(), distance, yaw_deg, pitch_deg, 0, 2,
                                               physicsClientId=client)
    projection = p.computeProjectionMatrixFOV(fov, width / height, distance / 100.0, distance * 10.0,
                                              physicsClientId=client)
    image = p.getCameraImage(width, height, view, projection, renderer=p.ER_TINY_RENDERER,
                             lightDirection=[1, 1, 2], shadow=0, physicsClientId=client)
    rgba = np.reshape(np.asarray(image[2], dtype=np.uint8), (height, width, 4))
    return np.ascontiguousarray(rgba[:, :, :3])
