"""Which class simulates each sensor kind: registered by the kind's own module, looked up here.

A kind's module in `twin_cli.sensors.kinds` decorates its sensor class with
`@sensor_for(SpecType)`; `sensor_class` imports every module of that package the first time it
is asked (no list to edit), so a new kind is one module there: its `Reading` subclass and its
sensor. A sensor class takes `(spec, entity, rng)` and has `bind(model)` (find its elements by
name after each compile) and `read(model, data, time) -> Reading` (evaluated outside the
world's lock on a copy of the state). Sensors that MuJoCo computes in C add `capture(data)`
and `reading(values, time)`; those with a kept history add `latest`, `samples_since` and
`noisy_batch` (see `imu`).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any, TypeVar

from twin_cli.lazy import import_modules

PACKAGE = "twin_cli.sensors.kinds"  # every module in it is imported by `sensor_class`

T = TypeVar("T", bound=type)
_SENSORS: dict[type, Any] = {}  # SensorSpec subclass → the class that simulates it
_KINEMATIC: list[type] = []  # SensorSpec subclasses whose sensors read poses only


def sensor_for(spec_type: type, *, kinematic: bool = False) -> Callable[[T], T]:
    """Registers the decorated class as the sensor of `spec_type` records.

    Args:
        spec_type: the kind's `converters` record (a `SensorSpec` subclass).
        kinematic: its readings need poses only (rays, cameras), so a read evaluates
            `mj_kinematics` instead of the whole forward dynamics.
    """

    def register(sensor: T) -> T:
        _SENSORS[spec_type] = sensor
        if kinematic:
            _KINEMATIC.append(spec_type)
        return sensor

    return register


@cache
def _load() -> None:
    import_modules(PACKAGE)


def sensor_class(spec_type: type) -> Any:
    """The class that simulates `spec_type` records.

    Raises:
        KeyError: no module of `twin_cli.sensors.kinds` registered one.
    """
    _load()
    return _SENSORS[spec_type]


def is_kinematic(spec: object) -> bool:
    """Whether `spec`'s sensor reads poses only (see `sensor_for`)."""
    _load()
    return isinstance(spec, tuple(_KINEMATIC))
