"""A recording: samples taken in the stepping thread, messages made and written in a worker.

The stepping thread only runs `Sampler.capture` (a few copies) and queues the sample; a worker
thread computes link poses, builds the ROS messages and hands them to the sinks (an MCAP file,
a Foxglove server). Sinks see topics appear and disappear as entities are spawned and deleted.
"""

from __future__ import annotations

import logging
import math
import queue
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

from twin_cli.errors import InvalidRequestError
from twin_cli.record import messages as ros
from twin_cli.record.follow import Follows
from twin_cli.record.layout import Layout
from twin_cli.record.live_messages import LiveMessages
from twin_cli.record.sampler import Kinematics, Sample, Sampler, Samples
from twin_cli.record.sensor_feed import KEPT, SensorFeed
from twin_cli.record.sensor_messages import sensor_message
from twin_cli.record.sensor_pump import SensorPump
from twin_cli.record.topics import Message, Topic, latched_messages, topics

if TYPE_CHECKING:
    from twin_cli.world.engine import World

log = logging.getLogger("twin.record")
HEARTBEAT_S = 0.5  # [s] wall: how often a live view republishes a world that is not stepping
MAX_RATE = 1000.0  # [Hz] of sim time; above the world's step rate a sample is taken every step


class Sink(Protocol):
    """Where messages go: a bag file, a live server."""

    def set_topics(self, topics: list[Topic]) -> None: ...

    def write(self, message: Message) -> None:
        """Encodes or copies `message` now: its object is refilled for the next sample."""

    def close(self) -> None: ...


@dataclass(frozen=True)
class RecordingStatus:
    """What a recording has done so far.

    Attributes:
        active: still sampling; samples: samples written; start, end: their sim times [s].
        error: why the worker stopped early, or None.
        blocked_s: wall time [s] the stepping thread waited for the encoder (its ring was
            full); waits: how many times. No sample is ever dropped from a bag.
    """

    active: bool
    samples: int
    start: float | None
    end: float | None
    error: str | None
    blocked_s: float = 0.0
    waits: int = 0


def check_rate(rate: float) -> float:
    """The sampling rate [Hz] if it is finite and in (0, MAX_RATE].

    Raises:
        InvalidRequestError: outside that range.
    """
    if not (math.isfinite(rate) and 0.0 < rate <= MAX_RATE):
        raise InvalidRequestError(
            "recording rate", f"{rate} Hz is not in (0, {MAX_RATE:g}]", "give e.g. --rate 100"
        )
    return rate


class Recording(Follows):
    """Samples `world` at `rate` [Hz] of sim time into `sinks` until `stop` (or `duration`)."""

    def __init__(
        self,
        world: World,
        sinks: Sequence[Sink],
        *,
        rate: float = 100.0,
        entities: Sequence[str] = (),
        descriptions: dict[str, str] | None = None,
        duration: float | None = None,
        latest_only: bool = False,
        frame_prefix: str | None = None,
        max_wall_rate: float | None = None,
    ) -> None:
        """Args:
        world: a `twin_cli.world.World` (stepping or not).
        sinks: receivers of every message.
        rate: samples per second of sim time.
        entities: entities to record (empty: all, and those spawned later).
        descriptions: URDF by entity, for entities spawned from an MjSpec.
        duration: stop after this much sim time [s] (None: until `stop`).
        latest_only: while the worker is busy, keep only the newest sample (live views: never
            slows the loop, never falls behind, always ends on the latest state).
        frame_prefix: tf frame prefix template (`{entity}` is the entity's name; None:
            `TWIN_FRAME_PREFIX`, else `{entity}/`; "": none).
        max_wall_rate: with `latest_only`, at most this many samples per wall second (the
            newest is taken each time): a world far faster than real time is thinned, so
            building its messages does not take the interpreter from the loop in proportion to
            its speed.

        Raises:
            EntityNotFoundError, InvalidRequestError: unknown entity, bad rate or duration.
        """
        self.rate = check_rate(rate)
        if duration is not None and not (math.isfinite(duration) and duration > 0):
            raise InvalidRequestError("duration", f"{duration} s", "give a positive duration")
        self._world = world
        self._sampler = Sampler(world, entities, descriptions, frame_prefix)
        self._entities, self._descriptions = tuple(entities), descriptions
        self._frame_prefix = self._sampler.frame_prefix
        self._sinks = list(sinks)
        self._duration = duration
        self._latest_only = latest_only
        self._wall_period = 1.0 / max_wall_rate if latest_only and max_wall_rate else 0.0
        self._next_slot = 0.0  # [s] monotonic: when the worker may take its next sample
        self._suspended = False  # set_sampling(False)
        self._pacing = False  # the worker waits out a wall period (max_wall_rate)
        self._sensor_slots: dict[float, float] = {}  # sensor rate → next wall time it may capture
        self._queue: queue.SimpleQueue[Sample | list | None] = queue.SimpleQueue()
        self._handle: int | None = None
        self._slot_lock = threading.Lock()  # latest_only: worker busy flag and newest sample
        self._busy, self._newest = False, None
        self._until: float | None = None
        self._done = threading.Event()
        self._samples, self._span = 0, [None, None]
        self._error: str | None = None
        self._worker = threading.Thread(target=self._work, name="twin-record", daemon=True)
        self._feed = SensorFeed(world, entities, self._frame_prefix, descriptions)
        self._pump = SensorPump(self._queue.put, "record-sensors")  # readings to the worker
        self._sensor_topics: dict[str, Topic] = {}  # worker thread: sensor topics seen so far
        self._layout_topics: list[Topic] = []
        # rosbags' message types, built here rather than by the worker beside a running loop:
        # the build holds the interpreter lock long enough (~0.1 s, once per process) to make a
        # real-time world drop ~50 steps
        ros.typestore()

    # ------------------------------------------------------------ control (any thread)
    def start(self) -> Recording:
        """Takes the first sample now and follows the world's stepping from here on."""
        self._worker.start()
        self._pump.start()
        with self._world.lock:
            now = float(self._world.data.time)
            self._until = None if self._duration is None else now + self._duration
            self._capture()
            if not self._done.is_set() and hasattr(self._world, "add_observer"):
                self._handle = self._world.add_observer(self._capture, self.rate)
        self._follow_sensors(self._world)
        return self

    def set_sampling(self, on: bool) -> None:
        """Suspends or resumes sampling, keeping the worker and the sinks open (benchmarks that
        alternate the loop with and without sampling, as `BagRecording.set_sampling`)."""
        with self._world.lock:
            if self._done.is_set() or (self._handle is not None) == on:
                return
            self._suspended = not on  # no heartbeat either
            if on:
                self._handle = self._world.add_observer(self._capture, self.rate)
            else:
                self._world.remove_observer(self._handle)
                self._handle = None

    def capture_now(self) -> None:
        """Takes one sample now (for callers that step the world themselves)."""
        with self._world.lock:
            self._capture()

    def stop(self) -> RecordingStatus:
        """Stops sampling, writes what is queued, closes the sinks; returns the status."""
        self._finish_sampling()
        self._worker.join()
        return self.status()

    def wait(self, timeout: float | None = None) -> bool:
        """Waits until the duration is over (or `stop`); True when sampling has ended."""
        return self._done.wait(timeout)

    def status(self) -> RecordingStatus:
        start, end = self._span
        active = not self._done.is_set()
        return RecordingStatus(active, self._samples, start, end, self._error)

    # ------------------------------------------------------------ stepping thread (lock held)
    def _capture(self) -> None:
        if self._done.is_set():
            return
        self._watch_sensors()
        sample = self._sampler.capture()
        if self._latest_only:
            with self._slot_lock:
                if self._busy:
                    self._newest = sample
                    return
                self._busy = True
        self._queue.put(sample)
        if self._until is not None and sample.time >= self._until - 1e-9:
            self._finish_sampling()

    def _capture_sensors(self, rate: float | None = None) -> None:
        if self._done.is_set():
            return
        # a live view already behind skips them: a sample waits while another is built (a
        # sample queued just now does not count: sensor ticks fall on state ticks, 10 Hz on 100)
        if self._latest_only and self._newest is not None and not self._pacing:
            return
        if self._wall_period and rate is not None:  # max_wall_rate thins sensors alike
            now = time.monotonic()
            if now < self._sensor_slots.get(rate, 0.0):
                return
            self._sensor_slots[rate] = now + self._wall_period * self.rate / rate
        self._pump.capture(self._feed, rate)  # copies; the pump's thread builds them

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
        self._queue.put(None)  # the worker closes the pump (not here: maybe the stepping thread)

    # ------------------------------------------------------------ worker thread
    def _work(self) -> None:
        publisher, layout = Publisher(), None
        try:
            while (sample := self._next()) is not None:
                if isinstance(sample, list):
                    self._publish_readings(sample)
                    continue
                while sample is not None:
                    layout = self._publish(sample, layout, publisher)
                    self._pace()
                    sample = self._next_newest()
            self._pump.close()  # its last readings, then those still queued
            while not self._queue.empty():
                item = self._queue.get()
                if isinstance(item, list):
                    self._publish_readings(item)
        except Exception as exc:  # disk full, a closed sink: stop sampling, report it
            log.exception("recording failed")
            self._error = f"{type(exc).__name__}: {exc}"
            self._finish_sampling()
            self._pump.close()
        finally:
            self._close_sinks()

    def _publish(self, sample: Sample, layout: Layout | None, publisher: Publisher) -> Layout:
        sink = _Fanout(self._sinks)
        if sample.layout is not layout:
            self._layout_topics = topics(sample.layout)
        extra = list(self._sensor_topics.values())
        new = sample.layout is not layout
        if len(publisher.publish(Samples.of(sample), sink, new_layout=new, extra_topics=extra)):
            self._count(sample.time)
            return sample.layout
        return layout

    def _publish_readings(self, readings: list) -> None:
        """Sensor messages; a new sensor topic is announced with all the others (a live sink
        closes channels that a topic list leaves out)."""
        sink = _Fanout(self._sinks)
        if any(t.name not in self._sensor_topics for t, _ in readings):
            self._sensor_topics.update({t.name: t for t, _ in readings})
            sink.set_topics(self._layout_topics + list(self._sensor_topics.values()))
        for topic, reading in readings:
            sink.write(sensor_message(topic, reading))

    def _next(self) -> Sample | None:
        """The next queued sample; a live view of a world that does not step (paused) gets the
        current state again every HEARTBEAT_S, so a viewer that connects sees the robot."""
        if not self._latest_only:
            return self._queue.get()
        while True:
            try:
                return self._queue.get(timeout=HEARTBEAT_S)
            except queue.Empty:
                with self._world.lock:
                    if not self._suspended:
                        self._capture()

    def _pace(self) -> None:
        """max_wall_rate: waits out the rest of this sample's wall period (still busy, so the
        stepping thread only replaces the newest sample meanwhile)."""
        if not self._wall_period:
            return
        now = time.monotonic()
        self._next_slot = max(self._next_slot, now - self._wall_period)
        self._next_slot += self._wall_period
        if self._next_slot > now:
            self._pacing = True  # waiting, not building: sensor captures go on
            self._done.wait(self._next_slot - now)
            self._pacing = False

    def _next_newest(self) -> Sample | None:
        """latest_only: the newest sample kept while busy, or None (and the worker is idle)."""
        if not self._latest_only:
            return None
        with self._slot_lock:
            sample, self._newest = self._newest, None
            self._busy = sample is not None
        return sample

    def _count(self, time: float) -> None:
        self._samples += 1
        if self._span[0] is None:
            self._span[0] = time
        self._span[1] = time

    def _close_sinks(self) -> None:
        for sink in self._sinks:
            try:
                sink.close()
            except Exception as exc:
                log.exception("closing %s failed", sink)
                self._error = self._error or f"{type(exc).__name__}: {exc}"


class _Fanout:
    """Several sinks as one."""

    def __init__(self, sinks: Sequence[Sink]) -> None:
        self._sinks = sinks

    def set_topics(self, topics: list[Topic]) -> None:
        for sink in self._sinks:
            sink.set_topics(topics)

    def write(self, message: Message) -> None:
        for sink in self._sinks:
            sink.write(message)


class Publisher:
    """Turns samples into messages: link poses on scratch data, and the reusable live messages
    of the current layout (`live_messages`). One per consumer thread or process."""

    def __init__(self) -> None:
        self._kinematics = Kinematics()
        self._live: LiveMessages | None = None

    def publish(
        self, samples: Samples, sink: Any, *, new_layout: bool, extra_topics: Sequence[Topic] = ()
    ) -> Samples:
        """Hands the samples' messages to `sink`, sample by sample (the layout's topics and
        latched messages first when it is new); returns the samples sent: diverged states (an
        entity being reset) are left out."""
        samples = samples.finite()
        if not len(samples):
            return samples
        exact = samples.with_exact_mimics()
        layout = samples.layout
        if new_layout:
            sink.set_topics(topics(layout) + list(extra_topics))
            for message in latched_messages(layout, float(samples.times[0])):
                sink.write(message)
        if self._live is None or self._live.layout is not layout:
            self._live = LiveMessages(layout)
        for messages in self._live.messages(exact, *self._kinematics.poses(exact)):
            for message in messages:
                sink.write(message)
        return samples


class BagSink:
    """A `BagWriter` as a sink: topics are added as they appear (an MCAP file keeps them all)."""

    def __init__(self, path: Any, *, overwrite: bool = False) -> None:
        from twin_cli.record.mcap_writer import BagWriter

        self.writer = BagWriter(path, overwrite=overwrite)

    def set_topics(self, topics: list[Topic]) -> None:
        for topic in topics:
            self.writer.add_topic(topic)

    def write(self, message: Message) -> None:
        self.writer.write(message)

    def close(self) -> None:
        self.writer.close()
