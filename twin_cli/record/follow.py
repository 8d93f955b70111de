"""Moving a running recording or live stream to another world (`twin load` swaps the world).

A mixin of `Recording` and `BagRecording`: both sample `self._world` through an observer and a
`Sampler`. The samples of the new world go on in the same file or stream; the layout changes
(a new model), so topics and latched messages are sent again. Sim time continues from the
loaded world's clock, which may be earlier than the last sample's.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from twin_cli.record.sampler import Sampler
from twin_cli.record.sensor_feed import SensorFeed

if TYPE_CHECKING:
    from twin_cli.world.engine import World


class Follows:
    """`retarget`: observe another world from now on (mixin; see module docstring); and the
    sensor observers both recorders share (`_follow_sensors` calls their `_capture_sensors`)."""

    _sensor_handles: tuple[int, ...] | list[int] = ()  # sensor observers of `_sensor_world`
    _sensor_rates: list[float] = []  # [Hz] they capture at (`_capture_sensors`' argument)
    _frame_prefix: str = "{entity}/"  # the recording's (`frames.prefix_template`)

    def retarget(self, world: World) -> None:
        """Samples `world` instead of the current one, starting with a sample now.

        Raises:
            EntityNotFoundError: a recorded entity is not in `world` (the recording is unchanged).
        """
        sampler = Sampler(world, self._entities, self._descriptions, self._frame_prefix)
        old = self._world
        if self._handle is not None:
            old.remove_observer(self._handle)
            self._handle = None
        with old.lock:
            old_time = float(old.data.time)
        self._stop_sensors()
        self._world, self._sampler, self._model = world, sampler, None
        self._feed = SensorFeed(world, self._entities, self._frame_prefix, self._descriptions)
        if self._done.is_set():
            return
        with world.lock:
            now = float(world.data.time)
            if self._until is not None:
                self._until = now + max(0.0, self._until - old_time)
            self._capture()
            if not self._done.is_set():
                self._handle = world.add_observer(self._capture, self._observer_rate(self.rate))
        self._follow_sensors(world)

    def _watch_sensors(self) -> None:
        """From a state sample (lock held): a new model (spawn, delete) may bring sensors and
        rates, so the sensor observers are registered again."""
        if self._world.model is not getattr(self, "_sensor_model", None):
            self._follow_sensors(self._world)

    def _follow_sensors(self, world: World) -> None:
        """Observes `world` at each of its sensors' rates (no sensors: not at all), reading them
        all once now: a sensor spawned into a paused world has a reading at once. The
        observers then go on at the clock's k/rate grid, the same as before a model change."""
        self._stop_sensors()
        with world.lock:
            self._sensor_model = world.model
        rates = self._feed.rates()
        if rates and not self._done.is_set():
            with world.lock:
                self._capture_sensors()
                self._sensor_world = world
                self._sensor_handles = self._observe_sensors(world, rates)

    def _observe_sensors(self, world: World, rates: list[float]) -> list[int]:
        """Registers one observer per sensor rate [Hz] (lock held); their handles. Each is on
        the clock's k/rate grid, so a sensor registered again after a spawn (or at another
        stride) keeps its stamps' grid."""
        self._sensor_rates = list(rates)
        return [
            world.add_observer(
                lambda rate=rate: self._capture_sensors(rate),
                self._observer_rate(rate),
                aligned=True,
            )
            for rate in rates
        ]

    def _observer_rate(self, rate: float) -> float:
        """The sim-time rate [Hz] an observer asking for `rate` is registered at: `rate` itself
        (a live view that thins a fast world asks for a whole fraction of it)."""
        return rate

    def _stop_sensors(self) -> None:
        for handle in getattr(self, "_sensor_handles", ()):
            self._sensor_world.remove_observer(handle)
        self._sensor_handles = []
