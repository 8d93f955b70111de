"""Short videos of a world: frames rendered offscreen at a sim-time rate, encoded to H.264 MP4.

Encoding uses PyAV, whose wheel carries FFmpeg's libraries (libx264 included): nothing is
downloaded or installed on the system. Frames are taken by a world observer (`World.add_observer`)
at `fps` frames per second of *simulated* time, so a video plays at real speed whatever the
real-time factor was, and the stepping has no Python per physics step.
"""

from __future__ import annotations

import os
from fractions import Fraction
from typing import TYPE_CHECKING

from twin_cli.view import offscreen

if TYPE_CHECKING:
    from twin_cli.world.engine import World

FPS = 20  # [frames per simulated second]; played at the same rate: real speed
WIDTH, HEIGHT = 320, 240  # [px]; H.264 with yuv420p needs even sizes


class WorldVideo:
    """Films one entity of a world into `path` (atomically: a temp file renamed on `close`).

    The camera is aimed at the entity once, at the start, and stays: the video shows how it
    moves (falls, slides, tips). Call `close` once the stepping is done; `frames` counts what
    was written.
    """

    def __init__(self, world: World, entity: str, path: str, *, fps: int = FPS) -> None:
        import av

        self.world, self.entity, self.path, self.fps = world, entity, path, fps
        self.frames = 0
        self._temp = f"{path}.part"
        self._container = av.open(self._temp, mode="w", format="mp4")
        self._stream = self._container.add_stream("libx264", rate=fps)
        self._stream.width, self._stream.height = WIDTH, HEIGHT
        self._stream.pix_fmt = "yuv420p"
        self._stream.time_base = Fraction(1, fps)
        self._renderer = offscreen.renderer(world.model, WIDTH, HEIGHT)
        self._model = world.model
        self._view: offscreen.CameraView | None = None
        self._frame()  # t = 0: the start pose
        self._handle = world.add_observer(self._frame, float(fps))

    def _frame(self) -> None:
        """Renders and encodes the world now (called with the world's lock held)."""
        import av

        model, data = self.world.model, self.world.data
        if model is not self._model:  # a spawn recompiled the world: a renderer for it
            self._renderer.close()
            self._renderer = offscreen.renderer(model, WIDTH, HEIGHT)
            self._model = model
        if self._view is None:
            bodies = self.world.index_of(self.entity).bodies
            self._view = offscreen.entity_view(model, data, bodies, WIDTH, HEIGHT)
        pixels = offscreen.render(model, data, self._view, self._renderer)
        frame = av.VideoFrame.from_ndarray(pixels, format="rgb24")
        frame.pts = self.frames
        for packet in self._stream.encode(frame):
            self._container.mux(packet)
        self.frames += 1

    def close(self) -> None:
        """Stops filming, flushes the encoder and moves the file into place."""
        self.world.remove_observer(self._handle)
        for packet in self._stream.encode():
            self._container.mux(packet)
        self._container.close()
        self._renderer.close()
        os.replace(self._temp, self.path)
