"""Inline SVG charts for the HTML report: the self-collision matrix as a heat map and the gravity
torque margins as a bar chart. Plain data in (the JSON documents of sample-collisions and
``info --torques``), SVG text out; every name is escaped, every cell and bar has a ``<title>`` (the
browser's hover) and the legend says in words what each colour means."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ar3cli.output.html_page import esc, number

RAMP = ("#ffffcc", "#c7e9b4", "#7fcdbb", "#41b6c4", "#1d91c0", "#225ea8", "#0c2c84")
"""ColorBrewer YlGnBu: sequential, readable with every common colour-vision deficiency and in grey."""
CATEGORY_FILL = {"adjacent": "#bdbdbd", "never": "#ffffff", "default": "#D55E00"}
"""Fixed fills; 'sometimes' and 'always' take the ramp by fraction (always is its dark end)."""
MAX_MATRIX_PX = 760
LABEL_PX = 150


def ramp(fraction: float) -> str:
    """The ramp colour of a collision fraction in [0, 1]."""
    position = min(max(fraction, 0.0), 1.0) ** 0.5  # small fractions stay visible
    return RAMP[min(int(position * (len(RAMP) - 1) + 0.5), len(RAMP) - 1)]


def cell_fill(pair: Mapping[str, Any]) -> str:
    category = str(pair.get("category"))
    if category in CATEGORY_FILL:
        return CATEGORY_FILL[category]
    return ramp(float(pair.get("fraction") or 0.0))


def heat_map_svg(collisions: Mapping[str, Any]) -> str:
    """The lower triangle of the link-pair matrix; hover (``<title>``) shows the pair, its category
    and the fraction of samples in collision. Cells touching at home get a black outline too."""
    links = [str(name) for name in collisions.get("links", [])]
    index = {name: at for at, name in enumerate(links)}
    count = len(links)
    if count < 2:
        return '<p class="muted">fewer than two links with collision geometry: no matrix.</p>'
    cell = max(3, min(18, MAX_MATRIX_PX // count))
    font = max(5, min(11, cell - 2))
    size = LABEL_PX + cell * count
    parts = [f'<svg class="heat" width="{size + 10}" height="{size + 10}" '
             f'viewBox="0 0 {size + 10} {size + 10}" role="img" aria-label="self-collision matrix">']
    for at, name in enumerate(links):
        y = LABEL_PX + at * cell + cell * 0.75
        x = LABEL_PX + at * cell + cell * 0.75
        parts.append(f'<text x="{LABEL_PX - 4}" y="{y:.1f}" font-size="{font}" text-anchor="end">{esc(name)}</text>')
        parts.append(f'<text transform="translate({x:.1f},{LABEL_PX - 4}) rotate(-60)" font-size="{font}">'
                     f'{esc(name)}</text>')
    samples = collisions.get("samples")
    for pair in collisions.get("pairs", []):
        a, b = index.get(str(pair.get("link_a"))), index.get(str(pair.get("link_b")))
        if a is None or b is None:
            continue
        row, column = max(a, b), min(a, b)
        at_home = bool(pair.get("at_home"))
        sampled = bool(pair.get("sampled"))
        fraction = f"fraction {number(pair.get('fraction'))} ({pair.get('collisions')} of {samples})" if sampled \
            else "not sampled (a link and its parent)"
        tip = f"{pair.get('link_a')} / {pair.get('link_b')}: {pair.get('category')}, {fraction}" + \
            ("; in contact at home" if at_home else "")
        outline = ' stroke="#000" stroke-width="1"' if at_home else ' stroke="#e0e0e0" stroke-width="0.5"'
        parts.append(f'<rect x="{LABEL_PX + column * cell}" y="{LABEL_PX + row * cell}" width="{cell}" height="{cell}" '
                     f'fill="{cell_fill(pair)}"{outline} data-category="{esc(pair.get("category"))}" '
                     f'data-fraction="{esc(pair.get("fraction"))}"><title>{esc(tip)}</title></rect>')
    parts.append("</svg>")
    return "".join(parts) + heat_legend()


def heat_legend() -> str:
    """The colours of the heat map, each with its meaning in words."""
    items = [(CATEGORY_FILL["adjacent"], "adjacent (a link and its parent: not checked)"),
             (CATEGORY_FILL["never"], "never collided"),
             (CATEGORY_FILL["default"], "default: in contact at the home pose (outlined)"),
             (ramp(0.01), "sometimes: 1% of samples"), (ramp(0.2), "20%"), (ramp(0.6), "60%"),
             (ramp(1.0), "always: 95% or more")]
    return "<p>" + " ".join(f'<span style="display:inline-block;width:1em;height:1em;background:{fill};'
                            f'border:1px solid #555;vertical-align:middle"></span> {esc(text)}&nbsp;'
                            for fill, text in items) + "</p>"


BAR_PX = 360
ROW_PX = 20
NAME_PX = 190
STATUS_FILL = {"ok": "#0072B2", "too weak": "#D55E00"}


def torque_chart_svg(torques: Mapping[str, Any]) -> str:
    """One bar per actuated joint: the largest gravity torque it needs as a share of its declared
    effort (100% = the limit, drawn as a dashed line; bars stop at 200%), with the numbers and the
    status in words beside it. Joints without an effort get no bar, only the words."""
    joints = list(torques.get("joints", []))
    if not joints:
        return '<p class="muted">no actuated joint.</p>'
    height = ROW_PX * len(joints) + 30
    width = NAME_PX + BAR_PX + 330
    limit_x = NAME_PX + BAR_PX / 2
    parts = [f'<svg width="{width}" height="{height}" viewBox="0 0 {width} {height}" '
             'role="img" aria-label="gravity torque against declared effort per joint">',
             f'<text x="{NAME_PX}" y="12" font-size="11">0%</text>'
             f'<text x="{limit_x - 12:.0f}" y="12" font-size="11">100% of effort</text>'
             f'<text x="{NAME_PX + BAR_PX - 30}" y="12" font-size="11">200%</text>']
    for row, joint in enumerate(joints):
        y = 20 + row * ROW_PX
        needed, effort, status = joint.get("needed"), joint.get("effort"), str(joint.get("status"))
        unit = esc(joint.get("unit"))
        parts.append(f'<text x="{NAME_PX - 6}" y="{y + 13}" font-size="11" text-anchor="end">{esc(joint.get("joint"))}'
                     '</text>')
        if effort:
            share = float(needed or 0.0) / float(effort)
            length = min(share, 2.0) * BAR_PX / 2
            tip = f"{joint.get('joint')}: needs {number(needed)} {joint.get('unit')} at {joint.get('at')}, " \
                  f"declares {number(effort)}; margin {number(joint.get('margin'), 3)}; {status}"
            parts.append(f'<rect x="{NAME_PX}" y="{y + 3}" width="{max(length, 1):.1f}" height="{ROW_PX - 6}" '
                         f'fill="{STATUS_FILL.get(status, "#999")}" data-joint-share="{share:.6g}">'
                         f'<title>{esc(tip)}</title></rect>')
            words = f"{number(needed)} of {number(effort)} {unit}, margin {number(joint.get('margin'), 3)}"
        else:
            words = f"{number(needed)} {unit} needed"
        parts.append(f'<text x="{NAME_PX + BAR_PX + 8}" y="{y + 13}" font-size="11">{words}: '
                     f'<tspan font-weight="bold">{esc(status)}</tspan></text>')
    parts.append(f'<line x1="{limit_x}" y1="16" x2="{limit_x}" y2="{height}" stroke="#000" stroke-dasharray="4 3"/>'
                 f'<line x1="{NAME_PX}" y1="16" x2="{NAME_PX}" y2="{height}" stroke="#555"/></svg>')
    return "".join(parts)
