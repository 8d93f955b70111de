"""The controller manager's parameter file that gazebo_ros2_control and gz_ros2_control load.

Their `<plugin>` names it in `<parameters>` (xacro has usually made it an absolute path; a
relative one starts at the description's folder). It is a ROS 2 parameter file: each node's
`ros__parameters` under its name (or `/name`), the controller manager's listing each controller
with its `type`, and each controller's own parameters under its own name. Parameters may be
nested maps (`linear: {x: {max_velocity: 1.0}}`) or dotted keys (`linear.x.max_velocity`), as
ROS 2 reads both.

The file is read once per conversion through `converters.replay`, so a served conversion's
world builds the same drives without opening it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

from converters.replay import read_once

MANAGER = "controller_manager"


def parameter_files(plugin_xml: str, source: str) -> tuple[Path, ...]:
    """The files a ros2_control plugin's `<parameters>` elements name, relative ones resolved
    against the folder of `source`."""
    try:
        root = ET.fromstring(plugin_xml)
    except ET.ParseError:
        return ()
    base = Path(source).parent
    paths = (Path((e.text or "").strip()) for e in root.findall("parameters"))
    return tuple(p if p.is_absolute() else base / p for p in paths if str(p) not in ("", "."))


def load_parameters(path: Path) -> dict | str:
    """The parameter file's document, or why it cannot be read (a sentence)."""

    def read() -> dict | str:
        import yaml

        try:
            document = yaml.safe_load(path.read_text())
        except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
            return f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
        return document if isinstance(document, dict) else "not a map of node names"

    return read_once("controller_parameters", (str(path),), read)


def node_parameters(document: Any, node: str) -> dict:
    """The `ros__parameters` of `node` in a ROS 2 parameter file (under `node` or `/node`)."""
    if not isinstance(document, dict):
        return {}
    entry = document.get(node) or document.get(f"/{node}")
    params = entry.get("ros__parameters") if isinstance(entry, dict) else None
    return params if isinstance(params, dict) else {}


def controller_types(document: Any) -> dict[str, str]:
    """Each controller the manager lists, with its `type`."""
    manager = node_parameters(document, MANAGER)
    return {
        str(name): str(entry["type"])
        for name, entry in manager.items()
        if isinstance(entry, dict) and "type" in entry
    }


def parameter(params: dict, dotted: str, default: Any = None) -> Any:
    """`params[dotted]`, or the same key as nested maps (`a.b.c` → params[a][b][c])."""
    if dotted in params:
        return params[dotted]
    node: Any = params
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return default
        node = node[part]
    return node
