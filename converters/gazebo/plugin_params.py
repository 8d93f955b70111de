"""A `<plugin>`'s parameters read as Gazebo reads them: by tag, under each accepted spelling.

Gazebo plugins take their parameters as child elements (`<wheel_separation>0.4</...>`), each
plugin with its own names and defaults (gazebo_ros' ROS 1 camelCase and ROS 2 snake_case, gz-sim's
snake_case). `Params` reads one plugin's verbatim XML and raises a GazeboTagError naming the tag
for a value that is not what the plugin needs, so a raw `float('wide')` never reaches the user.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

from converters.description.gazebo import Blob
from converters.errors import GazeboTagError

TRUE_WORDS = {"1": True, "true": True, "0": False, "false": False}


@dataclass(frozen=True)
class Params:
    """One plugin's parameter elements.

    Attributes:
        root: the `<plugin>` element; source: the description file, for messages.
    """

    root: ET.Element
    source: str

    @classmethod
    def of(cls, blob: Blob, source: str) -> Params:
        """The parameters of the plugin kept verbatim in `blob`."""
        return cls(ET.fromstring(blob.xml), source)

    def has(self, *tags: str) -> bool:
        """Whether any of `tags` is given."""
        return any(self.root.find(tag) is not None for tag in tags)

    def names(self, *tags: str) -> tuple[str, ...]:
        """Every text of every element named one of `tags` (repeatable tags such as
        `<left_joint>`), in the order of `tags`."""
        return tuple(
            (el.text or "").strip() for tag in tags for el in self.root.findall(tag) if el.text
        )

    def text(self, default: str, *tags: str) -> str:
        """The first given text of `tags`, else `default`."""
        found = self.names(*tags)
        return found[0] if found else default

    def number(self, default: float, *tags: str, signed: bool = False) -> float:
        """The first given value of `tags` as a finite number (≥ 0 unless `signed`).

        Raises:
            GazeboTagError: the value is not such a number.
        """
        for tag in tags:
            el = self.root.find(tag)
            if el is not None:
                return self._number(tag, (el.text or "").strip(), signed)
        return default

    def _number(self, tag: str, text: str, signed: bool) -> float:
        try:
            value = float(text)
        except ValueError as exc:
            raise GazeboTagError(self.source, "", f"plugin/{tag}", text, "a number") from exc
        if not math.isfinite(value) or (value < 0 and not signed):
            expected = "a finite number" if signed else "a finite number >= 0"
            raise GazeboTagError(self.source, "", f"plugin/{tag}", text, expected)
        return value

    def numbers(self, tag: str, *, signed: bool = False) -> tuple[float, ...]:
        """Every value of a repeatable `tag`, in order (gz-sim's per-joint parameters).

        Raises:
            GazeboTagError: a value is not a finite number (>= 0 unless `signed`).
        """
        return tuple(
            self._number(tag, (el.text or "").strip(), signed) for el in self.root.findall(tag)
        )

    def vector3(self, tag: str) -> tuple[float, float, float]:
        """`tag`'s three numbers (gz-sim's `math::Vector3d`, e.g. "0.3 0 0"), else zeros.

        Raises:
            GazeboTagError: the value is not three finite numbers.
        """
        el = self.root.find(tag)
        if el is None:
            return (0.0, 0.0, 0.0)
        text = (el.text or "").strip()
        try:
            x, y, z = (float(part) for part in text.split())
        except ValueError:  # not three parts, or one is not a number
            x = y = z = math.nan
        if not all(math.isfinite(v) for v in (x, y, z)):
            raise GazeboTagError(self.source, "", f"plugin/{tag}", text, "three numbers")
        return (x, y, z)

    def flag(self, default: bool, *tags: str) -> bool:
        """The first given value of `tags` as a boolean (true/false/1/0).

        Raises:
            GazeboTagError: the value is not a boolean.
        """
        for tag in tags:
            el = self.root.find(tag)
            if el is None:
                continue
            text = (el.text or "").strip().lower()
            if text not in TRUE_WORDS:
                raise GazeboTagError(self.source, "", f"plugin/{tag}", text, "true or false")
            return TRUE_WORDS[text]
        return default

    def odometry_source(self, default: str, *tags: str) -> str:
        """ "world" or "encoder" from 1/0 (ROS 2) or world/encoder (ROS 1).

        Raises:
            GazeboTagError: any other value.
        """
        named = {"0": "encoder", "1": "world", "encoder": "encoder", "world": "world"}
        for tag in tags:
            el = self.root.find(tag)
            if el is None:
                continue
            text = (el.text or "").strip().lower()
            if text not in named:
                raise GazeboTagError(
                    self.source, "", f"plugin/{tag}", text, "0 (encoder) or 1 (world)"
                )
            return named[text]
        return default

    def ros_topic(self, name: str, ros1_topic: str = "", ros1_namespace: str = "") -> str:
        """The topic the plugin's node gives `name`, as rclcpp resolves it: `<ros><remapping>`
        (`name:=NEW` or `~/name:=NEW`) in `<ros><namespace>`; for ROS 1 plugins, the
        `ros1_topic` and `ros1_namespace` tags. Absolute (`/ns/odom`) where a namespace or an
        absolute remapping names it, else relative (the world puts it under the entity's name).
        """
        pairs = ((r.text or "").partition(":=") for r in self.root.findall("ros/remapping"))
        remaps = {a.strip(): b.strip() for a, sep, b in pairs if sep and a.strip() and b.strip()}
        topic = remaps.get(name, remaps.get(f"~/{name}", ""))
        topic = topic or (self.text("", ros1_topic) if ros1_topic else "") or name
        namespace = (self.root.findtext("ros/namespace") or "").strip().strip("/")
        namespace = namespace or (
            self.text("", ros1_namespace).strip("/") if ros1_namespace else ""
        )
        if topic.startswith("/") or not namespace:
            return topic
        return f"/{namespace}/{topic}"

    def given(self) -> dict[str, str]:
        """Every parameter element's tag and text, for reports (`<ros>` blocks shown by tag)."""
        out: dict[str, str] = {}
        for child in self.root:
            text = (child.text or "").strip()
            out[str(child.tag)] = text if len(child) == 0 else "<...>"
        return out


def shown(params: dict[str, str], limit: int = 12) -> str:
    """`tag=value, ...` of a plugin's parameters for one report line."""
    items = [f"{k}={v}" for k, v in params.items()]
    more = f", ... ({len(items) - limit} more)" if len(items) > limit else ""
    return ", ".join(items[:limit]) + more
