"""Sensors into the built spec: a site `sensor:<name>` per sensor, and one report entry each.

Gazebo attaches a sensor to a link at `<pose>` in the link frame; after fixed-joint lumping
that link may live inside its parent's body, at the pose its frame site records (sdformat moves
the sensor the same way). The site carries the frame, so a running world finds it by name
(`<entity>/sensor:<name>`); cameras also get a MuJoCo camera of the same name, turned from
Gazebo's convention (look along +x, +z up) to MuJoCo's (look along −z, +y up).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from converters.description import RobotDescription
from converters.description.gazebo import Blob
from converters.description.sensors import (
    HISTORY_SAMPLES,
    CameraSpec,
    ForceTorqueSpec,
    SensorSpec,
)
from converters.description.transforms import pose_matrix
from converters.errors import InputFileError
from converters.gazebo.sensors import Placement, kind_of, read_sensor
from converters.provenance import Provenance
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

SITE_GROUP = 5  # the group of the builder's frame sites (lumped links, SDF frames)
# Gazebo camera axes (x forward, y left, z up) in MuJoCo camera axes (x right, y up, z back).
R_SENSOR_CAMERA = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def add_sensors(
    spec: mujoco.MjSpec, robot: RobotDescription, provenance: Provenance, report: Report
) -> tuple[SensorSpec, ...]:
    """Read every sensor of the robot, place a site for each and report what was mapped.

    Args:
        spec: the robot's built spec (bodies named as in `provenance`).
        robot: the description; sensors are in `robot.gazebo` (links and joints).
        provenance: body of each link, the geoms built from each link's collisions.
        report: one `mapped` entry per sensor (type, rate, noise), `ignored` for the rest.

    Returns:
        The typed sensors, in document order (links first, then joints).

    Raises:
        GazeboTagError: a sensor value that cannot be read.
        InputFileError: two sensors with one name (readings are addressed by name).
    """
    found: list[SensorSpec] = []
    for blob, placement, subject in _candidates(robot, provenance, report):
        if kind_of(blob.kind) is None:
            report.ignored(subject, f"sensor type '{blob.kind}' is not simulated", tag="sensor")
            continue
        sensor = read_sensor(blob, placement)
        if any(s.name == sensor.name for s in found):
            raise InputFileError(
                robot.source,
                f"sensor '{sensor.name}' ({subject}) is defined twice",
                "give each <sensor> a unique name",
            )
        _add_site(spec, sensor, robot, provenance)
        found.append(sensor)
        report.mapped(subject, describe(sensor), tag="sensor")
    return tuple(found)


def _candidates(
    robot: RobotDescription, provenance: Provenance, report: Report
) -> list[tuple[Blob, Placement, str]]:
    """Each sensor blob with where it sits; sensors that cannot be placed are reported."""
    out: list[tuple[Blob, Placement, str]] = []
    for link, ext in robot.gazebo.links.items():
        for blob in ext.sensors:
            subject = f"link '{link}' sensor '{blob.name}'"
            body = provenance.body_of_link.get(link)
            if body is None:
                report.ignored(subject, f"no link named '{link}' carries it", tag="sensor")
                continue
            geoms = _collision_geoms(link, body, provenance)
            out.append((blob, Placement(link, body, geoms=geoms), subject))
    joints = {j.name: j for j in robot.joints}
    for name, ext in robot.gazebo.joints.items():
        for blob in ext.sensors:
            subject = f"joint '{name}' sensor '{blob.name}'"
            joint = joints[name]
            body = provenance.body_of_link[joint.child]
            parent = provenance.body_of_link[joint.parent]
            if body == parent:
                reason = "fixed joint lumped into its parent; set preserveFixedJoint to measure it"
                report.ignored(subject, reason, tag="sensor")
                continue
            placement = Placement(joint.child, body, name, parent, joint.anchor)
            out.append((blob, placement, subject))
    return out


def _collision_geoms(link: str, body: str, provenance: Provenance) -> tuple[str, ...]:
    """The link's collision geoms, with those of links lumped into it: sdformat moves a lumped
    child's collisions onto the parent link (`<parent>_fixed_joint_lump__<child>_collision`),
    which is where a foot's contact sensor then names them (aliengo, hyq)."""
    if link != body:
        return tuple(g.geom for g in provenance.geoms_of_link(link))
    return tuple(g.geom for g in provenance.geoms if g.body == body and g.role == "collision")


def _add_site(
    spec: mujoco.MjSpec, sensor: SensorSpec, robot: RobotDescription, provenance: Provenance
) -> None:
    """The sensor's site (and camera) on its link's body, at link pose × sensor pose."""
    T_body_link = _T_body_link(spec, sensor.link, sensor.body)
    if isinstance(sensor, ForceTorqueSpec):  # at the joint's origin (SDF: in the child frame)
        T_body_link = T_body_link @ pose_matrix((*robot_anchor(robot, sensor.joint), 0, 0, 0))
    T_body_site = T_body_link @ pose_matrix(sensor.pose)
    body = spec.worldbody if sensor.body == "world" else spec.body(sensor.body)
    pos, quat = _pos_quat(T_body_site)
    body.add_site(name=sensor.site, pos=pos, quat=quat, group=SITE_GROUP)
    if isinstance(sensor, CameraSpec):
        T_body_camera = T_body_site.copy()
        T_body_camera[:3, :3] = T_body_site[:3, :3] @ R_SENSOR_CAMERA
        pos, quat = _pos_quat(T_body_camera)
        aspect = sensor.height / max(1, sensor.width)
        fovy = math.degrees(2.0 * math.atan(math.tan(sensor.horizontal_fov / 2.0) * aspect))
        body.add_camera(name=sensor.site, pos=pos, quat=quat, fovy=fovy)
    _add_native(spec, sensor)


def _add_native(spec: mujoco.MjSpec, sensor: SensorSpec) -> None:
    """MuJoCo's own sensors on the site, computed in C at every step (`sensor:<name>:<part>`).

    A running world then reads an IMU or F/T sensor by copying `sensordata` (a few µs under
    the world's lock) instead of evaluating the world's dynamics again per reading. MuJoCo's
    accelerometer is the specific force a − g (+g up at rest) and its force/torque sensors are
    the child body's interaction wrench at the site, in the site frame: what the twin sensors
    report (`twin_cli.sensors.kinds`).
    An IMU's (`native_history`) are computed only at its update period (`interval`) and keep
    their last HISTORY_SAMPLES samples with their times (`nsample`), so a recorder reads every
    sample in one look instead of stopping the stepping at each period (`sensors.history`).
    """
    import mujoco

    history = {}
    if sensor.native_history:
        period = 1.0 / sensor.update_rate if sensor.update_rate > 0 else 0.0
        history = {"nsample": HISTORY_SAMPLES, "interval": [period, 0.0]}
    for part, kind in sensor.native_parts:
        spec.add_sensor(
            name=f"{sensor.site}:{part}",
            type=getattr(mujoco.mjtSensor, kind),
            objtype=mujoco.mjtObj.mjOBJ_SITE,
            objname=sensor.site,
            **history,
        )


def robot_anchor(robot: RobotDescription, joint: str) -> tuple[float, float, float]:
    """The joint's origin in its child link's frame [m]."""
    return next(j.anchor for j in robot.joints if j.name == joint)


def _T_body_link(spec: mujoco.MjSpec, link: str, body: str) -> np.ndarray:
    """The link frame in its body: identity, or the lumped link's frame site (builder)."""
    if link == body:
        return np.eye(4)
    site = spec.site(link)
    T = np.eye(4)
    if site is None:  # the world link: its frame is the world's
        return T
    import mujoco

    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, np.asarray(site.quat, float))
    T[:3, :3] = R.reshape(3, 3)
    T[:3, 3] = site.pos
    return T


def _pos_quat(T: np.ndarray) -> tuple[list[float], list[float]]:
    import mujoco

    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T[:3, :3]).reshape(-1))
    return T[:3, 3].tolist(), quat.tolist()


def describe(sensor: SensorSpec) -> str:
    """One report line: what the sensor became, its rate and its noise."""
    rate = f"{sensor.update_rate:g} Hz" if sensor.update_rate > 0 else "every physics step"
    head = f"<sensor type='{sensor.type}'> → site '{sensor.site}' at {rate}"
    return f"{head}; {sensor.details()}"
