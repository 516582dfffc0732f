"""Open ``ar3cli view`` on real robots in headless Chromium: does every one draw, and does none hang?

For each robot: ``ar3cli view ROBOT --port 0`` as its own process (its own TMPDIR), then a fresh page in
one headless Chromium (tests/chromium.py), and a table of

- links: the links the viewer drew (its stderr line);
- ready s: from the process start to the URL printed (load, meshes, the first scene on the server);
- draw s: from opening the page to a finished picture: robot pixels in the middle of the canvas, the
  panel's status shown, and two screenshots in a row alike (the browser's share: the page, the
  websocket, every mesh uploaded, WebGL in software);
- contacts at home: the pairs the viewer's pybullet child reports at the home pose (sample-collisions'
  check, adjacent pairs left out);
- findings: errors / warnings / info with the simulated checks (its stderr line);
- ok: drawn, its lines printed, SIGTERM answered with exit 143 in time, no child process and no
  temporary file left.

Every step has a time limit (``--wait``): a hang is a failed row, never a stuck run. Robots: a set of
arms, a hand, humanoids, mobile bases and a quadruped from example-robot-data (installed by
benchmarks/sweep_real_robots.py into ~/.cache/ar3cli-sweep/erd; skipped when absent), pybullet_data, and
two xacro files: this repository's AR3 and the real AR3 description in ../shared (when present);
``--robot PATH`` (repeatable) chooses others. Needs Chromium and viser.

Usage::

    python benchmarks/view_real_robots.py [--shots DIR] [--robot PATH ...] [--wait SECONDS]
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.chromium import CHROMIUM, Chromium, difference, robot_pixels  # noqa: E402 - the repository's test helpers
from tests.view_process import ViewerProcess, running  # noqa: E402

ERD = Path.home() / ".cache" / "ar3cli-sweep" / "erd" / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
ERD_ROBOTS = ["ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf",
              "allegro_hand_description/urdf/allegro_right_hand.urdf", "talos_data/robots/talos_full_v2.urdf",
              "icub_description/robots/icub.urdf", "romeo_description/urdf/romeo.urdf",
              "tiago_description/robots/tiago.urdf", "pr2_description/urdf/pr2.urdf",
              "go1_description/urdf/go1.urdf"]
SHARED_XACRO = REPO.parent / "shared" / "models" / "ar3_description" / "urdf" / "ar3.urdf.xacro"
"""The real AR3 description's xacro (includes, macros), beside the repository where it is checked out."""
PYBULLET_ROBOTS = ["kuka_iiwa/model.urdf", "franka_panda/panda.urdf", "xarm/xarm6_robot.urdf", "husky/husky.urdf",
                   "r2d2.urdf"]
CANVAS = (0.05, 0.1, 0.64, 0.95)
"""Where a robot may be drawn (fractions of the page), clear of viser's panel."""
DRAWN = 0.01
STILL = 0.05
"""Mean per-channel difference (0..255) under which two screenshots in a row are the same picture."""


def default_robots() -> list[tuple[str, Path]]:
    import pybullet_data

    robots = [(f"erd:{name.split('/')[-1]}", ERD / name) for name in ERD_ROBOTS if (ERD / name).is_file()]
    data = Path(pybullet_data.getDataPath())
    robots += [(f"pybullet_data:{name}", data / name) for name in PYBULLET_ROBOTS]
    robots.append(("ar3cli:assets/ar3/ar3.urdf.xacro", REPO / "assets" / "ar3" / "ar3.urdf.xacro"))
    if SHARED_XACRO.is_file():
        robots.append(("shared:ar3_description/ar3.urdf.xacro", SHARED_XACRO))
    return robots


def view_one(browser: Chromium, name: str, path: Path, wait: float, shots: Path | None) -> dict:
    """One robot, start to finish; the row of the table."""
    row: dict = {"robot": name, "links": "-", "ready": "-", "draw": "-", "contacts": "-", "findings": "-",
                 "ok": False, "why": ""}
    with tempfile.TemporaryDirectory(prefix="ar3cli-view-bench-") as folder:
        temporary = Path(folder)
        try:
            viewer = ViewerProcess(path, temporary, wait=wait)
        except AssertionError as exc:
            row["why"] = f"no URL: {str(exc)[-200:]}"
            return row
        try:
            row["ready"] = f"{viewer.ready_s:.1f}"
            drew = viewer.wait_for(" links in ")
            row["links"] = re.search(r"drew (\d+) links", drew).group(1)
            browser.new_page()
            start = time.perf_counter()
            browser.open(viewer.url, timeout=wait)
            image = previous = None
            while time.perf_counter() - start < wait:
                image = browser.image()
                if (robot_pixels(image, CANVAS) > DRAWN and previous is not None and difference(image, previous) < STILL
                        and " links, " in (browser.evaluate("document.body.innerText") or "")):
                    row["draw"] = f"{time.perf_counter() - start:.1f}"
                    break
                previous = image
                time.sleep(0.3)
            if shots is not None and image is not None:
                browser.evaluate("document.querySelectorAll('.mantine-Notification-closeButton').forEach(b => b.click())")
                time.sleep(0.5)  # the notification slides out
                browser.image().save(shots / f"{re.sub(r'[^A-Za-z0-9_.-]+', '_', name)}.png", optimize=True)
            contacts = viewer.wait_for("contacts")
            found = re.search(r"contacts at home: (\d+) pair", contacts)
            row["contacts"] = found.group(1) if found else contacts.partition("contacts ")[2][:60]
            lint = viewer.wait_for("simulated checks")
            counts = re.search(r"(\d+) errors?, (\d+) warnings?, (\d+) info", lint)
            row["findings"] = "/".join(counts.groups()) if counts else "?"
            if "did not run" in lint:
                row["findings"] += " (static only: " + lint.partition("did not run: ")[2][:80] + ")"
            children = viewer.children()
            code = viewer.terminate()
            left = [pid for pid in children if running(pid)]
            leftovers = list(temporary.iterdir())
            problems = [why for why, bad in (("not drawn", row["draw"] == "-"), (f"exit {code}", code != 143),
                                             (f"children left: {left}", bool(left)),
                                             (f"temporary files left: {leftovers}", bool(leftovers))) if bad]
            row["ok"], row["why"] = not problems, "; ".join(problems)
        except AssertionError as exc:
            row["why"] = str(exc)[-200:]
        finally:
            viewer.stop()
    return row


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", action="append", type=Path, help="a robot file (repeatable; default: the set above)")
    parser.add_argument("--shots", type=Path, help="save each robot's screenshot in this folder")
    parser.add_argument("--wait", type=float, default=120.0, help="the longest one step may take (seconds)")
    args = parser.parse_args()
    if CHROMIUM is None:
        print("view_real_robots: Chromium is not installed (apt-get install chromium)", file=sys.stderr)
        return 2
    robots = [(path.name, path) for path in args.robot] if args.robot else default_robots()
    if args.shots is not None:
        args.shots.mkdir(parents=True, exist_ok=True)
    rows = []
    with Chromium(1200, 800) as browser:
        for name, path in robots:
            row = view_one(browser, name, path, args.wait, args.shots)
            rows.append(row)
            print(f"{name}: {'ok' if row['ok'] else 'FAILED ' + row['why']}", file=sys.stderr, flush=True)
    print("| robot | links | ready s | draw s | contacts at home | findings (E/W/I) | ok |")
    print("| --- | ---: | ---: | ---: | ---: | --- | --- |")
    for row in rows:
        ok = "yes" if row["ok"] else f"NO: {row['why']}"
        print(f"| {row['robot']} | {row['links']} | {row['ready']} | {row['draw']} | {row['contacts']} | "
              f"{row['findings']} | {ok} |")
    failed = sum(not row["ok"] for row in rows)
    print(f"\n{len(rows) - failed} of {len(rows)} robots drawn and stopped clean")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
