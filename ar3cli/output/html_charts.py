"""Inline SVG charts for the HTML report: the self-collision matrix as a heat map (in the colours and
letters of ``sample-collisions --png``: :mod:`ar3cli.output.collision_palette`) and the gravity
torque margins as a bar chart. Plain data in (the JSON documents of sample-collisions and
``info --torques``), SVG text out; every name is escaped, every cell and bar has a ``<title>`` (the
browser's hover) and the legend says in words what each colour means."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ar3cli.output.collision_palette import (
    CATEGORY_COLOURS,
    CATEGORY_LETTERS,
    LEGEND,
    LIMIT_ONLY,
    RAMP,
    SCALE_LOW,
    SCALE_TICKS,
    SCALE_TITLE,
    hex_colour,
    ink,
    pair_colour,
    pair_letter,
    ramp_colour,
    scale_position,
)
from ar3cli.output.html_page import esc, number

MAX_MATRIX_PX = 760
LABEL_PX = 150
"""The most room the link names get (names longer than this are cut by the SVG's edge, the hover has them)."""
LETTER_PX = 12
"""Cells at least this large hold their letter (or count), as the PNG's do."""
SCALE_PX = 240
SCALE_STEPS = 48


def heat_map_svg(collisions: Mapping[str, Any]) -> str:
    """The lower triangle of the link-pair matrix in the PNG's colours and letters; hover
    (``<title>``) shows the pair, its category and the fraction of samples in collision. Cells
    touching at home get a black outline too."""
    links = [str(name) for name in collisions.get("links", [])]
    index = {name: at for at, name in enumerate(links)}
    count = len(links)
    if count < 2:
        return '<p class="muted">fewer than two links with collision geometry: no matrix.</p>'
    cell = max(3, min(18, MAX_MATRIX_PX // count))
    font = max(5, min(11, cell - 2))
    label = int(min(LABEL_PX, max(40, 0.62 * font * max(len(name) for name in links) + 10)))
    size = label + cell * count
    width = size + 10 + label // 2  # the last column's name leans right by half its length (rotated -60 degrees)
    parts = [f'<svg class="heat" width="{width}" height="{size + 10}" '
             f'viewBox="0 0 {width} {size + 10}" role="img" aria-label="self-collision matrix">']
    for at, name in enumerate(links):
        y = label + at * cell + cell * 0.75
        x = label + at * cell + cell * 0.75
        parts.append(f'<text x="{label - 4}" y="{y:.1f}" font-size="{font}" text-anchor="end">{esc(name)}</text>')
        parts.append(f'<text transform="translate({x:.1f},{label - 4}) rotate(-60)" font-size="{font}">'
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
        fill = pair_colour(str(pair.get("category")), float(pair.get("fraction") or 0.0))
        x, y = label + column * cell, label + row * cell
        parts.append(f'<rect x="{x}" y="{y}" width="{cell}" height="{cell}" fill="{hex_colour(fill)}"{outline} '
                     f'data-category="{esc(pair.get("category"))}" data-fraction="{esc(pair.get("fraction"))}">'
                     f'<title>{esc(tip)}</title></rect>')
        letter = pair_letter(str(pair.get("category")), int(pair.get("collisions") or 0))
        if letter and cell >= LETTER_PX and len(letter) <= max(1, cell // 6):
            parts.append(f'<text x="{x + cell / 2:.1f}" y="{y + cell / 2:.1f}" font-size="{max(6, cell - 8)}" '
                         f'text-anchor="middle" dominant-baseline="central" fill="{ink(fill)}" '
                         f'pointer-events="none">{esc(letter)}</text>')
    parts.append("</svg>")
    return "".join(parts) + heat_legend()


def heat_legend() -> str:
    """The colours of the heat map, each with its meaning in words, and the 'sometimes' scale with its
    numbers: the legend of ``sample-collisions --png``."""
    def swatch(fill: tuple[int, int, int], letter: str) -> str:
        return (f'<span class="swatch" style="background:{hex_colour(fill)};color:{ink(fill)}">'
                f'{esc(letter)}</span>')

    items = [swatch(CATEGORY_COLOURS[category], CATEGORY_LETTERS[category]) + f" {esc(text)}"
             for category, text in LEGEND]
    step = SCALE_PX / SCALE_STEPS
    bar = [f'<rect x="{i * step:.1f}" y="0" width="{step + 0.5:.1f}" height="14" '
           f'fill="{hex_colour(ramp_colour(i / (SCALE_STEPS - 1)))}"/>' for i in range(SCALE_STEPS)]
    ticks = []
    for tick in SCALE_TICKS:
        x = scale_position(tick) * SCALE_PX
        anchor = "start" if tick == SCALE_TICKS[0] else "end" if tick == SCALE_TICKS[-1] else "middle"
        label = f"{100 * tick:g}%" if tick > SCALE_LOW else f"&lt;= {100 * tick:g}%"
        ticks.append(f'<line x1="{x:.1f}" y1="14" x2="{x:.1f}" y2="18" stroke="#000"/>'
                     f'<text x="{x:.1f}" y="29" font-size="10" text-anchor="{anchor}">{label}</text>')
    scale = (f'<svg width="{SCALE_PX + 2}" height="32" viewBox="-1 0 {SCALE_PX + 2} 32" role="img" '
             f'aria-label="colour scale of the sometimes category">{"".join(bar)}'
             f'<rect x="0" y="0" width="{SCALE_PX}" height="14" fill="none" stroke="#5a5a5a"/>{"".join(ticks)}</svg>')
    return (f'<p class="legend">{"&nbsp; ".join(items)}</p><p class="legend">{esc(SCALE_TITLE)}<br>{scale} '
            f'{swatch(RAMP[0], LIMIT_ONLY)} only at a joint limit</p>')


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
