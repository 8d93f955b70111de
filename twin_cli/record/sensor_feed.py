"""The recorded entities' sensor readings: copied in the stepping thread, built in the consumer's.

Read through `twin_cli.sensors.SensorSuite` (its public API only: how readings are computed is
that package's business). One world observer per distinct sensor rate calls `capture` at that
rate in sim time (so a 30 Hz camera is stamped at its own period, not at a faster IMU's next
tick; sensors of entities spawned later go with the fastest observer). It copies what the due
sensors need, or, for a sensor whose samples MuJoCo keeps (an IMU: `twin_cli.sensors.history`),
every sample since the last look: that observer runs POLLS_PER_HISTORY times per history
length instead of at every period, and each sample keeps its own sim time. The recorder's own
thread calls `build`, which casts the lidar rays, renders the cameras and draws the noise there,
off the stepping thread, which they would slow. A sensor that cannot be read in this process (a
camera without offscreen GL) is left out of the recording from then on, with one warning naming
it and the fix; the other sensors go on. Suites are rebuilt when the world's model changes.
Each built reading names the tf frame the recording publishes for it (`frames.sensor_frame`;
contacts: `world`, whose coordinates they are in).
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from twin_cli.record.frames import WORLD_FRAME, prefix_template, sources_of
from twin_cli.record.sensor_messages import sensor_topic
from twin_cli.record.tf_tree import entity_tree, model_names
from twin_cli.record.topics import Topic
from twin_cli.sensors import HISTORY_SAMPLES, ContactReading, Reading, SensorSuite
from twin_cli.world.observers import world_view

if TYPE_CHECKING:
    import mujoco

    from twin_cli.world.engine import World

log = logging.getLogger("twin.record")
MAX_RATE = 1000.0  # [Hz] of sim time, as recordings (recorder.MAX_RATE)
KEPT = -1.0  # `capture(KEPT)`: every sensor with a history, whatever its rate (a last look)
POLLS_PER_HISTORY = 2  # looks at a sensor's kept samples per HISTORY_SAMPLES periods

# (suite, SensorSuite.capture's Pending, sensor → frame as named at the capture)
Captured = list[tuple[SensorSuite, Any, dict[str, str]]]


class SensorFeed:
    """New sensor readings of some (or all) entities of a world, as (topic, reading) pairs."""

    def __init__(
        self,
        world: World,
        entities: Sequence[str] = (),
        frame_prefix: str | None = None,
        descriptions: dict[str, str] | None = None,
        sensors: Sequence[str] = (),
    ) -> None:
        """Args: the world, the entities (empty: all), the tf frame prefix template and URDF
        texts overriding the world's (as `Sampler`): the readings' frames are tf's; `sensors`:
        only these sensor names (empty: all; `twin topics echo` follows one sensor)."""
        self._world, self._names = world, tuple(entities)
        self._only = frozenset(sensors)
        self._template = prefix_template(frame_prefix)
        self._descriptions = dict(descriptions or {})
        self._frames: dict[str, dict[str, str]] = {}  # entity → sensor → its messages' frame
        self._model: mujoco.MjModel | None = None
        self._suites: dict[str, SensorSuite] = {}
        self._wanted: dict[str, list[str]] = {}  # entity → its sensors still recorded
        self._rates: list[float] = []  # [Hz] of the observers, fastest first
        self._groups: dict[float | None, dict[str, list[str]]] = {}  # rate → entity → sensors
        self.dropped: dict[tuple[str, str], str] = {}  # (entity, sensor) → why
        self._kept: dict[str, set[str]] = {}  # entity → its sensors with a history
        self._last: dict[tuple[str, str], float] = {}  # (entity, sensor) → last sample [s]
        # a live view's thinning: at most wall_share × rate kept samples of a sensor per wall
        # second (the newest); None: every one (a bag)
        self.wall_share: float | None = None
        self._looked: dict[tuple[str, str], float] = {}  # (entity, sensor) → wall time [s]

    def rates(self) -> list[float]:
        """[Hz] of sim time to call `capture(rate)` at, one per distinct sensor rate, fastest
        first (empty: no sensors). Rates are capped at MAX_RATE and the step rate."""
        with self._world.lock:
            self._refresh()
            self._rates = sorted(
                {self._rate(e, n) for e, names in self._wanted.items() for n in names}, reverse=True
            )
            self._group()
        return list(self._rates)

    def capture(self, rate: float | None = None) -> Captured:
        """Copies what the sensors due now need (of the observer at `rate`; None: all sensors);
        call with the world's lock held."""
        self._refresh()
        out = []
        if rate == KEPT:
            group = {
                e: [n for n in names if n in self._kept[e]] for e, names in self._wanted.items()
            }
        else:
            group = self._groups.get(rate, self._wanted) if rate is not None else self._wanted
        now = float(self._world.data.time)
        for entity, suite in self._suites.items():
            names = group.get(entity)
            if names and self.dropped:
                names = [n for n in names if (entity, n) not in self.dropped]
            if not names:
                continue
            kept = self._kept[entity]
            since = {n: self._since(entity, n, now) for n in names if n in kept}
            pending = suite.capture(names, since)
            for name, (times, _) in pending.batches.items():
                self._last[(entity, name)] = float(times[-1])
            if pending.native or pending.rest or pending.batches:  # frames named now: a
                # delete before the build must not strip the entity's prefix from them
                out.append((suite, pending, self._frames.get(entity, {})))
        return out

    def build(self, captured: Captured) -> list[tuple[Topic, Reading]]:
        """The readings of `captured` with their topics (any thread but the stepping one)."""
        out = []
        for suite, pending, frames in captured:
            errors: dict[str, Exception] = {}
            for reading in suite.complete(pending, errors):
                name = reading.sensor
                topic = sensor_topic(suite.entity, name, suite.specs[name].topic, reading)
                if topic is not None:
                    out.append((topic, _framed(frames, reading)))
            for name, error in errors.items():
                self._drop(suite.entity, name, error)
        return out

    def _since(self, entity: str, name: str, now: float) -> float:
        """Sim time [s] after which a kept sample is new: the last one taken, or (first look, or
        the clock went back) this very instant on; with `wall_share`, only the newest that the
        wall time since the last look allows."""
        last = self._last.get((entity, name))
        if last is None or last > now:
            last = self._last[(entity, name)] = now - 1e-9
        if self.wall_share is None:
            return last
        rate = self._suites[entity].specs[name].update_rate or 1.0 / self._world.model.opt.timestep
        wall = time.monotonic()
        allowed = (wall - self._looked.get((entity, name), 0.0)) * self.wall_share * rate
        self._looked[(entity, name)] = wall
        # the newest max(1, allowed): within that many periods and a half of now
        return max(last, now - (max(1.0, allowed) + 0.5) / rate)

    def _drop(self, entity: str, name: str, error: Exception) -> None:
        if (entity, name) in self.dropped:
            return
        self.dropped[(entity, name)] = str(error)  # the stepping thread filters on it
        log.warning("not recording sensor '%s' of [%s]: %s", name, entity, error)

    def _refresh(self) -> None:
        if self._world.model is self._model:
            return
        view = world_view(self._world)
        names = self._names or tuple(view.index)
        suites = {n: SensorSuite(self._world, n) for n in names if n in view.index}
        self._suites = {n: s for n, s in suites.items() if s.names}
        self._wanted = {
            n: [s for s in suite.names if (n, s) not in self.dropped and self._chosen(s)]
            for n, suite in self._suites.items()
        }
        self._kept = {n: set(suite.with_history()) for n, suite in self._suites.items()}
        self._frames = self._sensor_frames(view)
        self._model = view.model
        self._group()

    def _chosen(self, sensor: str) -> bool:
        return not self._only or sensor in self._only

    def _sensor_frames(self, view: Any) -> dict[str, dict[str, str]]:
        """Each recorded sensor's frame, as the recording's tf tree names it."""
        names = model_names(view.model)
        out = {}
        for entity in self._suites:
            sources = sources_of(
                self._world, entity, self._template, self._descriptions.get(entity)
            )
            tree = entity_tree(view.model, names, entity, view.index[entity], sources)
            out[entity] = tree.sensor_frames
        return out

    def _group(self) -> None:
        """Sensors by the observer that captures them: their own rate's, else the fastest."""
        self._groups = {rate: {} for rate in self._rates}
        for entity, names in self._wanted.items():
            for name in names:
                rate = self._rate(entity, name)
                group = rate if rate in self._groups else (self._rates or [None])[0]
                self._groups.setdefault(group, {}).setdefault(entity, []).append(name)

    def _rate(self, entity: str, name: str) -> float:
        """[Hz] of the observer that captures a sensor: its rate (capped), or for one with a
        history, POLLS_PER_HISTORY looks per history length."""
        step = 1.0 / float(self._world.model.opt.timestep)
        spec = self._suites[entity].specs[name]
        if name in self._kept.get(entity, ()):
            return (spec.update_rate or step) * POLLS_PER_HISTORY / HISTORY_SAMPLES
        return min(spec.update_rate or step, MAX_RATE, step)


def _framed(frames: dict[str, str], reading: Reading) -> Reading:
    """The reading with the tf frame its data is in (`frames`: sensor → frame, as named when it
    was captured): contacts are in world coordinates."""
    frame = (
        WORLD_FRAME
        if isinstance(reading, ContactReading)
        else frames.get(reading.sensor, reading.frame_id)
    )
    return dataclasses.replace(reading, frame_id=frame)
