"""Read a `<sensor>` element (kept verbatim as a `Blob`) into a typed sensor record.

Follows SDFormat's `sensor.sdf` and its children (`imu.sdf`, `ray.sdf`/`lidar.sdf`,
`contact.sdf`, `force_torque.sdf`, `camera.sdf`, `noise.sdf`) with their defaults, and the
topic and frame conventions of the gazebo_ros plugins (ROS 1 `topicName`/`frameName`, ROS 2
`<ros><remapping>~/out:=scan</remapping>` and `frame_name`). Both SDF 1.5's IMU noise
(`<imu><noise><rate>/<accel>`, one model for all axes) and 1.6+'s per-axis noise are read.
Pure: no MuJoCo here; `converters.gazebo.sensor_sites` places the records in the spec.

Each kind's reader registers itself with `@sensor_kind(kind, *gazebo_types)`: the kinds below,
and one module per further kind in `converters.gazebo.sensor_kinds` (found by scanning it), so
a new kind is one module there with its `SensorSpec` subclass and its reader.
"""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any, TypeVar

from converters.description.gazebo import Blob
from converters.description.sensors import (
    NO_NOISE3,
    NOISE_TYPES,
    CameraSpec,
    ContactSpec,
    ForceTorqueSpec,
    ImuSpec,
    Noise,
    RaySpec,
    SensorSpec,
)
from converters.gazebo.tags import ValueContext, read_bool, read_float, read_int

# The package whose modules add sensor kinds (one module per kind, each calling `sensor_kind`),
# imported the first time a sensor type is looked up.
KIND_PACKAGE = "converters.gazebo.sensor_kinds"
DEPTH_TYPES = frozenset({"depth", "depth_camera", "rgbd_camera"})
AXES = ("x", "y", "z")
# Plugin children naming the topic (gazebo_ros ROS 1 plugins) and the frame (both ROS versions).
TOPIC_TAGS = ("topicName", "bumperTopicName", "topic_name")
FRAME_TAGS = ("frameName", "frame_name")
PLUGIN_NOISE_TAGS = ("gaussianNoise", "gaussian_noise")  # gazebo_ros F/T plugins, [N] and [N m]


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


@sensor_kind("imu", "imu")
def _read_imu(reader: SensorReader, common: dict[str, Any], placement: Placement) -> ImuSpec:
    imu = reader.el.find("imu")
    angular, linear = NO_NOISE3, NO_NOISE3
    orientation = True
    if imu is not None:
        angular = _axes_noise(reader, imu, "angular_velocity", "rate")
        linear = _axes_noise(reader, imu, "linear_acceleration", "accel")
        orientation = reader.flag("imu/enable_orientation", True)
    return ImuSpec(
        **common,
        angular_velocity_noise=angular,
        linear_acceleration_noise=linear,
        enable_orientation=orientation,
    )


def _axes_noise(
    reader: SensorReader, imu: ET.Element, group: str, legacy: str
) -> tuple[Noise, Noise, Noise]:
    """Per-axis noise (1.6+: `<group><x><noise>`), else SDF 1.5's `<noise><legacy>` for all."""
    old = imu.find(f"noise/{legacy}")
    if old is not None:
        kind = reader.text("noise/type", "gaussian", imu).lower()
        shared = dataclasses.replace(reader.noise(old), type=kind)
        return (shared, shared, shared)
    x, y, z = (reader.noise(imu.find(f"{group}/{axis}/noise")) for axis in AXES)
    return (x, y, z)


@sensor_kind("ray", "ray", "gpu_ray", "lidar", "gpu_lidar")
def _read_ray(reader: SensorReader, common: dict[str, Any], placement: Placement) -> RaySpec:
    ray = reader.el.find("ray")
    ray = ray if ray is not None else reader.el.find("lidar")
    if ray is None:
        return RaySpec(**common)
    values: dict[str, Any] = {}
    for direction, samples in (("horizontal", 640), ("vertical", 1)):
        path = f"scan/{direction}/"
        values[f"{direction}_samples"] = reader.integer(path + "samples", samples, ray)
        values[f"{direction}_resolution"] = reader.number(path + "resolution", 1.0, ray)
        values[f"{direction}_min_angle"] = reader.number(path + "min_angle", 0.0, ray)
        values[f"{direction}_max_angle"] = reader.number(path + "max_angle", 0.0, ray)
    return RaySpec(
        **common,
        **values,
        range_min=reader.number("range/min", 0.0, ray),
        range_max=reader.number("range/max", 0.0, ray),
        range_resolution=reader.number("range/resolution", 0.0, ray),
        noise=reader.noise(ray.find("noise")),
    )


@sensor_kind("contact", "contact")
def _read_contact(
    reader: SensorReader, common: dict[str, Any], placement: Placement
) -> ContactSpec:
    collision = reader.text("contact/collision")
    common = {**common, "topic": common["topic"] or reader.text("contact/topic")}
    return ContactSpec(**common, collision=collision, geoms=placement.geoms)


@sensor_kind("force_torque", "force_torque")
def _read_force_torque(
    reader: SensorReader, common: dict[str, Any], placement: Placement
) -> ForceTorqueSpec:
    frame = reader.text("force_torque/frame", "child").lower()
    direction = reader.text("force_torque/measure_direction", "child_to_parent").lower()
    for tag, value, allowed in (
        ("frame", frame, ("child", "parent", "sensor")),
        ("measure_direction", direction, ("child_to_parent", "parent_to_child")),
    ):
        if value not in allowed:
            raise reader.ctx.fail(
                f"{reader.prefix} force_torque/{tag}", value, " or ".join(allowed)
            )
    ft = reader.el.find("force_torque")
    force, torque = NO_NOISE3, NO_NOISE3
    if ft is not None:
        force = _group_noise(reader, ft, "force")
        torque = _group_noise(reader, ft, "torque")
    if not any(n.active for n in force + torque):
        force = torque = _plugin_noise(reader)
    return ForceTorqueSpec(
        **common,
        joint=placement.joint,
        frame=frame,
        measure_direction=direction,
        child_body=placement.body,
        parent_body=placement.parent_body,
        force_noise=force,
        torque_noise=torque,
    )


def _group_noise(reader: SensorReader, el: ET.Element, group: str) -> tuple[Noise, Noise, Noise]:
    """SDF 1.6+ per-axis noise of a vector (`<force><x><noise>`, ...)."""
    x, y, z = (reader.noise(el.find(f"{group}/{axis}/noise")) for axis in AXES)
    return (x, y, z)


def _plugin_noise(reader: SensorReader) -> tuple[Noise, Noise, Noise]:
    """The gazebo_ros F/T plugin's `<gaussianNoise>` (ROS 1) or `<gaussian_noise>` (ROS 2):
    a zero-mean Gaussian of that standard deviation on every axis, as the plugin adds it."""
    for plugin in reader.el.findall("plugin"):
        for tag in PLUGIN_NOISE_TAGS:
            stddev = reader.number(tag, 0.0, plugin)
            if stddev > 0.0:
                noise = Noise("gaussian", stddev=stddev)
                return (noise, noise, noise)
    return NO_NOISE3


@sensor_kind("camera", "camera", "depth", "depth_camera", "rgbd_camera", "wideanglecamera")
def _read_camera(reader: SensorReader, common: dict[str, Any], placement: Placement) -> CameraSpec:
    camera = reader.el.find("camera")
    if camera is None:
        return CameraSpec(**common, depth=common["type"].lower() in DEPTH_TYPES)
    near = reader.number("clip/near", 0.1, camera)
    far = reader.number("clip/far", 100.0, camera)
    if not 0.0 < near < far:
        expected = "0 < near < far (metres)"
        raise reader.ctx.fail(
            f"{reader.prefix} camera/clip", f"near {near:g} far {far:g}", expected
        )
    return CameraSpec(
        **common,
        width=reader.integer("image/width", 320, camera),
        height=reader.integer("image/height", 240, camera),
        horizontal_fov=reader.number("horizontal_fov", 1.047, camera),
        near=near,
        far=far,
        image_format=reader.text("image/format", "R8G8B8", camera),
        depth=common["type"].lower() in DEPTH_TYPES,
        noise=reader.noise(camera.find("noise")),
    )
