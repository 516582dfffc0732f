"""Fixer edits on a xacro source, made through the expanded model's elements.

A fixer plans on the Model, whose elements are the *expansion*; for a ``.xacro`` file the bytes to
edit are the *source*. :class:`XacroDocument` is the :class:`~ar3cli.urdf.edits.Document` of the
source that a fixer's plan edits through the expanded elements: xacro's recorded origins
(:func:`~ar3cli.urdf.xacro_expand.origins`, the mapping lint findings use) lead from each expanded
element to the element written in the source, and an edit goes there when that is the same thing:

- the element is written in the file being fixed (not in a file it includes, not made by xacro),
- each attribute the fix reads or writes is literal text there (no ``${...}``, no ``$(...)``) and
  says what the expansion says,
- the element is written once for one use; an element of a macro body that several calls use is
  edited only where the fixer says its edit is the same for every use (a mesh URI: it depends on
  the URI text alone), never where one use may need it and another not (a joint's limits).

Anything else is refused with the reason (:meth:`XacroDocument.refusal`): the plan reports the
element as not fixed, and says where the value really comes from. Identical edits from several uses
of one macro body are made once. Lines in the fixer's report are the source's
(:meth:`XacroDocument.user_line`).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from xml.sax.saxutils import unescape

from ar3cli.urdf.edits import Document, Span

COMPUTED = ("${", "$(")
"""What makes an attribute value xacro's to compute, not literal text."""


@dataclass(frozen=True)
class Target:
    """An expanded element as the plan holds it: the source span it was written as (its index in
    :attr:`Document.spans`), or why there is none."""

    element: Any
    index: int | None
    reason: str | None
    origin: str
    """``FILE:LINE`` where xacro says the element was written (empty when xacro made it)."""


class XacroDocument(Document):
    """The bytes of a xacro source, edited through the elements of its expansion (``model.root``)."""

    def __init__(self, model: Any) -> None:
        super().__init__(model.source_bytes)
        self.model = model
        self._targets: dict[str, Target] = {}
        self._uses: dict[int, int] = {}
        self._lines: dict[int, int] = {}

    def bind(self, root: Any) -> dict[str, Span]:
        """Map every expanded element to the source element xacro read it from (see the module doc)."""
        from ar3cli.urdf.xacro_expand import origins

        elements = [element for element in root.iter() if isinstance(element.tag, str)]
        found = origins(self.model.xml_bytes) or []
        if len(found) != len(elements):
            found = [None] * len(elements)
        positions = self._positions()
        top = Path(self.model.path).resolve()
        tree = root.getroottree()
        self._tree = tree
        for element, origin in zip(elements, found):
            index, reason, where = None, None, ""
            if origin is None:
                reason = "made by xacro itself, not written in the source"
            else:
                where = f"{origin.file}:{origin.line}"
                if Path(origin.file).resolve() != top:
                    reason = f"written in {where}, a file the xacro includes: fix it there"
                else:
                    index = positions.get((origin.line, origin.column))
                    if index is None:
                        reason = f"not found at {where} in the source"
                    elif element.sourceline:
                        self._lines.setdefault(element.sourceline, origin.line)
            self._targets[tree.getpath(element)] = Target(element, index, reason, where)
            if index is not None:
                self._uses[index] = self._uses.get(index, 0) + 1
        self._by_path = {}
        return self._by_path

    def _positions(self) -> dict[tuple[int, int], int]:
        """(line, column) of each source element's start -> its index; columns in bytes and in characters."""
        positions: dict[tuple[int, int], int] = {}
        for index, span in enumerate(self.spans):
            line_start = self.data.rfind(b"\n", 0, span.start) + 1
            line = self.data.count(b"\n", 0, span.start) + 1
            prefix = self.data[line_start:span.start]
            positions.setdefault((line, len(prefix) + 1), index)
            positions.setdefault((line, len(prefix.decode("utf-8", "replace")) + 1), index)
        return positions

    # ---- what the plans ask ---------------------------------------------------------------------
    def span(self, element: Any) -> Any:
        """The :class:`Target` of an expanded element (the plans pass it back to the edit methods)."""
        return self._targets[self._tree.getpath(element)]

    def refusal(self, element: Any, attributes: Iterable[str] = (), same_for_every_use: bool = False) -> str | None:
        """Why ``element`` (an expanded element) cannot be edited in the source, reading or writing
        ``attributes``; None when it can. ``same_for_every_use``: the fixer's edit depends only on
        the text it edits, so an element a macro body gives several uses may be edited once for all."""
        target = self.span(element)
        if target.reason is not None:
            return f"<{element.tag}> is {target.reason}"
        span = self.spans[target.index]
        uses = self._uses.get(target.index, 0)
        if uses > 1 and not same_for_every_use:
            return (f"<{element.tag}> at {target.origin} is written once and used {uses} times (a macro body): "
                    "the fix may not suit every use; change the macro by hand")
        for name in attributes:
            written = span.attributes.get(name)
            expanded = element.get(name)
            if written is None:
                if expanded is not None:
                    return f"{name} of <{element.tag}> at {target.origin} is set by xacro, not written there"
                continue
            text = self.data[written.value_start:written.value_end].decode("utf-8", "replace")
            if any(marker in text for marker in COMPUTED):
                return (f"{name}=\"{text}\" of <{element.tag}> at {target.origin} is computed by xacro: change the "
                        "expression or the property it uses")
            if unescape(text, {"&quot;": '"', "&apos;": "'"}) != expanded:
                return f"{name} of <{element.tag}> at {target.origin} is not what xacro makes of it"
        return None

    def user_line(self, line: int) -> int:
        """The source line of the element on expansion line ``line`` (0 when it has none in this file)."""
        return self._lines.get(line, 0)

    # ---- edits: on the source span of each target ---------------------------------------------
    def _source(self, target: Any) -> Span:
        if not isinstance(target, Target) or target.index is None:
            raise AssertionError("a xacro edit without a source element: the plan must ask refusal() first")
        return self.spans[target.index]

    def set_attribute(self, span: Any, name: str, value: str) -> None:
        super().set_attribute(self._source(span), name, value)

    def remove_attribute(self, span: Any, name: str) -> None:
        super().remove_attribute(self._source(span), name)

    def remove_element(self, span: Any) -> None:
        super().remove_element(self._source(span))

    def insert_child(self, parent: Any, lines: list[str], after: Any = None, before: Any = None) -> None:
        super().insert_child(self._source(parent), lines, after=self._source(after) if after is not None else None,
                             before=self._source(before) if before is not None else None)

    def indentation(self, span: Any) -> bytes:
        return super().indentation(self._source(span) if isinstance(span, Target) else span)

    def apply(self) -> bytes:
        """The new source; the identical edits several uses of one macro body asked for are made once."""
        self._splices = list(dict.fromkeys(self._splices))
        return super().apply()
