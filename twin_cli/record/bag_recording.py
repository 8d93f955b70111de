"""A rosbag2 MCAP recording whose encoding runs in another process (see `ring`, `encoder`).

The stepping thread's share per sample is MuJoCo's state and qfrc_actuator, copied into shared
memory by two C calls (a few µs); the encoder process builds and writes the messages. Sensor
readings are copied at the sensors' rates and built by a `SensorPump` thread of this process (ray
casting, rendering), which sends them to the encoder; the loop's waits for a full ring or a
backlogged pump are `blocked_s`. The interface is `Recording`'s: `start`, `stop`, `wait`,
`status`, `capture_now`.
"""

from __future__ import annotations

import math
import os
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from twin_cli.errors import InvalidRequestError
from twin_cli.record import ring
from twin_cli.record.follow import Follows
from twin_cli.record.mcap_writer import open_output
from twin_cli.record.recorder import RecordingStatus, check_rate
from twin_cli.record.sampler import Sampler
from twin_cli.record.sensor_feed import KEPT, SensorFeed
from twin_cli.record.sensor_pump import SensorPump
from twin_cli.world.observers import world_view

if TYPE_CHECKING:
    import mujoco

    from twin_cli.world.engine import World

RING_BYTES = 32 << 20  # [B] ~40 s of a humanoid at 1,000 samples per wall second
START_TIMEOUT_S = 60.0  # [s] for the encoder's answer when stopping (imports on a loaded host)


class BagRecording(Follows):
    """Samples `world` at `rate` [Hz] of sim time into the MCAP file `path` until stopped."""

    def __init__(
        self,
        world: World,
        path: str | Path | None,
        *,
        rate: float = 100.0,
        entities: Sequence[str] = (),
        descriptions: dict[str, str] | None = None,
        duration: float | None = None,
        overwrite: bool = False,
        ring_bytes: int = RING_BYTES,
        frame_prefix: str | None = None,
    ) -> None:
        """Args: as `Recording`, with the output file instead of sinks; `ring_bytes` [B] is the
        shared buffer between the loop and the encoder (when full, the loop waits for it).
        `path` None: a subclass whose `_encoder_command` runs an encoder of its own.

        Raises:
            RequestError: the file exists or cannot be written.
            EntityNotFoundError, InvalidRequestError: unknown entity, bad rate or duration.
        """
        self.rate = check_rate(rate)
        if duration is not None and not (math.isfinite(duration) and duration > 0):
            raise InvalidRequestError("duration", f"{duration} s", "give a positive duration")
        self._sampler = Sampler(world, entities, descriptions, frame_prefix)  # checks the names
        self._entities, self._descriptions = tuple(entities), descriptions
        self._frame_prefix = self._sampler.frame_prefix
        if path is not None:
            open_output(path, overwrite=overwrite).close()  # the errors, here and now
        self.path = None if path is None else Path(path).expanduser()
        self._world, self._duration = world, duration
        fd, self._memory = ring.allocate(ring_bytes // 8)
        data, self._header, self._span = ring.views(self._memory)
        self._conn, self._child = _pipe()
        self._ring_fd = fd
        self._process: subprocess.Popen | None = None
        self._writer = ring.RingWriter(data, self._header, self._alive)
        self._model: mujoco.MjModel | None = None
        self._feed = SensorFeed(world, entities, self._frame_prefix, descriptions)
        self._pump = SensorPump(self._send_readings, "record-sensors")
        self._send_lock = threading.Lock()  # the stepping and sensor threads share the pipe
        self._epoch = -1
        self._until: float | None = None
        self._handle: int | None = None
        self._done = threading.Event()
        self._error: str | None = None
        self._closed = False
        self._started = False

    # ------------------------------------------------------------ control (any thread)
    def start(self) -> BagRecording:
        """Starts the encoder, takes the first sample now and follows the world's stepping."""
        fds = (self._ring_fd, self._child.fileno())
        command = self._encoder_command(fds)
        # A session of its own: a Ctrl-C to the terminal's group could reach the encoder before
        # its first line ignores it (its start-up takes seconds on a busy host), and end it with
        # the file the server opened still empty. The server tells it when to stop.
        self._process = subprocess.Popen(
            command, pass_fds=fds, stdin=subprocess.DEVNULL, start_new_session=True
        )
        os.close(self._ring_fd)
        self._child.close()
        self._pump.start()
        with self._world.lock:
            now = float(self._world.data.time)
            self._until = None if self._duration is None else now + self._duration
            self._capture()
            if not self._done.is_set():
                self._handle = self._world.add_observer(
                    self._capture, self._observer_rate(self.rate)
                )
        self._follow_sensors(self._world)
        return self

    def _encoder_command(self, fds: tuple[int, int]) -> list[str]:
        """The encoder process's command line, given the ring's and the pipe's descriptors."""
        return [sys.executable, "-m", "twin_cli.record.encoder", *map(str, fds), str(self.path)]

    def capture_now(self) -> None:
        """Takes one sample now (for callers that step the world themselves)."""
        with self._world.lock:
            self._capture()

    def set_sampling(self, on: bool) -> None:
        """Suspends or resumes sampling, keeping the encoder and the file open.

        For benchmarks that alternate the loop with and without sampling on one recording, so
        slow drifts in the machine's speed cancel; a suspended stretch is a gap in the bag.
        """
        with self._world.lock:
            if self._done.is_set() or (self._handle is not None) == on:
                return
            if on:
                self._handle = self._world.add_observer(
                    self._capture, self._observer_rate(self.rate)
                )
            else:
                self._world.remove_observer(self._handle)
                self._handle = None

    def stop(self, patience: float | None = None) -> RecordingStatus:
        """Stops sampling, lets the encoder write what is queued and close the file.

        Args:
            patience: at most this long [s] to wait for the encoder (None: as long as its
                backlog takes). Past it the encoder is let go, not killed: it has "stop", so it
                drains the ring, closes the file with its summary and exits on its own (a
                server shutting down must end before `twin stop` loses patience).
        """
        self._finish_sampling()
        if not self._closed:
            self._closed = True
            self._pump.close()
            self._error = self._error or self._pump.error
            figures = {"blocked_s": round(self._writer.blocked_s, 6), "waits": self._writer.waits}
            try:
                self._send(("stop", figures))
            except OSError:
                pass  # the encoder has ended (a full disk): its "done" may wait in the pipe
            wait = START_TIMEOUT_S + self._backlog_s() if patience is None else patience
            if self._await_done(wait):
                self._end_process()
            else:
                self._conn.close()
                self._error = self._error or "the encoder finishes the file in the background"
        return self.status()

    def _await_done(self, timeout: float) -> bool:
        """Waits up to `timeout` [s] for the encoder's "done" (or its end); False: still busy."""
        deadline = time.monotonic() + timeout
        try:
            while self._conn.poll(max(0.0, deadline - time.monotonic())):
                kind, error = self._conn.recv()
                self._error = error or self._error  # the encoder's cause comes first
                if kind == "done":
                    return True
        except (EOFError, OSError):
            self._error = self._error or "the encoder process ended unexpectedly"
            return True
        return False

    def wait(self, timeout: float | None = None) -> bool:
        """Waits until the duration is over (or `stop`); True when sampling has ended."""
        return self._done.wait(timeout)

    def status(self) -> RecordingStatus:
        samples = int(self._header[ring.SAMPLES])
        start, end = (float(self._span[0]), float(self._span[1])) if samples else (None, None)
        return RecordingStatus(
            not self._done.is_set(),
            samples,
            start,
            end,
            self._error,
            self._writer.blocked_s + self._pump.blocked_s,
            self._writer.waits,
        )

    # ------------------------------------------------------------ stepping thread (lock held)
    def _capture(self) -> None:
        if self._done.is_set():
            return
        world = self._world
        if world.model is not self._model:  # a spawn or delete: new layout, maybe new sensors
            self._watch_sensors()
            self._send_layout()
        # The ring notices a dead encoder only once it is full, minutes later for a small
        # robot; its exit (a full disk) is noticed at the next sample instead.
        if not self._alive() or not self._writer.put(world.data):
            self._error = "the encoder process ended; the recording stopped"
            self._finish_sampling()
            return
        if self._until is not None and float(world.data.time) >= self._until - 1e-9:
            self._finish_sampling()

    def _capture_sensors(self, rate: float | None = None) -> None:
        if self._done.is_set():
            return
        self._pump.capture(self._feed, rate)  # copies; the pump's thread builds the readings

    def _send_layout(self) -> None:
        view = world_view(self._world)
        index, sources = self._sampler.selection(view)
        self._epoch += 1
        start = self._writer.start_layout(view.model)  # sent before the layout's first record
        self._send(("layout", self._epoch, view.model, index, sources, start))
        self._model = view.model

    def _finish_sampling(self) -> None:
        if self._done.is_set():
            return
        if self._sensor_handles:  # the samples MuJoCo kept since the last look
            with self._world.lock:
                self._pump.capture(self._feed, KEPT)
        self._done.set()
        if self._handle is not None:
            self._world.remove_observer(self._handle)
        self._stop_sensors()

    # ------------------------------------------------------------ sensor pump thread
    def _send_readings(self, readings: list) -> None:
        try:
            self._send(("readings", readings))
        except (EOFError, OSError):
            self._error = self._error or "the encoder process ended; the recording stopped"

    def _send(self, message: tuple) -> None:
        with self._send_lock:
            self._conn.send(message)

    def ready(self, timeout: float = START_TIMEOUT_S) -> bool:
        """Waits until the encoder has started (its imports take about a second; samples wait
        in the ring meanwhile). For benchmarks, which time the steady state."""
        if self._started:
            return True
        if not self._conn.poll(timeout):
            return False
        kind, error = self._conn.recv()
        self._started = kind == "ready"
        self._error = self._error or error
        return self._started

    @property
    def encoder_pid(self) -> int | None:
        """The encoder process's id once started (benchmarks read its CPU time)."""
        return None if self._process is None else self._process.pid

    def _alive(self) -> bool:
        return self._process is not None and self._process.poll() is None

    def _end_process(self) -> None:
        self._conn.close()
        if self._process is None:
            return
        try:
            self._process.wait(timeout=10.0)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()
            self._error = self._error or "the encoder process did not finish"

    def _backlog_s(self) -> float:
        """A generous bound [s] on the time to encode what is still in the ring."""
        backlog = int(self._header[ring.WRITE] - self._header[ring.READ])
        return backlog / 100.0 * 1e-3 * 10  # ~100 doubles a sample, ≥ 100 samples/s


def _pipe() -> tuple[Any, Any]:
    """Both ends of a duplex message pipe (the child's end is inherited by descriptor)."""
    from multiprocessing.connection import Connection

    ours, theirs = socket.socketpair()
    return Connection(ours.detach()), Connection(theirs.detach())
