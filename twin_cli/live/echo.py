"""One topic's messages as they come (`twin topics echo`), built as a recording builds them.

The stepping thread only copies: a world observer at the topic's rate (sim time) takes a
`Sampler` sample (state topics) or a `SensorFeed` capture of the one sensor, and appends it to
a deque. A thread of the echo's own looks at that deque every POLL_S (waking it per capture
would cost the stepping thread a futex call each: `twin_cli.record.sensor_pump`), builds the
ROS messages with the recorder's `Publisher` or `sensor_message`, so an echoed message is the
one a bag would hold, and hands each one to `deliver` as plain JSON-ready values. Past
MAX_BACKLOG captures waiting, the oldest are dropped (a ROS subscriber's queue does the same):
an echo never holds the world back. A world faster than real time is thinned to the echo's
wall-clock budget (`budget`).
"""

from __future__ import annotations

import collections
import dataclasses
import logging
import math
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from twin_cli.errors import InvalidRequestError, RequestError
from twin_cli.live.budget import WALL_SPEEDUP, WallBudget
from twin_cli.live.catalogue import LiveTopic
from twin_cli.record.recorder import MAX_RATE, Publisher
from twin_cli.record.sampler import Sampler, Samples
from twin_cli.record.sensor_feed import SensorFeed
from twin_cli.record.sensor_messages import sensor_message
from twin_cli.record.topics import Message

if TYPE_CHECKING:
    from twin_cli.world.engine import World

log = logging.getLogger("twin.live")
POLL_S = 0.01  # [s] between the echo thread's looks at its backlog
MAX_BACKLOG = 1000  # captures kept while the echo thread is behind
LATCHED_RATE = 1.0  # [Hz] of sim time: how often a latched topic is looked at for a change
DEFAULT_TRUNCATE = 128  # items of an array or characters of a string shown (ros2 topic echo's)


def plain(value: Any, truncate: int = DEFAULT_TRUNCATE) -> Any:
    """A rosbags message as JSON-ready values: fields by name, arrays as lists, floats as
    Python floats, non-finite ones kept (`json.dumps` writes them `Infinity`, `-Infinity`,
    `NaN`, which `json.loads` reads back: the echo's client prints them as ROS does, `.inf`).
    Arrays and strings longer than `truncate` (0: never) keep their first `truncate` items and
    end in "...", as `ros2 topic echo` shows them."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {
            f.name: plain(getattr(value, f.name), truncate)
            for f in dataclasses.fields(value)
            if not f.name.startswith("__")
        }
    if isinstance(value, np.ndarray | list | tuple):
        cut = bool(truncate) and len(value) > truncate
        head = value[:truncate] if cut else value
        items = head.tolist() if isinstance(head, np.ndarray) else list(head)
        return [plain(v, truncate) for v in items] + (["..."] if cut else [])
    if isinstance(value, float | np.floating):
        return float(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, str) and truncate and len(value) > truncate:
        return value[:truncate] + "..."
    return value


def echo_rate(topic: LiveTopic, rate: float | None) -> float:
    """The rate [Hz] of sim time the echo samples at: the topic's, or `rate` for state topics.

    Raises:
        InvalidRequestError: a rate outside (0, MAX_RATE] Hz, or one given for a sensor's or a
            latched topic (those come when the sensor or the world makes them).
    """
    if rate is None:
        return topic.rate or LATCHED_RATE
    if topic.sensor or topic.latched:
        what = f"sensor '{topic.sensor}'" if topic.sensor else "the world when it changes"
        raise InvalidRequestError(
            f"--rate for {topic.name}", f"its messages come from {what}", "leave out --rate"
        )
    if not (math.isfinite(rate) and 0.0 < rate <= MAX_RATE):
        raise InvalidRequestError(
            f"--rate for {topic.name}",
            f"{rate:g} Hz is not in (0, {MAX_RATE:g}]",
            "give e.g. --rate 10",
        )
    return rate


class Echo:
    """The messages of one topic of `world`, handed to `deliver` as they are made."""

    def __init__(
        self,
        world: World,
        topic: LiveTopic,
        deliver: Callable[[dict], None],
        *,
        rate: float | None = None,
        truncate: int = DEFAULT_TRUNCATE,
    ) -> None:
        """Args:
        world: the world to observe; topic: one of its `live_topics`.
        deliver: called in the echo's thread with `{"topic", "type", "time", "message"}`,
            or at the end with `{"error", "message"}` when the topic cannot be read.
        rate: [Hz] of sim time for a state topic (default: the topic's own).
        truncate: see `plain`.

        Raises:
            InvalidRequestError: see `echo_rate`. EntityNotFoundError: the entity is gone.
        """
        self._world, self._topic, self._deliver = world, topic, deliver
        self.rate = echo_rate(topic, rate)
        self._truncate = truncate
        self._backlog: collections.deque[Any] = collections.deque(maxlen=MAX_BACKLOG)
        self._stopping = threading.Event()
        self._handles: list[int] = []
        entities = (topic.entity,) if topic.entity else ()
        if topic.sensor:
            self._feed: SensorFeed | None = SensorFeed(world, entities, sensors=(topic.sensor,))
            self._sampler: Sampler | None = None
        else:
            self._feed, self._sampler = None, Sampler(world, entities)
        self._thread = threading.Thread(target=self._run, name="twin-echo", daemon=True)

    def start(self) -> Echo:
        """Takes the first capture now and follows the world's stepping from here on."""
        rates = self._feed.rates() if self._feed is not None else [self.rate]
        with self._world.lock:
            if self._feed is None:
                self._capture_state()
                self._handles = [self._world.add_observer(self._capture_state, self.rate)]
            else:
                self._handles = [
                    self._world.add_observer(lambda r=r: self._capture_sensor(r), r) for r in rates
                ]
        self._thread.start()
        return self

    def stop(self) -> None:
        """Ends the echo (any thread, without waiting): its thread removes the observers."""
        self._stopping.set()

    @property
    def stopped(self) -> bool:
        return self._stopping.is_set() and not self._thread.is_alive()

    # ------------------------------------------------------------ stepping thread (lock held)
    def _capture_state(self) -> None:
        assert self._sampler is not None
        self._backlog.append(self._sampler.capture())

    def _capture_sensor(self, rate: float) -> None:
        assert self._feed is not None
        captured = self._feed.capture(rate)
        if captured:
            self._backlog.append(captured)

    # ------------------------------------------------------------ the echo's thread
    def _run(self) -> None:
        publisher, layout = Publisher(), None
        budget = WallBudget(WALL_SPEEDUP * self.rate)
        try:
            while not self._stopping.wait(POLL_S):
                items = [self._backlog.popleft() for _ in range(len(self._backlog))]
                if self._feed is not None:
                    self._send_readings(items, budget)
                    continue
                for sample in items if self._topic.latched else budget.take(items):
                    new = sample.layout is not layout
                    publisher.publish(Samples.of(sample), self, new_layout=new)
                    layout = sample.layout
                    time.sleep(0)  # hand the GIL to the stepping thread between samples
        except Exception as exc:  # a failing build ends this echo only; the world goes on
            log.exception("echo of %s failed", self._topic.name)
            what = f"echo of {self._topic.name}"
            problem = f"internal error {type(exc).__name__}: {exc}"
            self._end_with(RequestError(what, problem, "see `twin logs`; the world still runs"))
        finally:
            self._stopping.set()
            for handle in self._handles:
                self._world.remove_observer(handle)

    def _send_readings(self, captures: list, budget: WallBudget) -> None:
        assert self._feed is not None
        readings = [
            (topic, reading)
            for captured in captures
            for topic, reading in self._feed.build(captured)
            if topic.name == self._topic.name
        ]
        for topic, reading in budget.take(readings):
            self.write(sensor_message(topic, reading))
        why = self._feed.dropped.get((self._topic.entity, self._topic.sensor))
        if why is not None:  # e.g. a camera in a server without offscreen GL
            problem = f"sensor '{self._topic.sensor}' cannot be read in this server: {why}"
            fix = "echo it again once that is fixed"
            self._end_with(InvalidRequestError(f"echo of {self._topic.name}", problem, fix))

    def _end_with(self, error: Exception) -> None:
        """Sends `error` as the last line (`{"error": class, "message"}`: the client raises it
        again) and ends the echo."""
        if not self._stopping.is_set():
            self._deliver({"error": type(error).__name__, "message": str(error)})
        self._stopping.set()

    # `Publisher`'s sink: every message of a sample passes here; this topic's are sent
    def set_topics(self, topics: list) -> None:
        """Unused: the echo follows one topic."""

    def write(self, message: Message) -> None:
        """Sends `message` if it is the echoed topic's (encoded now: its object is reused)."""
        if message.topic != self._topic.name or self._stopping.is_set():
            return
        body = plain(message.message, self._truncate)
        self._deliver({"topic": message.topic, "type": message.type, "time": message.time,
                       "message": body})  # fmt: skip
