"""Gazebo model plugins: the diff drive read into a typed record, every plugin classified.

twin runs `libgazebo_ros_diff_drive.so` as a controller of its own (`twin_cli.control`), so the
converter reads its parameters, under both spellings gazebo_ros_pkgs accepts: ROS 2
(`left_joint`, `wheel_separation`, `max_wheel_torque`, `odometry_source` 0/1 ...) and ROS 1
(`leftJoint`, `wheelSeparation`, `wheelTorque`, `odometrySource` encoder/world ...), with the
plugin's own defaults. Each wheel joint gets a motor (`ctrlrange` = ±max wheel torque, the
joint's `fmax` in Gazebo) when it has none, so the world's velocity servo can drive it.
`gazebo_ros2_control` / `gazebo_ros_control` plugins enable the robot's command interfaces
(mapped elsewhere); gz-sim's MulticopterMotorModel becomes actuators per rotor
(`converters.gazebo.multicopter`); LiftDrag and the underwater systems are reported with what they
would need; every other plugin is reported by name as not run.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from converters.control_text import set_control_record
from converters.description.gazebo import Blob
from converters.errors import GazeboTagError
from converters.gazebo.multicopter import (
    Rotor,
    add_rotors,
    is_motor_model,
    missing_names,
    read_rotor,
)
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

DIFF_DRIVE_FILES = ("libgazebo_ros_diff_drive.so", "gazebo_ros_diff_drive")
CONTROL_FILES = ("libgazebo_ros2_control.so", "libgazebo_ros_control.so", "gazebo_ros2_control")
# Defaults of gazebo_ros_diff_drive (ROS 2 `Load`, ROS 1 `getParameter` defaults).
DEFAULT_SEPARATION = 0.34  # [m]
DEFAULT_DIAMETER = 0.15  # [m]
DEFAULT_TORQUE = 5.0  # [N m]
DEFAULT_ACCELERATION = 0.0  # [m/s²] at the wheel rim; 0 = unlimited
DEFAULT_RATE = 100.0  # [Hz]
# Systems twin does not run, with what running them would need (one report line each).
NEEDS = {
    "gz-sim-lift-drag-system": "LiftDrag: not run; needs lift and drag along the blade's "
    "velocity at its centre of pressure (quadratic in speed, by angle of attack), which no "
    "MuJoCo actuator expresses without code at every step",
    "gz-sim-hydrodynamics-system": "Hydrodynamics: not run; needs added mass and linear and "
    "quadratic damping in the body frame (MuJoCo's fluid model covers only part of it)",
    "gz-sim-buoyancy-system": "Buoyancy: not run; needs a fluid density and each link's "
    "displaced volume (MuJoCo's `density` option gives it only for a fully submerged world)",
    "gz-sim-thruster-system": "Thruster: not run; needs a propeller thrust ρ·Kt·D⁴·ω|ω| as a "
    "site actuator, like the multicopter rotors",
}


@dataclass(frozen=True)
class DiffDrive:
    """A `libgazebo_ros_diff_drive.so` plugin, typed.

    Attributes:
        name: the plugin's name attribute; where: file and element, for messages.
        left_joints, right_joints: wheel joint names (ROS 2 allows several pairs).
        wheel_separation [m], wheel_diameter [m], max_wheel_torque [N m],
        max_wheel_acceleration [m/s² at the rim; 0 = unlimited, as in the plugin's code],
        odometry_source: "world" or "encoder"; update_rate [Hz] (0 = every step).
    """

    name: str
    where: str
    left_joints: tuple[str, ...]
    right_joints: tuple[str, ...]
    wheel_separation: float = DEFAULT_SEPARATION
    wheel_diameter: float = DEFAULT_DIAMETER
    max_wheel_torque: float = DEFAULT_TORQUE
    max_wheel_acceleration: float = DEFAULT_ACCELERATION
    odometry_source: str = "world"
    update_rate: float = DEFAULT_RATE

    def to_dict(self) -> dict[str, Any]:
        """Plain values for JSON (the server's drive listing)."""
        return {k: list(v) if isinstance(v, tuple) else v for k, v in self.__dict__.items()}


def plugin_kind(blob: Blob) -> str:
    """ "diff_drive", "command_interfaces", "multicopter", a NEEDS key or "not_run", from the
    plugin's filename."""
    filename = (blob.kind or "").rsplit("/", 1)[-1]
    if filename in DIFF_DRIVE_FILES:
        return "diff_drive"
    if filename in CONTROL_FILES:
        return "command_interfaces"
    if is_motor_model(blob):
        return "multicopter"
    system = filename.removeprefix("lib").removesuffix(".so").replace("ignition-gazebo", "gz-sim")
    system = "gz-sim-lift-drag-system" if system == "LiftDragPlugin" else system  # Classic
    return system if system in NEEDS else "not_run"


def read_diff_drive(blob: Blob, source: str) -> DiffDrive:
    """The diff drive's parameters from its verbatim XML.

    Raises:
        GazeboTagError: a number is not a number, no wheel joint is named, or the odometry
            source is neither 0/1 nor encoder/world.
    """
    root = ET.fromstring(blob.xml)
    ctx = (source, blob.name or blob.kind or "plugin")
    left = _all(root, "left_joint", "leftJoint")
    right = _all(root, "right_joint", "rightJoint")
    if not left or not right:
        raise GazeboTagError(*ctx[:1], "", "plugin/left_joint", "", "a wheel joint name")
    return DiffDrive(
        name=blob.name or "diff_drive",
        where=blob.where,
        left_joints=left,
        right_joints=right,
        wheel_separation=_number(
            root, ctx, DEFAULT_SEPARATION, "wheel_separation", "wheelSeparation"
        ),
        wheel_diameter=_number(root, ctx, DEFAULT_DIAMETER, "wheel_diameter", "wheelDiameter"),
        max_wheel_torque=_number(root, ctx, DEFAULT_TORQUE, "max_wheel_torque", "wheelTorque"),
        max_wheel_acceleration=_number(
            root, ctx, DEFAULT_ACCELERATION, "max_wheel_acceleration", "wheelAcceleration"
        ),
        odometry_source=_odometry_source(root, ctx),
        update_rate=_number(root, ctx, DEFAULT_RATE, "update_rate", "updateRate"),
    )


def _all(root: ET.Element, *tags: str) -> tuple[str, ...]:
    return tuple((el.text or "").strip() for tag in tags for el in root.findall(tag))


def _number(root: ET.Element, ctx: tuple[str, str], default: float, *tags: str) -> float:
    for tag in tags:
        el = root.find(tag)
        if el is None:
            continue
        text = (el.text or "").strip()
        try:
            value = float(text)
        except ValueError as exc:
            raise GazeboTagError(ctx[0], "", f"plugin/{tag}", text, "a number") from exc
        if not math.isfinite(value) or value < 0:
            raise GazeboTagError(ctx[0], "", f"plugin/{tag}", text, "a finite number >= 0")
        return value
    return default


def _odometry_source(root: ET.Element, ctx: tuple[str, str]) -> str:
    for tag in ("odometry_source", "odometrySource"):
        el = root.find(tag)
        if el is None:
            continue
        text = (el.text or "").strip().lower()
        named = {"0": "encoder", "1": "world", "encoder": "encoder", "world": "world"}
        if text not in named:
            raise GazeboTagError(ctx[0], "", f"plugin/{tag}", text, "0 (encoder) or 1 (world)")
        return named[text]
    return "world"


def read_plugins(blobs: tuple[Blob, ...], source: str) -> tuple[DiffDrive | Rotor, ...]:
    """Every diff drive and multicopter rotor among a model's plugins."""
    drives = [read_diff_drive(b, source) for b in blobs if plugin_kind(b) == "diff_drive"]
    rotors = [read_rotor(b, source) for b in blobs if plugin_kind(b) == "multicopter"]
    return (*drives, *(r for r in rotors if r is not None))


def add_drive_motors(
    spec: mujoco.MjSpec, plugins: tuple[DiffDrive | Rotor, ...], report: Report
) -> None:
    """Gives each wheel joint of each drive a motor (±max wheel torque) unless it has one, and
    each multicopter rotor its actuators (`converters.gazebo.multicopter.add_rotors`).

    Raises:
        GazeboTagError: a wheel or rotor joint the plugin names is not a joint of the model.
    """
    import mujoco

    add_rotors(spec, tuple(p for p in plugins if isinstance(p, Rotor)), report)
    drives = [p for p in plugins if isinstance(p, DiffDrive)]
    driven = {a.target for a in spec.actuators}
    for drive in drives:
        for joint in drive.left_joints + drive.right_joints:
            if spec.joint(joint) is None:
                model = spec.modelname or "model"
                raise GazeboTagError(model, "", "plugin/*_joint", joint, "a joint of the model")
            if joint in driven:
                continue
            motor = spec.add_actuator(name=joint, target=joint)
            motor.trntype = mujoco.mjtTrn.mjTRN_JOINT
            motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            motor.ctrlrange = np.array([-drive.max_wheel_torque, drive.max_wheel_torque])
            _velocity_only(spec, joint, drive)
            driven.add(joint)


def _velocity_only(spec: mujoco.MjSpec, joint: str, drive: DiffDrive) -> None:
    """The plugin drives its wheels by velocity only (its joints' only command interface)."""
    record = {
        "modes": ["velocity"],
        "source": "diff_drive",
        "where": drive.where,
        "bounds": {},
        "pid": {},
        "velocity_limit": None,
        "plugin": None,
    }
    set_control_record(spec, joint, record)


def report_plugins(blobs: tuple[Blob, ...], report: Report) -> None:
    """Says what happens to each model plugin: run as a twin controller, or not run."""
    reasons = {
        "diff_drive": "run by twin as a diff-drive controller (`twin drive`, `twin odom`)",
        "command_interfaces": "enables the robot's <ros2_control>/<transmission> command "
        "interfaces",
        "multicopter": "rotor thrust, yaw moment, drag and lag as MuJoCo actuators (`twin "
        "command ENTITY ROTOR_JOINT=ω --mode velocity`, ω in rad/s)",
    }
    for blob in blobs:
        kind = plugin_kind(blob)
        label = " ".join(x for x in (blob.name and f"'{blob.name}'", blob.kind) if x)
        if kind == "not_run":
            report.ignored("model", f"<plugin> {label}: not run by twin", tag="plugin")
        elif kind in NEEDS:
            report.ignored("model", f"<plugin> {label}: {NEEDS[kind]}", tag="plugin")
        elif kind == "multicopter" and missing_names(blob):
            report.ignored("model", f"<plugin> {label}: {missing_names(blob)}", tag="plugin")
        else:
            report.mapped("model", f"<plugin> {label}: {reasons[kind]}", tag="plugin")
