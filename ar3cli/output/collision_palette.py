"""The colours and letters of the self-collision matrix, shared by ``sample-collisions --png``
(:mod:`ar3cli.collisions.heatmap_png`) and the report page's heat map (:mod:`ar3cli.output.html_charts`),
so a pair looks the same in both.

Each of MoveIt's categories has its colour and, but for ``never``, a letter (the terminal heat map's),
so the categories stay apart in greyscale too: adjacent grey-blue ``A``, default red ``D`` (in contact
at home), always magenta ``X``, never pale green (empty). A ``sometimes`` cell is coloured on a
logarithmic yellow-orange-brown scale by the fraction of samples in collision (0.1% and below the
palest, 100% the darkest); a pair that touched only at a joint limit (no sample) is the palest with ``L``.
"""

from __future__ import annotations

import math

Rgb = tuple[int, int, int]

CATEGORY_COLOURS: dict[str, Rgb] = {
    "adjacent": (120, 144, 180),
    "default": (214, 48, 49),
    "always": (170, 60, 170),
    "never": (214, 240, 214),
}
CATEGORY_LETTERS = {"adjacent": "A", "default": "D", "always": "X", "never": ""}
LIMIT_ONLY = "L"
"""The letter of a ``sometimes`` pair that collided only at a joint limit, in no sample."""
RAMP: tuple[Rgb, ...] = ((255, 240, 160), (245, 150, 40), (140, 45, 15))
"""The 'sometimes' scale: pale yellow at SCALE_LOW and below, orange half-way (log), brown at 100%."""
SCALE_LOW = 0.001
"""The fraction at the pale end of the scale: most 'sometimes' pairs collide in 0.1% to 10% of samples."""
SCALE_TICKS = (0.001, 0.01, 0.1, 1.0)
LEGEND = [("adjacent", "adjacent (joined by a joint)"), ("default", "default (in contact at home)"),
          ("always", "always (in contact in nearly every sample)"), ("never", "never (no contact seen)")]
SCALE_TITLE = "sometimes: fraction of samples in collision (log scale); a cell holds the count"


def scale_position(fraction: float) -> float:
    """0..1 along the colour scale: log10 from :data:`SCALE_LOW` (0) to 1.0 (1), clipped."""
    if fraction <= SCALE_LOW:
        return 0.0
    return min(1.0, math.log10(fraction / SCALE_LOW) / -math.log10(SCALE_LOW))


def ramp_colour(t: float) -> Rgb:
    """The colour at position ``t`` (0..1) of :data:`RAMP`."""
    t = min(1.0, max(0.0, t))
    segment = min(int(t * (len(RAMP) - 1)), len(RAMP) - 2)
    local = t * (len(RAMP) - 1) - segment
    low, high = RAMP[segment], RAMP[segment + 1]
    return tuple(round(a + (b - a) * local) for a, b in zip(low, high))  # type: ignore[return-value]


def pair_colour(category: str, fraction: float) -> Rgb:
    """A pair's fill: its category's colour, or the scale colour of its fraction for ``sometimes``."""
    if category in CATEGORY_COLOURS:
        return CATEGORY_COLOURS[category]
    return ramp_colour(scale_position(fraction))


def pair_letter(category: str, collisions: int) -> str:
    """What a pair's cell says: the category letter, the count of colliding samples, or L (limits only)."""
    if category in CATEGORY_LETTERS:
        return CATEGORY_LETTERS[category]
    return str(collisions) if collisions else LIMIT_ONLY


def ink(fill: Rgb) -> str:
    """Black on light fills, white on dark ones."""
    luminance = 0.299 * fill[0] + 0.587 * fill[1] + 0.114 * fill[2]
    return "black" if luminance > 140 else "white"


def hex_colour(fill: Rgb) -> str:
    """``#rrggbb`` for CSS and SVG."""
    return "#{:02x}{:02x}{:02x}".format(*fill)
