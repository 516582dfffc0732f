"""Record a simulation as an animated GIF: a fixed camera, pybullet's TinyRenderer, Pillow.

The TinyRenderer is pybullet's software renderer: it works in DIRECT mode, without a display
or OpenGL, so ``--record`` works on a headless CI machine. Frames are taken every ``every``
steps; each frame's GIF duration is chosen so that the animation plays at the speed of
simulated time (GIF durations are whole centiseconds, so they are rounded cumulatively: the
error never builds up).
"""

from __future__ import annotations

import io
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError
from ar3cli.infra.atomic import atomic_write, check_writable


def check_gif_path(path: Path, follow_symlinks: bool = False) -> Path:
    """The file to write (a link's target with ``follow_symlinks``), or UserError when ``path`` is not
    a writable ``.gif`` location (a symlink without ``follow_symlinks`` included)."""
    if path.suffix.lower() != ".gif":
        raise UserError(f"--record {path}: the file name must end in .gif")
    if path.is_dir():
        raise UserError(f"--record {path}: is a directory; give a file name such as grasp.gif")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise UserError(f"--record {path}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK):
        raise UserError(f"--record {path}: folder {parent} is not writable")
    return check_writable(path, follow_symlinks)


class GifRecorder:
    """Collects frames from a fixed camera; :meth:`write` saves them as an animated GIF."""

    def __init__(self, target: Sequence[float], distance: float, yaw_deg: float, pitch_deg: float,
                 width: int = 320, height: int = 240, every: int = 16, timestep: float = 1.0 / 240.0) -> None:
        self.target = list(target)
        self.distance = distance
        self.yaw_deg = yaw_deg
        self.pitch_deg = pitch_deg
        self.width = width
        self.height = height
        self.every = every
        self.timestep = timestep
        self.frames: list[Any] = []
        self._matrices: tuple[list[float], list[float]] | None = None

    def __call__(self, scene: Any, step: int) -> None:
        """Frame hook: capture on the first step and every ``every`` steps after."""
        if step == 1 or step % self.every == 0:
            self.capture(scene.p, scene.client)

    def capture(self, p: Any, client: int) -> None:
        from PIL import Image

        if self._matrices is None:
            view = p.computeViewMatrixFromYawPitchRoll(self.target, self.distance, self.yaw_deg, self.pitch_deg,
                                                       0, 2, physicsClientId=client)
            projection = p.computeProjectionMatrixFOV(50, self.width / self.height, 0.02, 5.0,
                                                      physicsClientId=client)
            self._matrices = (view, projection)
        view, projection = self._matrices
        _, _, rgba, _, _ = p.getCameraImage(self.width, self.height, view, projection,
                                            renderer=p.ER_TINY_RENDERER, shadow=0, physicsClientId=client)
        pixels = bytes(bytearray(rgba)) if not hasattr(rgba, "tobytes") else rgba.tobytes()
        self.frames.append(Image.frombytes("RGBA", (self.width, self.height), pixels).convert("RGB"))

    def durations_ms(self) -> list[int]:
        """Per-frame durations (ms, multiples of 10) that add up to the simulated time."""
        frame_cs = self.every * self.timestep * 100
        return [10 * (round((i + 1) * frame_cs) - round(i * frame_cs)) for i in range(len(self.frames))]

    def write(self, path: Path) -> int:
        """Write the GIF (to a temp file in the same folder, then rename); returns its frame count.

        Pillow merges identical consecutive frames (adding up their durations), so the file
        may hold fewer frames than were captured; the count returned is the file's.
        """
        from PIL import Image

        if not self.frames:
            raise UserError("nothing was recorded")
        path = Path(path)
        # one palette for every frame (from the last one, when the scene has changed the
        # most), so colours do not flicker between frames
        palette = self.frames[-1].quantize(colors=128, dither=0)
        first, *rest = [frame.quantize(palette=palette, dither=0) for frame in self.frames]
        buffer = io.BytesIO()
        first.save(buffer, format="GIF", save_all=True, append_images=rest, duration=self.durations_ms(),
                   loop=0, optimize=False, disposal=1)
        with Image.open(io.BytesIO(buffer.getvalue())) as written:
            count = written.n_frames
        atomic_write(path, buffer.getvalue())
        return count
