"""SDFormat's pose frame semantics for one model: every frame's pose in the model frame.

The rules (SDFormat 1.7+, "pose frame semantics"): a model has an implicit frame `__model__`;
a link's `<pose>` is relative to `__model__`, a joint's to its child link, a `<frame>`'s to the
frame it is `attached_to` (default `__model__`), a nested model's to the parent's `__model__`,
unless `relative_to` names another frame of the same scope. Nested scopes are reached with
`::` (`arm::hand`). Files before 1.7 are read as sdformat reads them, upgraded: the same
defaults, and a `relative_to` they write counts.
Frames are resolved lazily and a cycle is an error naming the frames in it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from converters.description import WORLD_LINK
from converters.sdf.document import SdfContext, read_pose

MODEL_FRAME = "__model__"
SEP = "::"


@dataclass
class FrameNode:
    """One frame of the model scope.

    Attributes:
        kind: link | joint | frame | model.
        element: its XML element (for error lines).
        pose: its `<pose>` (4×4) relative to `relative_to`.
        relative_to: scoped name of the frame the pose is expressed in.
        attached_to: frames: the scoped frame it is fixed to; joints: the child link;
            models: the canonical link (None while the model has no link).
        placement: models (1.8 `placement_frame`): the frame of the model that `pose` places,
            instead of the model frame (a name in the model's own scope).
    """

    kind: str
    element: Any
    pose: np.ndarray
    relative_to: str | None
    attached_to: str | None = None
    placement: str | None = None


class PoseGraph:
    """The frames of a model (nested models flattened with `::`) and their resolved poses."""

    def __init__(self, ctx: SdfContext, model: Any) -> None:
        self.ctx = ctx
        self.nodes: dict[str, FrameNode] = {}
        self._resolved: dict[str, np.ndarray] = {}
        self.nodes[MODEL_FRAME] = FrameNode("model", model, np.eye(4), None)
        self._collect(model, "")

    # ------------------------------------------------------------------ building
    def _collect(self, model: Any, prefix: str) -> None:
        here = prefix + MODEL_FRAME
        for link in model.findall("link"):
            self._add(prefix + link.get("name", ""), "link", link, prefix, here)
        for nested in model.findall("model"):
            name = prefix + nested.get("name", "")
            self._add(name + SEP + MODEL_FRAME, "model", nested, prefix, here)
            self.nodes[name + SEP + MODEL_FRAME].placement = nested.get("placement_frame")
            self._collect(nested, name + SEP)
        for joint in model.findall("joint"):
            child = self.ctx.text(joint, "child") or ""
            self._add(prefix + joint.get("name", ""), "joint", joint, prefix, scoped(child, prefix))
            self.nodes[prefix + joint.get("name", "")].attached_to = scoped(child, prefix)
        for frame in model.findall("frame"):
            attached = scoped(frame.get("attached_to") or MODEL_FRAME, prefix)
            self._add(prefix + frame.get("name", ""), "frame", frame, prefix, attached)
            self.nodes[prefix + frame.get("name", "")].attached_to = attached
        # The model frame is attached to its canonical link: `canonical_link`, else the first
        # link, else (no link of its own) the first nested model's frame (SDFormat 1.8).
        canonical = model.get("canonical_link")
        first, nested = model.find("link"), model.find("model")
        if canonical or first is not None:
            self.nodes[here].attached_to = prefix + (canonical or first.get("name"))
        elif nested is not None:
            self.nodes[here].attached_to = prefix + nested.get("name", "") + SEP + MODEL_FRAME

    def _add(self, name: str, kind: str, element: Any, prefix: str, default: str) -> None:
        if not element.get("name"):
            raise self.ctx.error(element, "has no name", "give it a name attribute")
        if element.get("name") == "world" and kind != "joint":  # the frame joints attach to
            raise self.ctx.error(
                element, f"a {kind} may not be named 'world' (SDFormat reserves it)", "rename it"
            )
        if name in self.nodes:
            raise self.ctx.error(
                element,
                f"the name '{name}' is used twice in this model",
                "links, joints, frames and nested models need unique names",
            )
        pose, relative_to = read_pose(self.ctx, element)
        target = default if relative_to is None else scoped(relative_to, prefix)
        self.nodes[name] = FrameNode(kind, element, pose, target)

    # ----------------------------------------------------------------- resolving
    def canonical(self, name: str) -> str:
        """The scoped name `name` refers to (a nested model's name means its model frame)."""
        if name in self.nodes:
            return name
        if name + SEP + MODEL_FRAME in self.nodes:
            return name + SEP + MODEL_FRAME
        raise KeyError(name)

    def pose(self, name: str, asked_by: Any = None) -> np.ndarray:
        """X_M_name: the frame's pose in the (outermost) model frame, 4×4.

        Raises:
            SDFError: an unknown frame name (listing the known ones) or a cycle.
        """
        return self._pose(name, asked_by, ())

    def _pose(self, name: str, asked_by: Any, chain: tuple[str, ...]) -> np.ndarray:
        key = self._known(name, asked_by)
        if key in self._resolved:
            return self._resolved[key]
        if key in chain:
            loop = " → ".join((*chain[chain.index(key) :], key))
            raise self.ctx.error(
                self.nodes[key].element,
                f"its pose is defined through a cycle of frames ({loop})",
                "make one of them relative_to a frame outside the cycle",
            )
        node = self.nodes[key]
        if node.relative_to is None:
            return np.eye(4)
        base = self._pose(node.relative_to, node.element, (*chain, key))
        pose = node.pose
        if node.kind == "model" and node.placement:
            pose = placed_pose(self.ctx, node.element, pose)
        self._resolved[key] = base @ pose
        return self._resolved[key]

    def _known(self, name: str, asked_by: Any) -> str:
        try:
            return self.canonical(name)
        except KeyError:
            known = sorted(n for n in self.nodes if not n.endswith(MODEL_FRAME)) + [MODEL_FRAME]
            element = asked_by if asked_by is not None else self.nodes[MODEL_FRAME].element
            raise self.ctx.error(
                element,
                f"frame '{name}' does not exist in this model",
                f"name one of: {', '.join(known)}",
            ) from None

    def link_of(self, name: str, asked_by: Any = None) -> str:
        """The link a frame is fixed to (following attached_to, joints to their child links).

        Returns `WORLD_LINK` for the world frame.
        """
        seen: list[str] = []
        key = name
        while True:
            if key == WORLD_LINK:
                return WORLD_LINK
            key = self._known(key, asked_by)
            node = self.nodes[key]
            if node.kind == "link":
                return key
            if key in seen:
                loop = " → ".join([*seen, key])
                raise self.ctx.error(
                    node.element,
                    f"frames are attached to each other in a cycle ({loop})",
                    "attach one of them to a link",
                )
            if node.attached_to is None:
                raise self.ctx.error(
                    node.element,
                    f"frame '{name}' is not attached to any link",
                    "attach it (attached_to) to a link, or give the model a link",
                )
            seen.append(key)
            key = node.attached_to


def placed_pose(ctx: SdfContext, model: Any, pose: np.ndarray) -> np.ndarray:
    """X_R_M: where `model`'s frame is when its `<pose>` (`pose`, in frame R) places the frame
    its `placement_frame` names (SDFormat 1.8): `pose` · X_M_P⁻¹, X_M_P that frame's pose in
    the model, resolved in the model's own scope (its nested placements included). Without a
    `placement_frame` (or naming `__model__`) it is `pose` itself.

    Raises:
        SDFError: the placement frame is not a link, joint, frame or nested model of the model.
    """
    placement = (model.get("placement_frame") or "").strip()
    if not placement or placement == MODEL_FRAME:
        return pose
    X_M_P = PoseGraph(ctx, model).pose(placement, model)
    return pose @ np.linalg.inv(X_M_P)


def scoped(reference: str, prefix: str) -> str:
    """A reference written inside scope `prefix` as a name of the outermost scope."""
    if reference == WORLD_LINK:
        return WORLD_LINK
    return prefix + reference
