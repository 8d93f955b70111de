"""Gazebo model plugins: every plugin classified, the drives and rotors read into typed records.

twin runs the common mobile-base drives as controllers of its own (`twin_cli.control`): the
converter reads their parameters (`converters.gazebo.drive_readers`, one reader per plugin, with
the plugin's own defaults; vendor diff drives by `converters.gazebo.vendor_drive`) and gives their
joints motors (`converters.gazebo.drive_motors`). `gazebo_ros2_control` / `gazebo_ros_control`
plugins enable the robot's command interfaces (mapped elsewhere); gz-sim's MulticopterMotorModel
becomes actuators per rotor (`converters.gazebo.multicopter`); LiftDrag and the underwater systems
are reported with what they would need; every other plugin is reported by name, with its
parameters, as not run.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from converters.description import CONTROL_PLUGINS
from converters.description.gazebo import Blob
from converters.gazebo.controller_drives import read_controller_drives
from converters.gazebo.controller_yaml import load_parameters, parameter_files
from converters.gazebo.drive_motors import add_drive_motors
from converters.gazebo.drive_notes import drive_notes
from converters.gazebo.drive_readers import READERS, ReadContext, plugin_key
from converters.gazebo.drive_records import DiffDrive, DriveRecord
from converters.gazebo.multicopter import Rotor, is_motor_model, missing_names, read_rotor
from converters.gazebo.plugin_params import Params, shown
from converters.gazebo.vendor_drive import is_vendor_diff_drive, read_vendor_diff_drive
from converters.gazebo.wheel_geometry import WheelGeometry
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

__all__ = [
    "CONTROL_FILES",
    "DIFF_DRIVE_FILES",
    "NEEDS",
    "DiffDrive",
    "add_drive_motors",
    "plugin_kind",
    "read_plugins",
    "report_plugins",
]

DIFF_DRIVE_FILES = ("libgazebo_ros_diff_drive.so", "gazebo_ros_diff_drive")
CONTROL_FILES = CONTROL_PLUGINS  # gazebo_ros(2)_control, gz_ros2_control and its ign_ names
# gz-sim system names (the `name` attribute) that identify a drive whatever its filename says.
SYSTEM_NAMES = {
    "DiffDrive": "gz-sim-diff-drive-system",
    "AckermannSteering": "gz-sim-ackermann-steering-system",
    "MecanumDrive": "gz-sim-mecanum-drive-system",
    "VelocityControl": "gz-sim-velocity-control-system",
    "JointController": "gz-sim-joint-controller-system",
    "JointPositionController": "gz-sim-joint-position-controller-system",
    "JointTrajectoryController": "gz-sim-joint-trajectory-controller-system",
    "ApplyJointForce": "gz-sim-apply-joint-force-system",
}
TRAJECTORY_KEY = "gz-sim-joint-trajectory-controller-system"
JOINT_DRIVE_MODES = {  # the mode a joint system's report names (JointController's: velocity)
    "gz-sim-joint-position-controller-system": "position",
    "gz-sim-apply-joint-force-system": "effort",
}
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
    "gz-sim-tracked-vehicle-system": "TrackedVehicle: not run; needs each track's belt speed "
    "from the body twist and steering_efficiency, moved as its geoms' contact surface "
    "(MuJoCo's geom surfacevel), and turns that skid, which MuJoCo's sliding contacts do not "
    "reproduce (they lift a skid-steered base)",
}
RUN = {
    "command_interfaces": "enables the robot's <ros2_control>/<transmission> command interfaces",
    "multicopter": "rotor thrust, yaw moment, drag and lag as MuJoCo actuators (`twin "
    "command ENTITY ROTOR_JOINT=ω --mode velocity`, ω in rad/s)",
    "drive": "run by twin as a drive controller in sim time (`twin drive`, `twin odom`)",
    "joint_drive": "run by twin: its joints take `twin command ENTITY JOINT=VALUE --mode {mode}`",
    "trajectory_drive": "run by twin: its joints follow `twin trajectory ENTITY FILE` with the "
    "plugin's gains",
    "vendor_drive": "read as a differential drive (`twin drive`, `twin odom`): its tags "
    "approximated one by one below",
}


def drive_key(blob: Blob) -> str | None:
    """The `READERS` key of a drive plugin (by filename, else by gz-sim system name)."""
    key = plugin_key(blob)
    if key in READERS:
        return key
    system = (blob.name or "").rsplit("::", 1)[-1]
    return SYSTEM_NAMES.get(system) if "::" in (blob.name or "") else None


def plugin_kind(blob: Blob) -> str:
    """ "drive", "joint_drive", "trajectory_drive", "vendor_drive", "command_interfaces",
    "multicopter", a NEEDS key or "not_run"."""
    filename = (blob.kind or "").rsplit("/", 1)[-1]
    if filename in CONTROL_FILES:
        return "command_interfaces"
    if is_motor_model(blob):
        return "multicopter"
    key = drive_key(blob)
    if key == TRAJECTORY_KEY:
        return "trajectory_drive"
    if key is not None:
        return "joint_drive" if "joint" in key else "drive"
    system = plugin_key(blob)
    system = "gz-sim-lift-drag-system" if system == "LiftDragPlugin" else system  # Classic
    if system in NEEDS:
        return system
    if blob.xml and is_vendor_diff_drive(Params.of(blob, "")):
        return "vendor_drive"
    return "not_run"


def read_plugins(
    blobs: tuple[Blob, ...],
    source: str,
    spec: mujoco.MjSpec | None = None,
    model: str = "",
    base_link: str = "base_link",
    report: Report | None = None,
    base: Path | None = None,
) -> tuple[DriveRecord | Rotor, ...]:
    """Every drive, joint controller and multicopter rotor among a model's plugins, and the
    diff_drive_controllers of a ros2_control plugin's parameter file
    (`converters.gazebo.controller_drives`).

    Args:
        blobs: the model's `<plugin>` elements; source: the file, for messages; spec: the
            robot (gazebo_ros' Ackermann and tricycle plugins measure their wheels on it);
            model, base_link: the model's name and canonical link (gz-sim's default odometry
            frames are `<model>/odom` and `<model>/<link>`); report: where a parameter file
            that cannot be read is said; base: where relative parameter file paths start
            (default: the folder of `source`).

    Raises:
        GazeboTagError: a parameter is not what its plugin needs. PluginJointError: a joint
            the plugin names is not the model's.
    """
    geometry = WheelGeometry(spec, source) if spec is not None else None
    ctx = ReadContext(source, model or "model", geometry, base_link)
    out: list[DriveRecord | Rotor] = []
    for blob in blobs:
        kind = plugin_kind(blob)
        if kind in ("drive", "joint_drive", "trajectory_drive"):
            key = drive_key(blob) or ""
            params = Params.of(blob, source)
            if geometry is not None:
                geometry.plugin = blob.name or key
            record = READERS[key](params, blob, ctx)
            if key.startswith("gazebo_ros") and hasattr(record, "cmd_vel_topic"):
                topic = params.ros_topic("cmd_vel", "commandTopic", "robotNamespace")
                record = replace(record, cmd_vel_topic=topic)  # SDF models carry it too
            notes = drive_notes(key, params, getattr(record, "initial", 0.0))
            out.append(replace(record, notes=record.notes + notes))
        elif kind == "vendor_drive":
            out.append(read_vendor_diff_drive(Params.of(blob, source), blob))
        elif kind == "command_interfaces":
            joints = {j.name for j in spec.joints} if spec is not None else None
            folder = base if base is not None else Path(source).parent
            drives, problems = read_controller_drives(blob, source, folder, joints)
            out += drives
            for problem in problems:
                if report is not None:
                    report.warn("model", f"<plugin> '{blob.name}' <parameters>: {problem}")
        elif kind == "multicopter":
            rotor = read_rotor(blob, source)
            if rotor is not None:
                out.append(rotor)
    return tuple(out)


def read_plugin_files(blobs: tuple[Blob, ...], source: str, base: Path | None = None) -> None:
    """Read the files `read_plugins` reads (a ros2_control plugin's parameter files), for a
    served conversion's reading stage; `source` and `base` as for `read_plugins`."""
    folder = base if base is not None else Path(source).parent
    for blob in blobs:
        if plugin_kind(blob) == "command_interfaces":
            for path in parameter_files(blob.xml, folder):
                load_parameters(path)


def report_plugins(blobs: tuple[Blob, ...], report: Report) -> None:
    """Says what happens to each model plugin: run as a twin controller, or not run (with its
    parameters, so a user sees what twin left out)."""
    for blob in blobs:
        kind = plugin_kind(blob)
        label = " ".join(x for x in (blob.name and f"'{blob.name}'", blob.kind) if x)
        if kind == "not_run":
            report.ignored(
                "model", f"<plugin> {label}: not run by twin{_given(blob)}", tag="plugin"
            )
        elif kind in NEEDS:
            report.ignored("model", f"<plugin> {label}: {NEEDS[kind]}{_given(blob)}", tag="plugin")
        elif kind == "multicopter" and missing_names(blob):
            report.ignored("model", f"<plugin> {label}: {missing_names(blob)}", tag="plugin")
        elif kind == "vendor_drive":
            report.approximated("model", f"<plugin> {label}: {RUN[kind]}", tag="plugin")
        else:
            mode = JOINT_DRIVE_MODES.get(drive_key(blob) or "", "velocity")
            report.mapped("model", f"<plugin> {label}: {RUN[kind].format(mode=mode)}", tag="plugin")


def _given(blob: Blob) -> str:
    """`; parameters: tag=value, ...` of a plugin twin does not run (empty without any)."""
    params = Params.of(blob, "").given() if blob.xml else {}
    return f"; parameters: {shown(params)}" if params else ""
