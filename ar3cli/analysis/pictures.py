"""The robot from three sides, with its visual and with its collision geometry: render's drawing
(TinyRenderer, in a pybullet child per geometry), links in contact at home in red."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ar3cli.analysis.robot import RobotAnalysis, question
from ar3cli.errors import UserError

VIEWS = (("front", 0.0, -10.0), ("side", 90.0, -10.0), ("top", 0.0, -89.0))
"""(name, camera yaw, camera pitch) of the three pictures, each drawn with the visual and the collision geometry."""
PICTURE_SIZE = (360, 300)
GEOMETRIES = ("visual", "collision")


@dataclass(frozen=True)
class Picture:
    """One side of one geometry: the PNG, or why it was not drawn. ``facts`` is render's JSON for it
    (size, the joint values drawn, the contacts, the visuals left out), without the file path."""

    side: str
    geometry: str
    png: bytes | None = None
    error: str | None = None
    facts: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The entry of the report's data island (no PNG bytes)."""
        entry: dict[str, Any] = {"side": self.side, "geometry": self.geometry}
        if self.error is not None:
            entry["error"] = self.error
        entry.update(self.facts)
        return entry


@dataclass(frozen=True)
class Pictures:
    """The pictures in order (visual front, side, top; collision front, side, top; a geometry that
    cannot be drawn at all is one entry with its reason) and render's warnings (visuals left out)."""

    pictures: list[Picture]
    notes: list[str]

    def contacts_at_home(self) -> dict[tuple[str, str], float]:
        """(link a, link b) -> penetration depth (m, negative) of the pairs drawn red."""
        return {(contact["link_a"], contact["link_b"]): contact["depth_m"]
                for picture in self.pictures for contact in picture.facts.get("contacts", [])}


@question
def pictures(analysis: RobotAnalysis) -> Pictures:
    """Both geometries' three sides; each geometry's sides are drawn in one pybullet child."""
    import tempfile

    from ar3cli.pictures.draw import draw_views

    model = analysis.require_model()
    drawn_pictures: list[Picture] = []
    notes: list[str] = []
    with tempfile.TemporaryDirectory(prefix="ar3cli-pictures-") as folder:
        for geometry in GEOMETRIES:
            views = [(Path(folder) / f"{geometry}-{side}.png", yaw, pitch) for side, yaw, pitch in VIEWS]
            try:
                drawn: list = draw_views(model, views, None, *PICTURE_SIZE, show_collision=geometry == "collision",
                                         warn=notes.append)
            except UserError as exc:
                drawn = [exc] * len(views)
            for (side, _yaw, _pitch), (target, _, _), result in zip(VIEWS, views, drawn):
                if isinstance(result, UserError):
                    drawn_pictures.append(Picture(side, geometry, error=result.message))
                    if geometry == "visual":
                        break  # the same reason for the other sides
                    continue
                facts = result.to_dict()
                del facts["path"]
                drawn_pictures.append(Picture(side, geometry, png=target.read_bytes(), facts=facts))
    return Pictures(drawn_pictures, notes)
