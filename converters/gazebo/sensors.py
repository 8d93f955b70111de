"""Read a `<sensor>` element (kept verbatim as a `Blob`) into a typed sensor record.

Follows SDFormat's `sensor.sdf` and `noise.sdf` with their defaults, and the topic and frame
conventions of the gazebo_ros plugins (ROS 1 `topicName`/`frameName`, ROS 2
`<ros><remapping>~/out:=scan</remapping>` and `frame_name`). Pure: no MuJoCo here;
`converters.gazebo.sensor_sites` places the records in the spec.

Each kind's reader registers itself with `@sensor_kind(kind, *gazebo_types)` in its own module
of `converters.gazebo.sensor_kinds` (`imu`, `ray`, `contact`, `force_torque`, `camera`, and any
module added there), found by scanning that package the first time a type is looked up; this
module reads what every sensor has.
"""

from __future__ import annotations

import importlib
import pkgutil
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any, TypeVar

from converters.description.gazebo import Blob
from converters.description.sensors import NOISE_TYPES, Noise, SensorSpec
from converters.gazebo.tags import ValueContext, read_bool, read_float, read_int

# The package whose modules add sensor kinds (one module per kind, each calling `sensor_kind`),
# imported the first time a sensor type is looked up.
KIND_PACKAGE = "converters.gazebo.sensor_kinds"
AXES = ("x", "y", "z")
# Plugin children naming the topic (gazebo_ros ROS 1 plugins) and the frame (both ROS versions).
TOPIC_TAGS = ("topicName", "bumperTopicName", "topic_name")
FRAME_TAGS = ("frameName", "frame_name")


@dataclass(frozen=True)
class Placement:
    """Where a sensor sits before its type is read: its link, MuJoCo body and joint (F/T)."""

    link: str
    body: str
    joint: str = ""
    parent_body: str = ""
    anchor: tuple[float, float, float] = (0.0, 0.0, 0.0)
    geoms: tuple[str, ...] = ()


Read = Callable[["SensorReader", dict[str, Any], Placement], SensorSpec]
R = TypeVar("R", bound=Read)
_KINDS: dict[str, str] = {}  # Gazebo sensor type (lower case) → the kind twin simulates
_READERS: dict[str, Read] = {}  # kind → its reader


def sensor_kind(kind: str, *gazebo_types: str) -> Callable[[R], R]:
    """Registers the decorated reader as kind `kind`, read from `<sensor type=...>` of each of
    `gazebo_types` (Gazebo Classic's and gz-sim's names).

    The reader takes the element (`SensorReader`), the values every sensor has (`SensorSpec`'s
    fields, by name) and its `Placement`, and returns the kind's `SensorSpec` subclass.
    """

    def register(read: R) -> R:
        _READERS[kind] = read
        _KINDS.update({t.lower(): kind for t in gazebo_types})
        return read

    return register


@cache
def _load_kinds() -> None:
    package = importlib.import_module(KIND_PACKAGE)
    for module in pkgutil.iter_modules(package.__path__):
        importlib.import_module(f"{KIND_PACKAGE}.{module.name}")


def kind_of(gazebo_type: str | None) -> str | None:
    """The kind twin simulates a `<sensor type=...>` as, or None when it simulates none."""
    _load_kinds()
    return _KINDS.get((gazebo_type or "").lower())


class SensorReader:
    """Typed lookups inside one `<sensor>` element, failing with file, sensor and tag."""

    def __init__(self, el: ET.Element, blob: Blob, link: str) -> None:
        self.el = el
        self.ctx = ValueContext(blob.where.split(": <gazebo")[0], link)
        self.prefix = f"sensor '{blob.name}'"

    def text(self, path: str, default: str = "", el: ET.Element | None = None) -> str:
        found = (self.el if el is None else el).find(path)
        if found is None or found.text is None:
            return default
        return found.text.strip()

    def number(self, path: str, default: float, el: ET.Element | None = None) -> float:
        raw = self.text(path, "", el)
        return default if raw == "" else read_float(self.ctx, f"{self.prefix} {path}", raw)

    def integer(self, path: str, default: int, el: ET.Element | None = None) -> int:
        raw = self.text(path, "", el)
        return default if raw == "" else read_int(self.ctx, f"{self.prefix} {path}", raw)

    def flag(self, path: str, default: bool) -> bool:
        raw = self.text(path)
        return default if raw == "" else read_bool(self.ctx, f"{self.prefix} {path}", raw)

    def pose(self) -> tuple[float, float, float, float, float, float]:
        raw = self.text("pose")
        parts = raw.split() if raw else ["0"] * 6
        if len(parts) != 6:
            raise self.ctx.fail(f"{self.prefix} pose", raw, "six numbers (x y z roll pitch yaw)")
        x, y, z, r, p, w = (read_float(self.ctx, f"{self.prefix} pose", v) for v in parts)
        return (x, y, z, r, p, w)

    def noise(self, el: ET.Element | None) -> Noise:
        """SDF `<noise>` (type as attribute, 1.6+, or as a child, 1.5)."""
        if el is None:
            return Noise()
        kind = (el.get("type") or self.text("type", "none", el)).lower()
        if kind not in NOISE_TYPES:
            expected = "one of " + ", ".join(NOISE_TYPES)
            raise self.ctx.fail(f"{self.prefix} noise type", kind, expected)
        fields = ("mean", "stddev", "bias_mean", "bias_stddev", "precision")
        values = {f: self.number(f, 0.0, el) for f in fields}
        return Noise(kind, **values)

    def vector_noise(self, el: ET.Element, group: str) -> tuple[Noise, Noise, Noise]:
        """SDF 1.6+ noise per axis of a vector inside `el` (`<group><x><noise>`, y, z)."""
        x, y, z = (self.noise(el.find(f"{group}/{axis}/noise")) for axis in AXES)
        return (x, y, z)


def read_sensor(blob: Blob, placement: Placement) -> SensorSpec:
    """The typed record of one sensor blob of a known kind (see `kind_of`).

    Raises:
        GazeboTagError: a value is not a number/boolean where SDF wants one (names the file,
            link, sensor and tag).
        KeyError: `blob.kind` is no registered type (callers report those as ignored instead).
    """
    el = ET.fromstring(blob.xml)
    reader = SensorReader(el, blob, placement.link)
    kind = kind_of(blob.kind)
    if kind is None:
        raise KeyError(blob.kind)
    common = _common(reader, blob, placement)
    return _READERS[kind](reader, common, placement)


def _common(reader: SensorReader, blob: Blob, placement: Placement) -> dict[str, Any]:
    topic, frame_id = _ros_names(reader.el)
    return {
        "name": blob.name or f"{placement.link}_{blob.kind}",
        "type": blob.kind or "",
        "link": placement.link,
        "pose": reader.pose(),
        "update_rate": max(0.0, reader.number("update_rate", 0.0)),
        "always_on": reader.flag("always_on", False),
        "topic": reader.text("topic") or topic,
        "frame_id": frame_id or placement.link,
        "where": blob.where,
        "body": placement.body,
    }


def _ros_names(el: ET.Element) -> tuple[str, str]:
    """(topic, frame) from the sensor's gazebo_ros plugin, as the plugin would publish them."""
    topic = frame = ""
    for plugin in el.findall("plugin"):
        for tag in TOPIC_TAGS:
            topic = topic or (plugin.findtext(tag) or "").strip()
        for tag in FRAME_TAGS:
            frame = frame or (plugin.findtext(tag) or "").strip()
        for remap in plugin.findall("ros/remapping"):
            _, sep, target = (remap.text or "").partition(":=")
            topic = topic or (target.strip() if sep else "")
        namespace = (plugin.findtext("ros/namespace") or "").strip().strip("/")
        if topic and namespace and not topic.startswith("/"):
            topic = f"/{namespace}/{topic}"
    return topic, frame
