"""The self-collision pair matrix as a picture (PNG), for READMEs, reviews and CI artifacts.

Lower triangle, one cell per pair of links with collision geometry, the link names on both axes
(rows on the left, columns underneath), in the colours and letters of
:mod:`ar3cli.output.collision_palette` (the report page's heat map uses the same); a ``sometimes``
cell holds the count of colliding samples when it fits in the cell. Under the matrix, the legend:
one swatch per category and the colour scale with its numbers. Drawn with Pillow.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from typing import Any

from ar3cli.collisions.matrix import PairResult
from ar3cli.output.collision_palette import (
    CATEGORY_COLOURS,
    CATEGORY_LETTERS,
    LEGEND,
    LIMIT_ONLY,
    RAMP,
    SCALE_LOW,
    SCALE_TICKS,
    SCALE_TITLE,
    ink,
    pair_colour,
    pair_letter,
    ramp_colour,
    scale_position,
)

CELL = 36
MARGIN = 12
BAR_WIDTH = 240
BAR_HEIGHT = 14


def cell_colour(result: PairResult) -> tuple[int, int, int]:
    """The fill of one pair's cell: its category's colour, or the scale colour of its fraction for 'sometimes'."""
    return pair_colour(result.category, result.fraction)


def cell_text(result: PairResult) -> str:
    """What a cell says: the category letter, the count of colliding samples, or L (limits only)."""
    return pair_letter(result.category, result.collisions)


def heat_map_png(links: Sequence[str], pairs: Sequence[tuple[int, int]], results: Sequence[PairResult],
                 title: str = "") -> bytes:
    """PNG bytes of the lower-triangular link x link matrix with its legend."""
    image, _ = heat_map_image(links, pairs, results, title)
    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    return buffer.getvalue()


def heat_map_image(links: Sequence[str], pairs: Sequence[tuple[int, int]], results: Sequence[PairResult],
                   title: str = "") -> tuple[Any, dict[str, tuple[int, int, int, int]]]:
    """The Pillow image and where its parts are: ``{"grid", "legend", "scale"}`` boxes (left, top,
    right, bottom), for tests."""
    from PIL import Image, ImageDraw, ImageFont

    font = _font(ImageFont, 13)
    small = _font(ImageFont, 11)
    cell = {pair: result for pair, result in zip(pairs, results)}
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    label_width = max((probe.textlength(name, font=font) for name in links), default=0) + 10
    top = MARGIN + (24 if title else 0)
    count = max(len(links) - 1, 1)
    grid = CELL * count
    scale_title = SCALE_TITLE
    legend_width = max(probe.textlength(scale_title, font=small),
                       max(probe.textlength(text, font=font) for _, text in LEGEND) + 26,
                       BAR_WIDTH + probe.textlength(f"{LIMIT_ONLY}  only at a joint limit", font=font) + 40)
    width = int(max(MARGIN + label_width + grid + MARGIN, MARGIN + legend_width + MARGIN,
                    MARGIN + (probe.textlength(title, font=font) if title else 0) + MARGIN))
    legend_top = int(top + grid + 10 + label_width + 8)
    rows_height = 20 * len(LEGEND)
    scale_top = legend_top + rows_height + 8
    height = scale_top + 18 + BAR_HEIGHT + 18 + MARGIN
    image = Image.new("RGB", (width, height), "white")
    draw = ImageDraw.Draw(image)
    if title:
        draw.text((MARGIN, MARGIN), title, fill="black", font=font)
    left = MARGIN + label_width
    for row in range(1, len(links)):
        y = top + (row - 1) * CELL
        draw.text((left - 6, y + CELL / 2), links[row], fill="black", font=font, anchor="rm")
        for column in range(row):
            result = cell.get((column, row))
            x = left + column * CELL
            if result is None:
                continue
            fill = cell_colour(result)
            draw.rectangle((x, y, x + CELL - 2, y + CELL - 2), fill=fill)
            text = cell_text(result)
            chosen = font if len(text) <= 2 else small
            if text and probe.textlength(text, font=chosen) <= CELL - 6:
                draw.text((x + CELL / 2 - 1, y + CELL / 2 - 1), text, fill=ink(fill), font=chosen, anchor="mm")
    columns = Image.new("RGB", (int(label_width), grid), "white")
    column_draw = ImageDraw.Draw(columns)
    for column in range(len(links) - 1):
        column_draw.text((label_width - 6, column * CELL + CELL / 2), links[column], fill="black", font=font,
                         anchor="rm")
    image.paste(columns.rotate(90, expand=True), (int(left), int(top + grid + 6)))
    y = legend_top
    for category, text in LEGEND:
        colour = CATEGORY_COLOURS[category]
        draw.rectangle((MARGIN, y, MARGIN + 16, y + 16), fill=colour)
        letter = CATEGORY_LETTERS[category]
        if letter:
            draw.text((MARGIN + 8, y + 8), letter, fill=ink(colour), font=small, anchor="mm")
        draw.text((MARGIN + 24, y + 8), text, fill="black", font=font, anchor="lm")
        y += 20
    draw.text((MARGIN, scale_top), scale_title, fill="black", font=small)
    bar_top = scale_top + 18
    for i in range(BAR_WIDTH):
        draw.line((MARGIN + i, bar_top, MARGIN + i, bar_top + BAR_HEIGHT), fill=ramp_colour(i / (BAR_WIDTH - 1)))
    draw.rectangle((MARGIN, bar_top, MARGIN + BAR_WIDTH, bar_top + BAR_HEIGHT), outline=(90, 90, 90))
    for tick in SCALE_TICKS:
        x = MARGIN + scale_position(tick) * BAR_WIDTH
        draw.line((x, bar_top + BAR_HEIGHT, x, bar_top + BAR_HEIGHT + 3), fill="black")
        label = f"{100 * tick:g}%" if tick > SCALE_LOW else f"<= {100 * tick:g}%"
        anchor = "la" if tick == SCALE_TICKS[0] else "ra" if tick == SCALE_TICKS[-1] else "ma"
        draw.text((x, bar_top + BAR_HEIGHT + 4), label, fill="black", font=small, anchor=anchor)
    swatch = MARGIN + BAR_WIDTH + 24
    draw.rectangle((swatch, bar_top - 1, swatch + 16, bar_top + 15), fill=RAMP[0])
    draw.text((swatch + 8, bar_top + 7), LIMIT_ONLY, fill="black", font=small, anchor="mm")
    draw.text((swatch + 24, bar_top + 7), "only at a joint limit", fill="black", font=font, anchor="lm")
    boxes = {"grid": (int(left), int(top), int(left + grid), int(top + grid)),
             "legend": (MARGIN, legend_top, width - MARGIN, height - MARGIN),
             "scale": (MARGIN, bar_top, MARGIN + BAR_WIDTH, bar_top + BAR_HEIGHT)}
    return image, boxes


def _font(image_font, size: int):
    """Pillow's built-in scalable font (Pillow >= 10.1); the tiny bitmap font on older versions."""
    try:
        return image_font.load_default(size=size)
    except TypeError:  # pragma: no cover - Pillow < 10.1
        return image_font.load_default()
