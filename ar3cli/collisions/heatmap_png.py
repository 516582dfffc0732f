"""The self-collision pair matrix as a picture (PNG), for READMEs, reviews and CI artifacts.

Lower triangle, one cell per pair of links with collision geometry. Colour says the category
(MoveIt's): adjacent grey-blue, default red, always magenta, never pale green, sometimes a yellow to
orange ramp by the colliding fraction (its percentage is written in the cell). The same data as
the terminal heat map (:func:`ar3cli.collisions.matrix.heat_map`), drawn with Pillow.
"""

from __future__ import annotations

import io
from collections.abc import Sequence

from ar3cli.collisions.matrix import PairResult

CELL = 34
MARGIN = 12
CATEGORY_COLOURS = {
    "adjacent": (120, 144, 180),
    "default": (214, 48, 49),
    "always": (170, 60, 170),
    "never": (214, 240, 214),
}
SOMETIMES_LOW, SOMETIMES_HIGH = (255, 236, 140), (240, 120, 20)
LEGEND = [("adjacent", CATEGORY_COLOURS["adjacent"]), ("default (at home)", CATEGORY_COLOURS["default"]),
          ("always", CATEGORY_COLOURS["always"]), ("never", CATEGORY_COLOURS["never"]),
          ("sometimes (% of samples)", SOMETIMES_HIGH)]


def cell_colour(result: PairResult) -> tuple[int, int, int]:
    """The fill of one pair's cell: its category's colour, or a ramp by fraction for 'sometimes'."""
    if result.category != "sometimes":
        return CATEGORY_COLOURS[result.category]
    t = min(1.0, result.fraction * 2.0)  # most 'sometimes' pairs collide rarely; saturate at 50%
    return tuple(round(lo + (hi - lo) * t) for lo, hi in zip(SOMETIMES_LOW, SOMETIMES_HIGH))  # type: ignore[return-value]


def heat_map_png(links: Sequence[str], pairs: Sequence[tuple[int, int]], results: Sequence[PairResult],
                 title: str = "") -> bytes:
    """PNG bytes of the lower-triangular link x link matrix."""
    from PIL import Image, ImageDraw, ImageFont

    font = _font(ImageFont, 13)
    small = _font(ImageFont, 10)
    cell = {pair: result for pair, result in zip(pairs, results)}
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    label_width = max((probe.textlength(name, font=font) for name in links), default=0) + 10
    top = MARGIN + (24 if title else 0)
    grid = CELL * max(len(links) - 1, 1)
    width = int(MARGIN + label_width + grid + MARGIN)
    height = int(top + grid + 10 + label_width + 20 * len(LEGEND) + MARGIN)
    image = Image.new("RGB", (max(width, 340), height), "white")
    draw = ImageDraw.Draw(image)
    if title:
        draw.text((MARGIN, MARGIN), title, fill="black", font=font)
    left = MARGIN + label_width
    for row in range(1, len(links)):
        y = top + (row - 1) * CELL
        draw.text((left - 6, y + CELL / 2), links[row], fill="black", font=font, anchor="rm")
        for column in range(row):
            result = cell[(column, row)]
            x = left + column * CELL
            draw.rectangle((x, y, x + CELL - 2, y + CELL - 2), fill=cell_colour(result))
            if result.category == "sometimes" and result.collisions:
                percent = 100 * result.fraction
                label = "<1" if percent < 0.5 else f"{percent:.0f}"
                draw.text((x + CELL / 2 - 1, y + CELL / 2 - 1), label, fill="black", font=small, anchor="mm")
    columns = Image.new("RGB", (int(label_width), CELL * max(len(links) - 1, 1)), "white")
    column_draw = ImageDraw.Draw(columns)
    for column in range(len(links) - 1):
        column_draw.text((label_width - 6, column * CELL + CELL / 2), links[column], fill="black", font=font,
                         anchor="rm")
    image.paste(columns.rotate(90, expand=True), (int(left), int(top + grid + 6)))
    y = top + grid + 10 + label_width
    for name, colour in LEGEND:
        draw.rectangle((MARGIN, y, MARGIN + 14, y + 14), fill=colour)
        draw.text((MARGIN + 20, y + 7), name, fill="black", font=font, anchor="lm")
        y += 20
    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    return buffer.getvalue()


def _font(image_font, size: int):
    """Pillow's built-in scalable font (Pillow >= 10.1); the tiny bitmap font on older versions."""
    try:
        return image_font.load_default(size=size)
    except TypeError:  # pragma: no cover - Pillow < 10.1
        return image_font.load_default()
