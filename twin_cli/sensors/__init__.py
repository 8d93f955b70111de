"""Sensors of a running world: Gazebo's `<sensor>`s read from the world at their own rates.

A consumer of the world (like the recorder): it reads the engine's state under its lock and
computes outside it; the world never imports it. Modules: `suite` (all sensors of an entity,
update rates; `capture` then `complete` for recorders, which take every reading: see
`twin_cli.record.sensor_feed`), `snapshot` (state copy and its dynamics), `history` (past
samples MuJoCo keeps), `registry` (which class simulates each kind), `kinds/` (`imu`, `ray`,
`contact`, `force_torque`, `camera`: one sensor kind each, found by scanning), `noise`
(Gazebo's Gaussian noise, seeded), `readings` (what each reports), `frames` (finding a
sensor's elements by name).
"""

from __future__ import annotations

from twin_cli.sensors.history import HISTORY_SAMPLES
from twin_cli.sensors.readings import (
    ContactReading,
    ContactState,
    ImageReading,
    ImuReading,
    Reading,
    ScanReading,
    WrenchReading,
)
from twin_cli.sensors.suite import SensorSuite, describe_sensors

__all__ = [
    "HISTORY_SAMPLES",
    "ContactReading",
    "ContactState",
    "ImageReading",
    "ImuReading",
    "Reading",
    "ScanReading",
    "SensorSuite",
    "WrenchReading",
    "describe_sensors",
]
