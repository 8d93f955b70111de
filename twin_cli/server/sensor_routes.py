"""Routes of the robots' sensors: list an entity's sensors and read them (`twin sensors`).

Each entity gets one `twin_cli.sensors.SensorSuite` per served world, kept between requests so
that update rates and noise streams carry on; requests run on a thread pool, so each suite has
its own lock. A reading is refreshed only when its sensor is due in sim time.
"""

from __future__ import annotations

import threading
from typing import Any

from fastapi import APIRouter, Request

from twin_cli.server.holder import WorldDep

router = APIRouter()


class _Suites:
    """The sensor suites of the served world(s), by (world, entity)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.suites: dict[tuple[int, str], tuple[Any, threading.Lock]] = {}

    def get(self, world: Any, entity: str) -> tuple[Any, threading.Lock]:
        from twin_cli.sensors import SensorSuite

        key = (id(world), entity)
        with self.lock:
            found = self.suites.get(key)
            if found is None or found[0].world is not world:
                found = (SensorSuite(world, entity), threading.Lock())
                self.suites[key] = found
            return found


def _suites(request: Request) -> _Suites:
    state = request.app.state
    if getattr(state, "sensor_suites", None) is None:
        state.sensor_suites = _Suites()
    return state.sensor_suites


@router.get("/entities/{name}/sensors")
def list_sensors(name: str, request: Request, world: WorldDep, read: bool = False) -> dict:
    """The entity's sensors (name, type, link, rate, topic, frame); `read=true` adds readings."""
    from twin_cli.sensors import describe_sensors

    suite, lock = _suites(request).get(world, name)
    with lock:
        sensors = describe_sensors(list(suite.specs.values()))
        if read:
            readings = suite.read()
            for entry in sensors:
                entry["reading"] = readings[entry["name"]].to_dict()
    return {"entity": name, "sensors": sensors}


@router.get("/entities/{name}/sensors/{sensor}")
def read_sensor(name: str, sensor: str, request: Request, world: WorldDep) -> dict:
    """The latest reading of one sensor (refreshed when due); +inf ranges are null."""
    suite, lock = _suites(request).get(world, name)
    with lock:
        return suite.read([sensor])[sensor].to_dict()
