"""Headless Chromium driven over the Chrome DevTools Protocol: what the viewer's browser test and
benchmarks/view_real_robots.py need, and nothing more (no playwright, nothing downloaded).

One browser per session (:class:`Chromium`, a context manager): launched with a fresh profile in a
temporary folder, WebGL on SwiftShader (no GPU), no background networking, the DevTools port chosen
by Chromium (read back from ``DevToolsActivePort``). One page target is attached; :meth:`Chromium.call`
sends a command to it and waits for its answer over the browser's websocket (``websockets``' sync
client, which viser already depends on). Closing ends the browser and removes the profile.
"""

from __future__ import annotations

import base64
import contextlib
import io
import itertools
import json
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
"""Debian's package (``apt-get install chromium``; .ci/run installs it), None when absent."""
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run", "--use-angle=swiftshader",
         "--enable-unsafe-swiftshader", "--disable-default-apps", "--mute-audio", "--hide-scrollbars")
START_SECONDS = 30.0


class Chromium:
    """A headless Chromium with one page, ``width`` x ``height`` CSS pixels."""

    def __init__(self, width: int = 1200, height: int = 800, executable: str | None = None) -> None:
        from websockets.sync.client import connect

        self.profile = tempfile.mkdtemp(prefix="ar3cli-chromium-")
        self.process = subprocess.Popen([executable or CHROMIUM or "chromium", *FLAGS,
                                         f"--user-data-dir={self.profile}", "--remote-debugging-port=0",
                                         f"--window-size={width},{height}", "about:blank"],
                                        stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            port_file = Path(self.profile) / "DevToolsActivePort"
            deadline = time.monotonic() + START_SECONDS
            while not (port_file.is_file() and len(port_file.read_text().split()) >= 2):
                if time.monotonic() > deadline or self.process.poll() is not None:
                    raise RuntimeError("Chromium did not open its DevTools port")
                time.sleep(0.05)
            port, path = port_file.read_text().split()[:2]
            self.socket = connect(f"ws://127.0.0.1:{port}{path}", max_size=None, open_timeout=START_SECONDS)
            self._ids = itertools.count(1)
            self.size = (width, height)
            self.session: str | None = None
            self.target: str | None = None
            self.new_page()
        except BaseException:
            self.close()
            raise

    def new_page(self) -> None:
        """Open a fresh page (tab) and close the previous one: each robot gets a page of its own."""
        previous = self.target
        self.target = self.call("Target.createTarget", url="about:blank", browser=True)["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=self.target, flatten=True, browser=True)["sessionId"]
        if previous is not None:
            self.call("Target.closeTarget", targetId=previous, browser=True)
        self.call("Page.enable")
        self.call("Runtime.enable")
        self.call("Emulation.setDeviceMetricsOverride", width=self.size[0], height=self.size[1], deviceScaleFactor=1,
                  mobile=False)

    def call(self, method: str, browser: bool = False, timeout: float = 60.0, **params: Any) -> dict:
        """Send ``method`` to the page (``browser``: to the browser itself) and return its result."""
        number = next(self._ids)
        message: dict[str, Any] = {"id": number, "method": method, "params": params}
        if self.session is not None and not browser:
            message["sessionId"] = self.session
        self.socket.send(json.dumps(message))
        deadline = time.monotonic() + timeout
        while True:
            reply = json.loads(self.socket.recv(timeout=max(0.1, deadline - time.monotonic())))
            if reply.get("id") == number:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})

    def open(self, url: str, timeout: float = 60.0) -> None:
        """Navigate to ``url`` and wait until its document has loaded."""
        self.call("Page.navigate", url=url)
        deadline = time.monotonic() + timeout
        while True:
            try:
                if self.evaluate("document.readyState") == "complete" and self.evaluate("location.href") != "about:blank":
                    return
            except RuntimeError:  # the page is being swapped for the new one
                pass
            if time.monotonic() > deadline:
                raise RuntimeError(f"{url} did not load in {timeout:g} s")
            time.sleep(0.1)

    def evaluate(self, expression: str) -> Any:
        """The value of a JavaScript expression in the page (JSON-able)."""
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression[:60]}: {result['exceptionDetails'].get('text')}")
        return result["result"].get("value")

    def screenshot(self) -> bytes:
        """The page as PNG bytes."""
        return base64.b64decode(self.call("Page.captureScreenshot", format="png", timeout=120.0)["data"])

    def image(self):
        """The page as a PIL RGB image."""
        from PIL import Image

        return Image.open(io.BytesIO(self.screenshot())).convert("RGB")

    def click(self, x: float, y: float) -> None:
        """A left click at (``x``, ``y``) CSS pixels (the pointer moved there first, as a hand would)."""
        self.call("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y)
        for kind in ("mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)

    def close(self) -> None:
        """End the browser and remove its profile."""
        socket = getattr(self, "socket", None)
        if socket is not None:
            with contextlib.suppress(Exception):  # already gone
                self.call("Browser.close", browser=True, timeout=5.0)
            socket.close()
        try:
            self.process.wait(10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        shutil.rmtree(self.profile, ignore_errors=True)

    def __enter__(self) -> Chromium:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def robot_pixels(image, box: tuple[float, float, float, float] = (0.1, 0.15, 0.6, 0.85),
                 background_tolerance: int = 24) -> float:
    """The share of pixels in ``box`` (fractions of the width and height: left, top, right, bottom;
    by default the middle of the canvas left of viser's panel) that differ from the page's light
    background and grid: where something is drawn."""
    import numpy as np

    width, height = image.size
    region = np.asarray(image.crop((int(box[0] * width), int(box[1] * height), int(box[2] * width),
                                    int(box[3] * height))), dtype=int).reshape(-1, 3)
    drawn = (region.min(axis=1) < 255 - background_tolerance) | (np.ptp(region, axis=1) > 40)
    return float(drawn.mean()) if len(region) else 0.0


def difference(first, second) -> float:
    """The mean absolute difference of two images of the same size, per channel (0..255)."""
    from PIL import ImageChops, ImageStat

    return sum(ImageStat.Stat(ImageChops.difference(first, second)).mean) / 3.0


def env_without_display() -> dict[str, str]:
    """The environment for Chromium and the viewer: no DISPLAY (headless means headless)."""
    return {key: value for key, value in os.environ.items() if key not in ("DISPLAY", "WAYLAND_DISPLAY")}
