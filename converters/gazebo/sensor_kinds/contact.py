"""`<sensor type="contact">` (and the gazebo_ros bumper plugin): SDF `contact.sdf`."""

from __future__ import annotations

from typing import Any

from converters.description.sensors import ContactSpec
from converters.gazebo.sensors import Placement, SensorReader, sensor_kind


@sensor_kind("contact", "contact")
def read_contact(reader: SensorReader, common: dict[str, Any], placement: Placement) -> ContactSpec:
    """The `<contact><collision>` name and the link's collision geoms; `<contact><topic>`."""
    collision = reader.text("contact/collision")
    common = {**common, "topic": common["topic"] or reader.text("contact/topic")}
    return ContactSpec(**common, collision=collision, geoms=placement.geoms)
