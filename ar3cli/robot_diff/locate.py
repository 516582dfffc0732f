"""Where NEW writes an element: the file and line a reviewer should look at (for a ``.xacro`` file,
the source file and line xacro read it from, as the linter reports them)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ar3cli.urdf.model import Model


class Locator:
    """``locate(element) -> (file, line)`` in a model; ``show`` turns a real path into what the user
    knows (a revision's temporary copy back into ``REV:path``)."""

    def __init__(self, model: Model, shown: str, show: Callable[[str], str] = str) -> None:
        self.model = model
        self.shown = shown
        self.show = show
        self._origins: dict[Any, Any] | None = None
        if model.is_xacro:  # now: the loader keeps the origins of its last few expansions only
            self._element_origins()

    def locate(self, element: Any) -> tuple[str, int]:
        if element is None:
            return self.shown, 0
        if not self.model.is_xacro:
            return self.shown, element.sourceline or 0
        origins = self._element_origins()
        node = element
        while node is not None:
            origin = origins.get(node)
            if origin is not None:
                return (self.shown if origin.file == str(self.model.path) else self.show(origin.file)), origin.line
            node = node.getparent()
        return self.shown, 0

    def _element_origins(self) -> dict[Any, Any]:
        if self._origins is None:
            from ar3cli.urdf.xacro_expand import origins

            found = origins(self.model.xml_bytes) or []
            elements = [node for node in self.model.root.iter() if isinstance(node.tag, str)]
            self._origins = dict(zip(elements, found)) if len(found) == len(elements) else {}
        return self._origins
