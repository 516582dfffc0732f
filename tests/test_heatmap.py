"""The collision heat map picture (``sample-collisions --png``): cells, labels on both axes, legend
and colour scale, built from a hand-made matrix (no sampling)."""

from __future__ import annotations

import io

import pytest

from ar3cli.collisions.heatmap_png import (
    CATEGORY_COLOURS,
    RAMP,
    cell_colour,
    cell_text,
    heat_map_image,
    heat_map_png,
    ramp_colour,
    scale_position,
)
from ar3cli.collisions.matrix import PairResult

LINKS = ["base", "upper_arm", "forearm", "wrist", "gripper"]


def matrix():
    """Every category once, a 'sometimes' pair at 2%, one at 60%, one that touched only at a limit."""
    pairs = [(a, b) for b in range(len(LINKS)) for a in range(b)]
    kinds = {(0, 1): ("adjacent", 1000), (1, 2): ("adjacent", 1000), (2, 3): ("adjacent", 1000),
             (3, 4): ("adjacent", 1000), (0, 2): ("never", 0), (1, 3): ("default", 1000),
             (0, 3): ("sometimes", 20), (1, 4): ("sometimes", 600), (0, 4): ("always", 990),
             (2, 4): ("sometimes", 0)}
    results = []
    for a, b in pairs:
        category, collisions = kinds.get((a, b), ("never", 0))
        results.append(PairResult(LINKS[a], LINKS[b], category, collisions, 1000, category == "default",
                                  ["all at upper"] if (a, b) == (2, 4) else []))
    return pairs, results


def ink(image, box) -> int:
    """Non-white pixels in ``box``."""
    region = image.convert("L").crop(box)
    return sum(count for count, value in region.getcolors(1 << 16) if value < 250)


def test_png_builds_with_a_legend():
    from PIL import Image

    pairs, results = matrix()
    data = heat_map_png(LINKS, pairs, results, title="test: 1000 samples, seed 0")
    image = Image.open(io.BytesIO(data))
    assert image.format == "PNG"
    same, boxes = heat_map_image(LINKS, pairs, results, title="test: 1000 samples, seed 0")
    assert same.size == image.size
    grid, legend, scale = boxes["grid"], boxes["legend"], boxes["scale"]
    assert legend[1] > grid[3]  # the legend is under the matrix
    assert ink(image, legend) > 1000  # swatches, words and the scale are drawn there
    colours = {colour for _, colour in image.convert("RGB").getcolors(1 << 16)}
    for colour in CATEGORY_COLOURS.values():
        assert colour in colours  # every category, in the cells and the legend
    # the colour scale runs from the palest to the darkest colour of the ramp, left to right
    rgb = image.convert("RGB")
    middle = (scale[1] + scale[3]) // 2
    assert rgb.getpixel((scale[0] + 2, middle)) == pytest.approx(RAMP[0], abs=3)
    assert rgb.getpixel((scale[2] - 2, middle)) == pytest.approx(RAMP[-1], abs=3)
    # its numbers: there is text under the bar
    assert ink(image, (scale[0], scale[3] + 3, scale[2], scale[3] + 16)) > 50


def test_link_labels_on_both_axes():
    """Row labels left of the grid, column labels under it: both strips carry text."""
    from PIL import Image

    pairs, results = matrix()
    image = Image.open(io.BytesIO(heat_map_png(LINKS, pairs, results)))
    _, boxes = heat_map_image(LINKS, pairs, results)
    left, top, right, bottom = boxes["grid"]
    assert ink(image, (0, top, left - 2, bottom)) > 200
    assert ink(image, (left, bottom + 4, right, boxes["legend"][1] - 4)) > 200


def test_cells_say_their_category_and_count():
    _, results = matrix()
    texts = {(r.link_a, r.link_b): cell_text(r) for r in results}
    assert texts[("base", "upper_arm")] == "A" and texts[("upper_arm", "wrist")] == "D"
    assert texts[("base", "gripper")] == "X" and texts[("base", "forearm")] == ""
    assert texts[("base", "wrist")] == "20" and texts[("upper_arm", "gripper")] == "600"
    assert texts[("forearm", "gripper")] == "L"
    rare, often = (next(r for r in results if r.collisions == n and r.category == "sometimes") for n in (20, 600))
    assert cell_colour(rare) != cell_colour(often)


def test_scale():
    assert scale_position(0) == 0 and scale_position(0.001) == 0 and scale_position(1) == 1
    assert scale_position(0.01) == pytest.approx(1 / 3) and scale_position(0.1) == pytest.approx(2 / 3)
    assert ramp_colour(0) == RAMP[0] and ramp_colour(0.5) == RAMP[1] and ramp_colour(1) == RAMP[-1]


def test_single_pair_and_long_names():
    pairs = [(0, 1)]
    results = [PairResult("a" * 60, "b", "sometimes", 12345, 20000, False)]
    data = heat_map_png(["a" * 60, "b"], pairs, results)
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
