"""The names a robot's ros2_control parameter files give its ROS inputs: the controllers of the
YAML files gazebo_ros2_control (or gz_ros2_control) loads. (A gazebo_ros drive plugin's own
`cmd_vel` name is read by the converter into its drive record: `cmd_vel_topic`.)

- gazebo_ros2_control's `<parameters>` names the controller manager's YAML file: each controller
  under `controller_manager: ros__parameters:` with a `type`, and its own `ros__parameters`
  (`joints`, `interface_name` or the type's interface). Forward command controllers and the
  joint group position, velocity and effort controllers take `<ns>/<controller>/commands`; a
  joint_trajectory_controller takes `<ns>/<controller>/joint_trajectory`; a
  diff_drive_controller takes one cmd_vel topic of one type, as the controller subscribes:
  `<ns>/<controller>/cmd_vel` (geometry_msgs/TwistStamped: Jazzy's only input, and Humble's
  default, `use_stamped_vel: true`), or with `use_stamped_vel: false` (a Humble parameter;
  Jazzy has none) `<ns>/<controller>/cmd_vel_unstamped` (geometry_msgs/Twist). `<ns>` is the
  plugin's `<ros><namespace>`, else the entity's name.

Only URDF descriptions carry these (`Entity.description`); a YAML file that cannot be read is
logged once and the entity keeps twin's default controller names.
"""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from converters.description import is_control_plugin
from converters.gazebo.controller_drives import DIFF_DRIVE_TYPE
from converters.gazebo.controller_yaml import (
    controller_types,
    load_parameters,
    manager_name,
    merged_nodes,
    node_parameters,
    parameter_files,
)
from twin_cli.ros.graph import TWIST, TWIST_STAMPED

log = logging.getLogger("twin.ros")
TRAJECTORY = "trajectory"  # a controller's mode: joint_trajectory_controller's topic
DRIVE = "drive"  # a controller's mode: diff_drive_controller's cmd_vel
CONTROLLER_MODES = {  # controller type → the command interface it writes
    "position_controllers/JointGroupPositionController": "position",
    "velocity_controllers/JointGroupVelocityController": "velocity",
    "effort_controllers/JointGroupEffortController": "effort",
    "joint_trajectory_controller/JointTrajectoryController": TRAJECTORY,
}
FORWARD = "forward_command_controller/ForwardCommandController"  # mode: its interface_name


@dataclass(frozen=True)
class Controller:
    """A controller the YAML names: its command topic, mode and joints (in the YAML's order)."""

    topic: str
    mode: str
    joints: tuple[str, ...]
    message: str = ""  # a drive's cmd_vel message type


@dataclass(frozen=True)
class PluginNames:
    """What an entity's description names: a diff_drive_controller's cmd_vel topics with their
    message types (empty: none) and its controllers (empty: twin's default controller names)."""

    cmd_vel: tuple[tuple[str, str], ...] = ()
    controllers: tuple[Controller, ...] = ()


@lru_cache(maxsize=64)
def plugin_names(entity: str, description: str | None, base: str = "") -> PluginNames:
    """The names `description` (an entity's URDF text) gives its inputs (cached: the listener
    asks every half second). A relative `<parameters>` path starts at `base`, the folder the
    converter read the description from."""
    if not description:
        return PluginNames()
    try:
        root = ET.fromstring(description)
    except ET.ParseError:
        return PluginNames()
    controllers: tuple[Controller, ...] = ()
    for plugin in root.iter("plugin"):
        if is_control_plugin(plugin.get("filename", "")):
            controllers = _controllers(plugin, entity, base)
            break
    drive_topics = tuple((c.topic, c.message) for c in controllers if c.mode == DRIVE)
    named = tuple(c for c in controllers if c.mode != DRIVE)
    return PluginNames(drive_topics, named)


def _namespace(plugin: ET.Element, entity: str) -> str:
    return (plugin.findtext("ros/namespace") or "").strip().strip("/") or entity


def _controllers(plugin: ET.Element, entity: str, base: str) -> tuple[Controller, ...]:
    xml = ET.tostring(plugin, encoding="unicode")
    documents = []
    for path in parameter_files(xml, Path(base)):
        document = load_parameters(path)
        if isinstance(document, str):
            log.warning("[%s] %s not read (%s): default controller names", entity, path, document)
            continue
        documents.append(document)
    nodes = merged_nodes(documents)
    return tuple(_from_yaml(nodes, manager_name(xml), _namespace(plugin, entity)))


def _drive_topic(name: str, namespace: str, params: dict) -> Controller:
    """A diff_drive_controller's input: `~/cmd_vel` (TwistStamped), or with Humble's
    `use_stamped_vel: false` `~/cmd_vel_unstamped` (Twist)."""
    if params.get("use_stamped_vel") is False:
        return Controller(f"/{namespace}/{name}/cmd_vel_unstamped", DRIVE, (), TWIST)
    return Controller(f"/{namespace}/{name}/cmd_vel", DRIVE, (), TWIST_STAMPED)


def _from_yaml(nodes: dict[str, dict], manager: str, namespace: str) -> list[Controller]:
    """The command-taking controllers the controller manager's parameter files declare."""
    out = []
    for name, kind in controller_types(nodes, manager).items():
        params = node_parameters(nodes, name)
        if kind == DIFF_DRIVE_TYPE:
            out.append(_drive_topic(name, namespace, params))
            continue
        mode = params.get("interface_name") if kind == FORWARD else CONTROLLER_MODES.get(kind)
        joints = tuple(str(j) for j in params.get("joints") or ())
        if mode is None or not joints:
            continue
        leaf = "joint_trajectory" if mode == TRAJECTORY else "commands"
        out.append(Controller(f"/{namespace}/{name}/{leaf}", str(mode), joints))
    return out
