"""Gazebo paths that ROS packages export in their `package.xml`.

A package writes `<export><gazebo_ros gazebo_model_path="${prefix}/models"
gazebo_media_path="${prefix}"/></export>`; gazebo_ros (ROS 1 and 2) and ros_gz_sim add every
such path, `${prefix}` replaced by the package's directory, to Gazebo's model and resource
paths. twin finds the packages where ROS does: under each `ROS_PACKAGE_PATH` entry (at any
depth, a directory with a `package.xml` ends the descent) and in `<prefix>/share/*` of each
`AMENT_PREFIX_PATH` prefix.
"""

from __future__ import annotations

import os
from pathlib import Path

# The export element and its attributes (gazebo_ros's `gazebo_ros_paths`).
EXPORT_TAG = "gazebo_ros"
MODEL_PATH = "gazebo_model_path"
MEDIA_PATH = "gazebo_media_path"
PREFIX = "${prefix}"
# How deep below a ROS_PACKAGE_PATH entry packages are looked for (a catkin source space
# nests them a few levels: src/stack/package).
MAX_DEPTH = 4


def exported_paths(
    ros_entries: tuple[Path, ...], ament_prefixes: tuple[Path, ...], attribute: str
) -> list[Path]:
    """Every path the packages found on these entries export under `attribute`, in order."""
    out: list[Path] = []
    for package in _packages(ros_entries, ament_prefixes):
        out += [p for p in _exports(package).get(attribute, ()) if p not in out]
    return out


def _packages(ros_entries: tuple[Path, ...], ament_prefixes: tuple[Path, ...]) -> list[Path]:
    found: list[Path] = []
    for entry in ros_entries:
        found += _crawl(entry, MAX_DEPTH)
    for prefix in ament_prefixes:
        share = prefix / "share"
        if share.is_dir():
            found += sorted(d for d in share.iterdir() if (d / "package.xml").is_file())
    return found


def _crawl(directory: Path, depth: int) -> list[Path]:
    """Package directories under `directory` (itself if it is one), sorted by path."""
    if (directory / "package.xml").is_file():
        return [directory]
    if depth == 0 or not directory.is_dir() or (directory / "CATKIN_IGNORE").exists():
        return []
    try:
        children = sorted(d for d in directory.iterdir() if d.is_dir())
    except OSError:
        return []
    return [p for child in children if not child.name.startswith(".") for p in
            _crawl(child, depth - 1)]  # fmt: skip


def _exports(package: Path) -> dict[str, tuple[Path, ...]]:
    """attribute → paths of the `<gazebo_ros>` exports of `package/package.xml`; a manifest that
    is not XML exports nothing (ROS skips it too)."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(package / "package.xml").getroot()
    except (OSError, ET.ParseError):
        return {}
    out: dict[str, list[Path]] = {}
    for export in root.findall(f"export/{EXPORT_TAG}"):
        for attribute in (MODEL_PATH, MEDIA_PATH):
            for raw in (export.get(attribute) or "").split(os.pathsep):
                if raw.strip():
                    path = Path(raw.strip().replace(PREFIX, str(package))).expanduser()
                    out.setdefault(attribute, []).append(path)
    return {k: tuple(v) for k, v in out.items()}
