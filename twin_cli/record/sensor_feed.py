"""The recorded entities' sensor readings, taken in the stepping thread at the sensors' rates.

Read through `twin_cli.sensors.SensorSuite` (its public API only: how readings are computed is
that package's business). One world observer runs at the fastest sensor's rate; each call
returns the readings that are new since the last (a suite refreshes a sensor once per its own
period and hands back the previous reading otherwise). Suites are rebuilt when the world's
model changes (spawn, delete, load).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from twin_cli.record.sensor_messages import sensor_topic
from twin_cli.record.topics import Topic
from twin_cli.sensors import Reading, SensorSuite
from twin_cli.world.observers import world_view

MAX_RATE = 1000.0  # [Hz] of sim time, as recordings (recorder.MAX_RATE)


class SensorFeed:
    """New sensor readings of some (or all) entities of a world, as (topic, reading) pairs."""

    def __init__(self, world: Any, entities: Sequence[str] = ()) -> None:
        self._world, self._names = world, tuple(entities)
        self._model: Any = None
        self._suites: dict[str, SensorSuite] = {}
        self._last: dict[tuple[str, str], float] = {}

    def rate(self) -> float:
        """[Hz] of sim time the feed must be called at: the fastest sensor's (0: no sensors)."""
        with self._world.lock:
            self._refresh()
            step = 1.0 / float(self._world.model.opt.timestep)
        rates = [
            (spec.update_rate or step)
            for suite in self._suites.values()
            for spec in suite.specs.values()
        ]
        return min(max(rates, default=0.0), MAX_RATE, step)

    def fresh(self) -> list[tuple[Topic, Reading]]:
        """Readings taken since the last call; call with the world's lock held."""
        self._refresh()
        out = []
        for entity, suite in self._suites.items():
            for name, reading in suite.read().items():
                if self._last.get((entity, name)) == reading.time:
                    continue
                self._last[(entity, name)] = reading.time
                topic = sensor_topic(entity, name, suite.specs[name].topic, reading)
                if topic is not None:
                    out.append((topic, reading))
        return out

    def _refresh(self) -> None:
        if self._world.model is self._model:
            return
        view = world_view(self._world)
        names = self._names or tuple(view.index)
        suites = {n: SensorSuite(self._world, n) for n in names if n in view.index}
        self._suites = {n: s for n, s in suites.items() if s.names}
        self._last = {}
        self._model = view.model
