"""A world's frames (SDFormat 1.7+): its `<frame>`s and its models' frames, posed in the world.

A world `<frame>`'s pose is relative to the frame it is `attached_to` (default `world`) unless
`relative_to` names another; a model's pose is relative to `world` unless `relative_to` names a
world frame or another model, and places the frame its `placement_frame` names (1.8), which
moves the model frame accordingly. Frames are resolved lazily; a cycle is an error naming its
frames.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from converters.sdf.document import SdfContext, read_pose
from converters.sdf.poses import placed_pose

WORLD_FRAME = "world"


@dataclass(frozen=True)
class WorldFrame:
    """One named frame of the world: its element, `<pose>` (4×4) and the frame that pose is in."""

    element: Any
    pose: np.ndarray
    relative_to: str


class WorldFrames:
    """The world-level frames of one `<world>` and their poses in the world frame."""

    def __init__(self, ctx: SdfContext, world: Any) -> None:
        self.ctx = ctx
        self.frames: dict[str, WorldFrame] = {}
        for frame in world.findall("frame"):
            self._add(frame, frame.get("attached_to") or WORLD_FRAME)
        for model in world.findall("model"):
            self._add(model, WORLD_FRAME)
        self._resolved: dict[str, np.ndarray] = {WORLD_FRAME: np.eye(4)}

    def _add(self, element: Any, default: str) -> None:
        name = element.get("name", "")
        if name in self.frames or name == WORLD_FRAME:
            raise self.ctx.error(
                element,
                f"the name '{name}' is taken in this world",
                "give world frames and models unique names other than 'world'",
            )
        pose, relative_to = read_pose(self.ctx, element)
        if element.tag == "model":  # its pose may place a frame of it, not its model frame
            pose = placed_pose(self.ctx, element, pose)
        self.frames[name] = WorldFrame(element, pose, relative_to or default)

    def pose(self, name: str) -> np.ndarray:
        """X_W_name: the pose of world frame or model `name` in the world frame.

        Raises:
            SDFError: a pose relative to a frame the world does not have, or a cycle.
        """
        return self._pose(name, ())

    def _pose(self, name: str, chain: tuple[str, ...]) -> np.ndarray:
        if name in self._resolved:
            return self._resolved[name]
        node = self.frames[name]
        if name in chain:
            loop = " → ".join((*chain[chain.index(name) :], name))
            raise self.ctx.error(
                node.element,
                f"its pose is defined through a cycle of frames ({loop})",
                "make one of them relative_to the world",
            )
        base = node.relative_to
        if base not in self.frames and base != WORLD_FRAME:
            known = ", ".join([WORLD_FRAME, *sorted(self.frames)])
            pose = node.element.find("pose")
            raise self.ctx.error(
                node.element if pose is None else pose,
                f"frame '{base}' does not exist at world level",
                f"name one of: {known}",
            )
        self._resolved[name] = self._pose(base, (*chain, name)) @ node.pose
        return self._resolved[name]
