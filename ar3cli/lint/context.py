"""What a lint rule sees: :class:`Context`, the model plus lazily built shared helpers."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

from ar3cli.urdf.bounds import Box, link_bounds, scaled_mesh_bounds, shape_bounds
from ar3cli.urdf.model import Link, Model, Shape

T = TypeVar("T")


class Context:
    """The model a rule checks, with the link boxes and the PyBullet session built once per file
    and shared by every rule that asks (pybullet is imported only when a ``--sim`` rule does)."""

    def __init__(self, model: Model, srdf_disabled: frozenset[frozenset[str]] = frozenset(),
                 targets: tuple[str, ...] = ("pybullet", "ros")) -> None:
        self.model = model
        self.srdf_disabled = srdf_disabled
        """Pairs the user's SRDF disables (``lint-urdf --srdf``; see :func:`ar3cli.urdf.srdf_read.is_disabled`)."""
        self.targets = targets
        """The engines the robot is meant for (``lint-urdf --target``): a rule whose verdict depends on
        the engine (a mesh MuJoCo finds through its own ``meshdir``) asks here."""
        self._bounds: dict[str, Box | None] = {}
        self._shape_bounds: dict[int, Box | None] = {}
        self._mesh_bounds: dict[tuple, Box | None] = {}
        self._session: Any = None
        self._shared: dict[str, Any] = {}

    def shared(self, key: str, build: Callable[[Model], T]) -> T:
        """``build(model)``, computed once per file for every rule that asks with the same ``key``
        (the schema rules' walk of the URDF elements: five rules, one walk)."""
        if key not in self._shared:
            self._shared[key] = build(self.model)
        return self._shared[key]

    def link_bounds(self, link: Link) -> Box | None:
        """Box around the link's collision (else visual) shapes in its frame, or None."""
        if link.name not in self._bounds:
            self._bounds[link.name] = link_bounds(link, self.shape_bounds)
        return self._bounds[link.name]

    def shape_bounds(self, shape: Shape) -> Box | None:
        """Box around one visual or collision shape in its link's frame, or None; computed once per
        shape for every rule that asks (the geometry and consistency rules ask for the same ones)."""
        key = id(shape)  # the model, and with it every shape, lives as long as this context
        if key not in self._shape_bounds:
            self._shape_bounds[key] = shape_bounds(shape, self.scaled_mesh_bounds)
        return self._shape_bounds[key]

    def scaled_mesh_bounds(self, geometry) -> Box | None:
        """:func:`~ar3cli.urdf.bounds.scaled_mesh_bounds`, once per mesh file and scale of this file:
        a link's visual and collision often share their mesh, and G006 asks for every mesh again
        (pybullet_data's 95 robots: 1,140 questions, 311 different answers)."""
        resolution = geometry.resolution
        if resolution is None or not resolution.found:
            return None  # what scaled_mesh_bounds answers without looking
        key = (resolution.path, geometry.params.get("scale"))
        if key not in self._mesh_bounds:
            self._mesh_bounds[key] = scaled_mesh_bounds(geometry)
        return self._mesh_bounds[key]

    @property
    def session(self) -> Any:
        """A PyBullet session (gravity on) for ``--sim`` rules, opened on first use."""
        if self._session is None:
            from ar3cli.sim.session import Session

            self._session = Session(gravity=-9.81, file_caching=True)
        return self._session

    def close(self) -> None:
        if self._session is not None:
            self._session.close()
            self._session = None
