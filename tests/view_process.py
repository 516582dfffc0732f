"""``ar3cli view`` as a real process, for the browser test (tests/test_view_browser.py) and the real-robot
run (benchmarks/view_real_robots.py): started on a free port with its own TMPDIR, its URL read from
stdout, its stderr lines collected as they come, its children listed, stopped with a signal."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
WAIT_SECONDS = 90.0
"""The longest any one step may take (a loaded 2-core CI machine renders WebGL in software)."""


class ViewerProcess:
    """``ar3cli view ROBOT --port 0 [ARGS]``; raises AssertionError when it prints no URL in time."""

    def __init__(self, robot: Path, temporary: Path, *args: str, wait: float = WAIT_SECONDS) -> None:
        env = {**os.environ, "PYTHONPATH": str(REPO), "NO_COLOR": "1", "TMPDIR": str(temporary)}
        self.wait = wait
        self.started = time.perf_counter()
        self.process = subprocess.Popen([sys.executable, "-m", "ar3cli", "view", str(robot), "--port", "0", *args],
                                        cwd=robot.parent, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                        stderr=subprocess.PIPE, text=True)
        self.lines: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        found: list[str] = []
        stdout = threading.Thread(target=lambda: found.append(self.process.stdout.readline()), daemon=True)
        stdout.start()
        stdout.join(wait)
        match = re.search(r"http://\S+/", found[0] if found else "")
        if not match:
            self.stop()
            raise AssertionError(f"no URL printed; stderr: {self.lines}")
        self.url = match.group()
        self.ready_s = time.perf_counter() - self.started
        """Seconds from the start to the URL: loading, meshes and the first draw on the server's side."""

    def _read(self) -> None:
        for line in self.process.stderr:
            self.lines.append(line.rstrip("\n"))

    def wait_for(self, text: str, after: int = 0) -> str:
        """The first stderr line from number ``after`` on that holds ``text``."""
        deadline = time.monotonic() + self.wait
        while time.monotonic() < deadline:
            for line in self.lines[after:]:
                if text in line:
                    return line
            if self.process.poll() is not None and not self._reader.is_alive():
                break
            time.sleep(0.05)
        raise AssertionError(f"no stderr line with {text!r}: {self.lines}")

    def children(self) -> list[int]:
        """The process ids of its children now."""
        found: list[int] = []
        for task in Path(f"/proc/{self.process.pid}/task").glob("*"):
            try:
                found += [int(pid) for pid in (task / "children").read_text().split()]
            except OSError:
                continue
        return found

    def terminate(self) -> int | None:
        """SIGTERM, then its exit code (None: still running after the wait, then killed)."""
        self.process.send_signal(signal.SIGTERM)
        try:
            return self.process.wait(self.wait)
        except subprocess.TimeoutExpired:
            self.stop()
            return None

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


def running(pid: int) -> bool:
    """Whether process ``pid`` still runs (a zombie waiting for a reaper that never comes does not)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")
