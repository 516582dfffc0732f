"""``ar3cli info --png``: the kinematic tree as a picture, drawn with Pillow.

Top-down by depth: each link is a box (the root with a thick border, end effectors pale yellow,
the name of a link without mass in grey), and above each child box the joint that leads to it, its name
and type, in the joint type's colour; elbow connectors join a parent's box to its children's joint
labels. Each subtree gets its own column span (its width is the larger of its own labels and the
sum of its children's spans), so no two labels overlap however many links there are; the canvas
grows with the tree. Links no root reaches are drawn as extra roots; a joint that leads back to a
link already drawn (a loop) is listed under the picture, not drawn.
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field

from ar3cli.errors import UserError
from ar3cli.info.summary import JointInfo, Summary

FONT_SIZE = 13
SMALL_SIZE = 11
PAD = 8
"""px of padding inside a box and between sibling columns."""
BOX_HEIGHT = 26
LABEL_HEIGHT = 30
"""Two lines of joint label (name, type) above each non-root box."""
GAP = 26
"""Vertical space between a parent box and its children's joint labels (the connectors run here)."""
MARGIN = 16
MAX_SIDE = 32_000
"""px: a larger picture is refused (a chain of thousands of links would need gigabytes to draw)."""

JOINT_COLOURS = {
    "revolute": (31, 100, 200),
    "continuous": (130, 60, 190),
    "prismatic": (20, 140, 70),
    "fixed": (120, 120, 120),
    "floating": (220, 110, 0),
    "planar": (220, 110, 0),
    "spherical": (220, 110, 0),
}
OTHER_JOINT = (200, 40, 40)
LINK_FILL = (235, 242, 252)
LEAF_FILL = (255, 246, 200)
UNREACHABLE_FILL = (250, 225, 225)


@dataclass
class _Node:
    link: str
    joint: JointInfo | None
    depth: int
    children: list[_Node] = field(default_factory=list)
    own: float = 0.0
    span: float = 0.0
    x: float = 0.0
    unreachable: bool = False


def tree_png(summary: Summary) -> bytes:
    """PNG bytes of the kinematic tree of ``summary``; UserError when it would be too large to draw."""
    from PIL import Image, ImageDraw, ImageFont

    font, small = _font(ImageFont, FONT_SIZE), _font(ImageFont, SMALL_SIZE)
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    roots, loops = _build(summary)
    nodes = [node for root in roots for node in _preorder(root)]
    masses = {link.name: link for link in summary.links}
    for node in nodes:
        widths = [probe.textlength(_link_text(node), font=font) + 2 * PAD]
        if node.joint is not None:
            widths += [probe.textlength(node.joint.name, font=small) + PAD,
                       probe.textlength(_joint_type(node.joint), font=small) + PAD]
        node.own = max(widths) + PAD
    for node in reversed(nodes):  # children before parents
        node.span = max(node.own, sum(child.span for child in node.children))
    depth = max((node.depth for node in nodes), default=0)
    level = LABEL_HEIGHT + BOX_HEIGHT + GAP
    legend = _legend_items(summary)
    legend_width = sum(probe.textlength(text, font=small) + 34 for text, _ in legend)
    title = f"kinematic tree of {summary.name or summary.path.name}: {len(summary.links)} links, " \
            f"{len(summary.joints)} joints, DOF {summary.dof}"
    notes = [f"not drawn (loop): joint {joint.name} -> {joint.child}" for joint in loops]
    width = MARGIN * 2 + max(sum(root.span for root in roots), legend_width, probe.textlength(title, font=font),
                             *(probe.textlength(note, font=small) for note in notes))
    top = MARGIN + 24 + 22
    height = top + (depth + 1) * level + len(notes) * 16 + MARGIN
    if width > MAX_SIDE or height > MAX_SIDE:
        raise UserError(f"{summary.path}: the tree picture would be {int(width)} x {int(height)} px "
                        f"({len(summary.links)} links, depth {depth}); at most {MAX_SIDE} px a side is drawn")
    image = Image.new("RGB", (int(width), int(height)), "white")
    draw = ImageDraw.Draw(image)
    draw.text((MARGIN, MARGIN), title, fill="black", font=font)
    x = MARGIN
    for text, colour in legend:
        draw.line((x, MARGIN + 31, x + 22, MARGIN + 31), fill=colour, width=3)
        draw.text((x + 26, MARGIN + 31), text, fill=colour, font=small, anchor="lm")
        x += probe.textlength(text, font=small) + 34
    offset = MARGIN
    for root in roots:
        _place(root, offset)
        offset += root.span
    for node in nodes:
        y = top + node.depth * level  # top of the joint label; the box starts LABEL_HEIGHT below
        box_top = y + LABEL_HEIGHT
        half = (node.own - PAD) / 2
        if node.joint is not None:
            colour = JOINT_COLOURS.get(node.joint.type, OTHER_JOINT)
            draw.text((node.x, y + 1), node.joint.name, fill=colour, font=small, anchor="ma")
            draw.text((node.x, y + 15), _joint_type(node.joint), fill=colour, font=small, anchor="ma")
        link = masses.get(node.link)
        fill = UNREACHABLE_FILL if node.unreachable else LEAF_FILL if not node.children else LINK_FILL
        box = (node.x - half, box_top, node.x + half, box_top + BOX_HEIGHT)
        draw.rounded_rectangle(box, radius=5, fill=fill, outline="black", width=3 if node.depth == 0 else 1)
        massless = link is not None and link.mass_note != ""
        draw.text((node.x, box_top + BOX_HEIGHT / 2), _link_text(node), fill=(110, 110, 110) if massless else "black",
                  font=font, anchor="mm")
        if node.children:
            bottom, middle = box_top + BOX_HEIGHT, box_top + BOX_HEIGHT + GAP / 2
            xs = [child.x for child in node.children]
            draw.line((node.x, bottom, node.x, middle), fill="black", width=1)
            draw.line((min(xs + [node.x]), middle, max(xs + [node.x]), middle), fill="black", width=1)
            for child in node.children:
                colour = JOINT_COLOURS.get(child.joint.type, OTHER_JOINT) if child.joint else "black"
                draw.line((child.x, middle, child.x, bottom + GAP - 1), fill=colour, width=2)
    y = top + (depth + 1) * level
    for note in notes:
        draw.text((MARGIN, y), note, fill=OTHER_JOINT, font=small)
        y += 16
    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    return buffer.getvalue()


def _build(summary: Summary) -> tuple[list[_Node], list[JointInfo]]:
    """The drawn trees (roots, then unreachable links as extra roots) and the loop joints left out.
    Iterative: a chain of thousands of links must not hit Python's recursion limit."""
    children: dict[str | None, list[JointInfo]] = {}
    for joint in summary.joints:
        children.setdefault(joint.parent, []).append(joint)
    seen: set[str] = set()
    loops: list[JointInfo] = []
    roots: list[_Node] = []
    starts = [(name, False) for name in summary.roots] + [(name, True) for name in summary.unreachable]
    for name, unreachable in starts:
        if name in seen:
            continue
        root = _Node(name, None, 0, unreachable=unreachable)
        seen.add(name)
        stack = [root]
        while stack:
            node = stack.pop()
            for joint in children.get(node.link, []):
                child = joint.child or "?"
                if child in seen:
                    loops.append(joint)
                    continue
                seen.add(child)
                grown = _Node(child, joint, node.depth + 1, unreachable=unreachable)
                node.children.append(grown)
                stack.append(grown)
        roots.append(root)
    return roots, loops


def _preorder(root: _Node) -> list[_Node]:
    order, stack = [], [root]
    while stack:
        node = stack.pop()
        order.append(node)
        stack += reversed(node.children)
    return order


def _place(root: _Node, left: float) -> None:
    """Centre each node over its column span; children share the span side by side."""
    stack = [(root, left)]
    while stack:
        node, start = stack.pop()
        node.x = start + node.span / 2
        inner = start + (node.span - sum(child.span for child in node.children)) / 2
        for child in node.children:
            stack.append((child, inner))
            inner += child.span


def _link_text(node: _Node) -> str:
    return node.link + ("  (not reachable)" if node.unreachable and node.depth == 0 else "")


def _joint_type(joint: JointInfo) -> str:
    return joint.type + (f", follows {joint.mimic['joint']}" if joint.mimic is not None else "")


def _legend_items(summary: Summary) -> list[tuple[str, tuple[int, int, int]]]:
    """The joint types present, in a fixed order."""
    present = {joint.type for joint in summary.joints}
    items = [(kind, colour) for kind, colour in JOINT_COLOURS.items() if kind in present]
    items += [(kind, OTHER_JOINT) for kind in sorted(present - set(JOINT_COLOURS))]
    return items


def _font(image_font, size: int):
    """Pillow's built-in scalable font (Pillow >= 10.1); the tiny bitmap font on older versions."""
    try:
        return image_font.load_default(size=size)
    except TypeError:  # pragma: no cover - Pillow < 10.1
        return image_font.load_default()
