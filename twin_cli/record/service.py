"""The recording and the live stream a world server runs (at most one of each at a time).

Used by the server's `/record` and `/foxglove` routes and by `twin serve --record/--foxglove`;
kept here so that the server holds no recording logic.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import asdict
from typing import TYPE_CHECKING

from twin_cli.errors import InvalidRequestError, TwinError
from twin_cli.record.bag_recording import BagRecording
from twin_cli.record.foxglove import LiveStream
from twin_cli.record.recorder import Recording

if TYPE_CHECKING:
    from twin_cli.world.engine import World

SHUTDOWN_WAIT_S = 5.0  # [s] a server's shutdown waits this long at most for its encoder


class Consumers:
    """One server's recording and live stream; start/stop are thread safe."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.recording: BagRecording | None = None
        self.recording_path: str | None = None
        self.live: tuple[Recording, LiveStream] | None = None

    def record(
        self,
        world: World,
        path: str,
        *,
        rate: float = 100.0,
        entities: Sequence[str] = (),
        duration: float | None = None,
        frame_prefix: str | None = None,
    ) -> dict:
        """Starts recording `world` into `path` (`frame_prefix`: see `frames.prefix_template`).

        Raises:
            InvalidRequestError: a recording is running. RequestError: unwritable path.
            EntityNotFoundError: unknown entity.
        """
        with self._lock:
            if self.recording is not None and self.recording.status().active:
                raise InvalidRequestError(
                    "recording",
                    f"already recording into {self.recording_path}",
                    "stop it first (`twin record --stop` or Ctrl-C the recording command)",
                )
            if self.recording is not None:
                self.recording.stop()
            recording = BagRecording(
                world, path, rate=rate, entities=entities, duration=duration,
                frame_prefix=frame_prefix,
            )  # fmt: skip
            self.recording, self.recording_path = recording.start(), path
            return self.record_status()

    def record_status(self) -> dict:
        """The recording's status (`active` false once it ended); raises when none was made."""
        if self.recording is None:
            raise InvalidRequestError("recording", "none was started", "start one with twin record")
        return {"path": self.recording_path, **asdict(self.recording.status())}

    def stop_recording(self) -> dict:
        """Stops the recording and closes its file; returns its final status."""
        with self._lock:
            if self.recording is None:
                raise InvalidRequestError(
                    "recording", "none is running", "start one with twin record"
                )
            self.recording.stop()
            status = self.record_status()
            self.recording = None
            return status

    def stream(
        self,
        world: World,
        *,
        port: int,
        host: str = "127.0.0.1",
        rate: float = 30.0,
        frame_prefix: str | None = None,
    ) -> dict:
        """Starts the Foxglove server on `host:port` (latest sample only: never slows the loop;
        `frame_prefix`: see `frames.prefix_template`)."""
        with self._lock:
            if self.live is not None:
                raise InvalidRequestError(
                    "Foxglove stream",
                    f"already streaming on port {self.live[1].port}",
                    "connect Foxglove to it, or stop it first",
                )
            live = LiveStream(port, host)
            try:
                recording = Recording(
                    world, [live], rate=rate, latest_only=True, frame_prefix=frame_prefix
                )
            except BaseException:
                live.close()
                raise
            self.live = (recording.start(), live)
            return {"host": host, "port": live.port, "url": f"ws://{host}:{live.port}"}

    def stop_stream(self) -> dict:
        with self._lock:
            if self.live is None:
                raise InvalidRequestError("Foxglove stream", "none is running", "twin foxglove")
            recording, live = self.live
            recording.stop()
            self.live = None
            return {"stopped": live.port}

    def follow(self, world: World) -> dict:
        """Moves the recording and the live stream to `world` (the server loaded a new one).

        Returns what happened to each, for the `/load` reply: "moved", or "stopped: <why>"
        (a recorded entity is not in the new world; the file is closed and complete).
        """
        out = {}
        with self._lock:
            if self.recording is not None and self.recording.status().active:
                try:
                    self.recording.retarget(world)
                    out["recording"] = "moved"
                except TwinError as exc:
                    self.recording.stop()
                    out["recording"] = f"stopped: {exc}"
            if self.live is not None:
                self.live[0].retarget(world)
                out["foxglove"] = "moved"
        return out

    def close(self) -> None:
        """Stops both (server shutdown): the recording's file gets its summary, from the
        encoder, which finishes it on its own if it takes longer than `SHUTDOWN_WAIT_S`."""
        if self.recording is not None:
            self.recording.stop(patience=SHUTDOWN_WAIT_S)
            self.recording = None
        if self.live is not None:
            self.live[0].stop()
            self.live = None
