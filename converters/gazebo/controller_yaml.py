"""The controller manager's parameter files that gazebo_ros2_control and gz_ros2_control load.

Their `<plugin>` names them in `<parameters>` (xacro has usually made each an absolute path; a
relative one starts at the description's folder, or at the folder a text description was sent
from) and the manager's node in `<controller_manager_name>` (default `controller_manager`).
Each file is a ROS 2 parameter file, and the plugin passes all of them, so a node's parameters
are merged across files, later files winning. A node's parameters sit in `ros__parameters` under
its name, written as ROS reads it: `name`, `/name`, `/ns/name`, nested namespace maps, and
`/**` (every node). Parameters may be nested maps (`linear: {x: {max_velocity: 1.0}}`) or dotted
keys (`linear.x.max_velocity`). A controller's type comes from the manager's listing, or, as in
gz_ros2_control's demos, from the `type` among the controller's own parameters.

Each file is read once per conversion through `converters.isolated.replay`, so a served conversion's
world builds the same drives without opening it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

from converters.isolated.replay import read_once

MANAGER = "controller_manager"
WILDCARD = "**"


def parameter_files(plugin_xml: str, base: Path) -> tuple[Path, ...]:
    """The files a ros2_control plugin's `<parameters>` elements name, relative ones resolved
    against `base` (the description's folder)."""
    try:
        root = ET.fromstring(plugin_xml)
    except ET.ParseError:
        return ()
    paths = (Path((e.text or "").strip()) for e in root.findall("parameters"))
    return tuple(p if p.is_absolute() else base / p for p in paths if str(p) not in ("", "."))


def manager_name(plugin_xml: str) -> str:
    """The controller manager's node name (`<controller_manager_name>`, else the default)."""
    try:
        root = ET.fromstring(plugin_xml)
    except ET.ParseError:
        return MANAGER
    return (root.findtext("controller_manager_name") or "").strip().strip("/") or MANAGER


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


def merged_nodes(documents: list[dict]) -> dict[str, dict]:
    """Every node's `ros__parameters` across `documents`, by the node's own name (its last path
    segment; `**` for the wildcard), later documents overriding earlier ones."""
    nodes: dict[str, dict] = {}
    for document in documents:
        for name, params in _nodes(document):
            nodes[name] = _merge(nodes.get(name, {}), params)
    return nodes


def node_parameters(nodes: dict[str, dict], node: str) -> dict:
    """`node`'s parameters: the wildcard's, overridden by its own."""
    return _merge(nodes.get(WILDCARD, {}), nodes.get(node, {}))


def controller_types(nodes: dict[str, dict], manager: str = MANAGER) -> dict[str, str]:
    """Each controller with its type: the manager's listing, and any node whose own parameters
    name a controller type (`package/Class`)."""
    listed = {
        str(name): str(entry["type"])
        for name, entry in node_parameters(nodes, manager).items()
        if isinstance(entry, dict) and isinstance(entry.get("type"), str)
    }
    own = {
        name: params["type"]
        for name, params in nodes.items()
        if name not in (manager, WILDCARD)
        and isinstance(params.get("type"), str)
        and "/" in params["type"]
    }
    return {**own, **listed}


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


def _nodes(document: Any, prefix: str = "") -> list[tuple[str, dict]]:
    """(node name, parameters) for each `ros__parameters` in `document`, at any namespace depth."""
    out: list[tuple[str, dict]] = []
    if not isinstance(document, dict):
        return out
    for key, value in document.items():
        if not isinstance(value, dict):
            continue
        path = f"{prefix}/{str(key).strip('/')}"
        params = value.get("ros__parameters")
        if isinstance(params, dict):
            out.append((path.rstrip("/").rsplit("/", 1)[-1] or WILDCARD, params))
        out += _nodes({k: v for k, v in value.items() if k != "ros__parameters"}, path)
    return out


def _merge(base: dict, over: dict) -> dict:
    """`base` with `over` laid on it, maps merged key by key."""
    out = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out
