"""``ar3cli view`` end to end, in a real headless Chromium: the real command as its own process on a real
robot (pybullet_data's KUKA iiwa, copied so the test can edit it), the real page drawn with WebGL on
SwiftShader, driven through the Chrome DevTools Protocol (tests/chromium.py).

One viewer and one browser for the whole story, in order: the robot is drawn (robot-coloured pixels
in the middle, not a blank canvas); a joint moved with its slider in the page moves the robot; a check
box shows the inertia boxes; an edit of the file (a joint origin moved) redraws it without a restart,
the slider where it was; a file that no longer parses leaves the robot on screen with the error in the
status; SIGTERM ends it with exit code 143, no child process and no temporary file left.

Skipped without Chromium (``apt-get install chromium``; .ci/run installs it) or without viser (the
``view`` extra; the ``test`` extra has it). Set ``AR3CLI_VIEW_SCREENSHOT=docs/images/view.png`` to save
the picture of the docs, ``AR3CLI_VIEW_SHOTS=FOLDER`` to keep every step's screenshot (to look at them).
"""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import time
from pathlib import Path

import pytest

from tests.chromium import CHROMIUM, Chromium, difference, robot_pixels
from tests.conftest import REPO
from tests.view_process import WAIT_SECONDS, ViewerProcess, running

pytestmark = [
    pytest.mark.skipif(CHROMIUM is None, reason="headless Chromium is not installed (apt-get install chromium; "
                                                "the CI script does)"),
    pytest.mark.skipif(importlib.util.find_spec("viser") is None,
                       reason="viser is not installed (pip install 'ar3cli[view]')"),
]

DRAWN = 0.02
"""Share of the middle of the canvas that must differ from the background: the robot is drawn."""
MOVED = 1.0
"""Mean per-channel difference (0..255) of two screenshots that shows the picture changed."""
CANVAS = (0.3, 0.2, 0.64, 0.92)
"""Where the robot is (fractions of the page: left, top, right, bottom): the canvas's middle, clear of
viser's panel on the right and of its notifications on the top left."""


def _kept(name: str, image):
    """``image``, saved as FOLDER/NAME.png when ``AR3CLI_VIEW_SHOTS`` names a folder."""
    folder = os.environ.get("AR3CLI_VIEW_SHOTS")
    if folder:
        image.save(Path(folder) / f"{name}.png")
    return image


def _robot_points(image, count: int = 4) -> list[tuple[float, float]]:
    """``count`` pixels well inside the robot (their 7x7 neighbourhood drawn too), spread from the middle
    of what is drawn outwards: where a click lands on a link, not on its edge."""
    import numpy as np

    pixels = np.asarray(image, dtype=int)
    height, width = pixels.shape[:2]
    left, top, right, bottom = (int(f * size) for f, size in zip(CANVAS, (width, height, width, height)))
    region = pixels[top:bottom, left:right]
    mask = (region.min(axis=2) < 200) & (np.ptp(region, axis=2) < 200)
    inside = mask.copy()
    for dy in range(-3, 4):
        for dx in range(-3, 4):
            inside &= np.roll(np.roll(mask, dy, axis=0), dx, axis=1)
    found = np.argwhere(inside)
    centre = np.median(found, axis=0)
    ordered = found[np.argsort(((found - centre) ** 2).sum(axis=1))]
    picked = ordered[np.linspace(0, len(ordered) - 1, count).astype(int) // 3]  # from the middle, not the rim
    return [(float(left + column), float(top + row)) for row, column in picked]


def _settled(browser: Chromium):
    """A screenshot once two in a row are alike (every update the page got is drawn)."""
    previous = browser.image()
    deadline = time.monotonic() + WAIT_SECONDS
    while time.monotonic() < deadline:
        time.sleep(0.3)
        image = browser.image()
        if difference(image, previous) < 0.05:
            return image
        previous = image
    return previous


def _until(condition, what: str, seconds: float = WAIT_SECONDS, fail: bool = True):
    """Call ``condition()`` until it returns something true (then return it), at most ``seconds``; then
    an AssertionError naming ``what`` (None when not ``fail``)."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.2)
    if fail:
        raise AssertionError(f"timed out waiting for {what}")
    return None


FIND = """const label = [...document.querySelectorAll('label')].find(e => e.textContent.trim() === {name!r});
  const target = document.getElementById(label.htmlFor);
  target.scrollIntoView({{block: 'center'}});
  const box = target.getBoundingClientRect();"""
SLIDER = """(() => {{ """ + FIND + """
  return {{x: box.left, y: box.top, width: box.width, height: box.height,
           value: target.parentElement.querySelector('input').value}}; }})()"""
"""The slider labelled ``name``: its track's box and the value in the number field beside it."""
CHECKBOX = """(() => {{ """ + FIND + """
  return {{x: box.left + box.width / 2, y: box.top + box.height / 2, checked: target.checked}}; }})()"""
"""The check box labelled ``name``: its centre and whether it is checked."""


@pytest.fixture(scope="module")
def browser():
    with Chromium(1200, 800) as opened:
        yield opened


@pytest.fixture
def robot(tmp_path, pybullet_data_dir) -> Path:
    folder = tmp_path / "kuka"
    shutil.copytree(pybullet_data_dir / "kuka_iiwa" / "meshes", folder / "meshes")
    shutil.copy(pybullet_data_dir / "kuka_iiwa" / "model.urdf", folder / "model.urdf")
    return folder / "model.urdf"


def test_the_viewer_draws_moves_reloads_and_stops_clean(robot, tmp_path, browser):
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    viewer = ViewerProcess(robot, temporary)
    try:
        viewer.wait_for("contacts at home: 0 pair(s)")
        browser.new_page()
        browser.open(viewer.url)
        _until(lambda: robot_pixels(browser.image(), CANVAS) > DRAWN, "the robot to be drawn")
        first = _settled(browser)  # every mesh drawn: a later difference is the joint's (a loaded machine lags)
        _kept("1-drawn", first)

        slider = browser.evaluate(SLIDER.format(name="lbr_iiwa_joint_2"))
        assert slider["value"] == "0"
        browser.click(slider["x"] + 0.9 * slider["width"], slider["y"] + slider["height"] / 2)
        value = _until(lambda: float(browser.evaluate(SLIDER.format(name="lbr_iiwa_joint_2"))["value"]),
                       "the slider to take the click")
        assert 1.0 < value <= 2.1, value
        moved = _until(lambda: (lambda image: image if difference(image, first) > MOVED else None)(browser.image()),
                       "the joint to move the robot")
        _kept("2-moved", moved)

        assert "Click a link to see its facts" in browser.evaluate("document.body.innerText")
        def clicked() -> str | None:
            text = browser.evaluate("document.body.innerText")
            return text if "lbr_iiwa_link_" in text.partition("Selected link")[2] else None

        for x, y in _robot_points(_settled(browser)):  # a click between two links selects nothing: try again
            browser.click(x, y)
            card = _until(clicked, "the clicked link's facts", seconds=10.0, fail=False)
            if card:
                break
        assert card, "no click on the robot selected a link"
        assert re.search(r"Selected link\s+lbr_iiwa_link_\d\s+(parent: |root link)", card), card
        if os.environ.get("AR3CLI_VIEW_SHOTS"):
            browser.evaluate("[...document.querySelectorAll('*')].filter(e => e.textContent.trim() === "
                             "'Selected link').pop().scrollIntoView()")
            _kept("2b-clicked", browser.image())

        box = browser.evaluate(CHECKBOX.format(name="inertia boxes"))
        assert box["checked"] is False
        browser.click(box["x"], box["y"])
        boxes = _until(lambda: (lambda image: image if difference(image, moved) > MOVED / 4 else None)(browser.image()),
                       "the inertia boxes to appear")
        _kept("3-inertia-boxes", boxes)

        seen = len(viewer.lines)
        text = robot.read_text(encoding="utf-8")
        edited = text.replace('<origin rpy="1.57079632679 0 0" xyz="0 0 0.2155"/>',
                              '<origin rpy="1.57079632679 0 0" xyz="0 0.25 0.2155"/>', 1)
        assert edited != text
        robot.write_text(edited, encoding="utf-8")
        assert "model.urdf changed" in viewer.wait_for("reloaded 8 links", seen)
        reloaded = _until(lambda: (lambda image: image if difference(image, boxes) > MOVED else None)(browser.image()),
                          "the edit to be drawn")
        _kept("4-reloaded", reloaded)
        assert robot_pixels(reloaded, CANVAS) > DRAWN
        assert float(browser.evaluate(SLIDER.format(name="lbr_iiwa_joint_2"))["value"]) == value
        if os.environ.get("AR3CLI_VIEW_SCREENSHOT"):
            browser.evaluate("document.querySelectorAll('.mantine-Notification-closeButton').forEach(b => b.click())")
            time.sleep(0.5)
            browser.image().save(REPO / os.environ["AR3CLI_VIEW_SCREENSHOT"], optimize=True)

        seen = len(viewer.lines)
        robot.write_text(edited.replace("</robot>", ""), encoding="utf-8")
        viewer.wait_for("does not load", seen)
        status = _until(lambda: (lambda found: found if "Does not load" in found else None)(
            browser.evaluate("document.body.innerText")), "the error in the status")
        assert "the last good load is shown" in status  # the status at the top of the panel
        assert "model.urdf does not load (the last good robot stays on screen)" in status  # the banner
        assert robot_pixels(_kept("5-does-not-load", browser.image()), CANVAS) > DRAWN

        children = viewer.children()
        assert children, "the contact checker's pybullet child should be running"
        assert viewer.terminate() == 143
        viewer.wait_for("ar3cli: terminated")
        assert [pid for pid in children if running(pid)] == []
        assert list(temporary.iterdir()) == []
    finally:
        viewer.stop()
