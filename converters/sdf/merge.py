"""`<include merge="true">` (SDFormat 1.9): the included model's parts spliced into the parent.

As sdformat does it: no nested scope and no `::` prefix; the included model's frame becomes a
frame `_merged__NAME__model__` attached to its canonical link and posed where the include puts
the model; whatever referred to the included `__model__` (poses, attachments, a joint's parent
or child, an axis's `expressed_in`) refers to that frame. Links, nested models, joints, frames,
grippers and plugins are copied; `<static>`, `<self_collide>` and the like are not.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from converters.sdf.document import INCLUDED_SOURCE, INCLUDED_VERSION, SdfContext, read_pose
from converters.sdf.links import INCLUDED_DIR
from converters.sdf.poses import MODEL_FRAME, SEP, placed_pose

# What a merge copies into the parent (sdformat's list; namespaced custom elements too).
MERGED = ("link", "model", "joint", "frame", "gripper", "plugin")
# Markings (file, directory, version) each copied part keeps from the included model.
MARKS = (INCLUDED_SOURCE, INCLUDED_DIR, INCLUDED_VERSION)


def proxy_name(model_name: str) -> str:
    """The frame that stands for a merged model's frame (sdformat's name for it)."""
    return f"_merged__{model_name}__model__"


def merge_include(ctx: SdfContext, parent: Any, include: Any, model: Any) -> None:
    """Put `model`'s parts where `include` is in `parent` (a `<model>` or `<world>`).

    Raises:
        SDFError: what was included is not a model, the parent is neither a model nor a world,
            a world merges links, or the model has no link to attach its frame to.
    """
    if model.tag != "model" or parent.tag not in ("model", "world"):
        raise ctx.error(
            include,
            f"merge='true' includes a <{model.tag}> into a <{parent.tag}>",
            "merge a model into a model or world, or drop merge='true'",
        )
    proxy = proxy_name(model.get("name", ""))
    parts = [proxy_frame(ctx, parent, include, model, proxy)]
    for child in [c for c in model if isinstance(c.tag, str)]:
        if child.tag not in MERGED and ":" not in child.tag:
            continue
        if parent.tag == "world" and child.tag in ("link", "gripper"):
            raise ctx.error(
                child, "a world cannot merge a model's link", "include the model without merge"
            )
        _to_proxy(ctx, child, proxy)
        for mark in MARKS:
            if model.get(mark) and not child.get(mark):
                child.set(mark, model.get(mark))
        parts.append(child)
    at = list(parent).index(include)
    parent.remove(include)
    for offset, part in enumerate(parts):
        parent.insert(at + offset, part)


def proxy_frame(ctx: SdfContext, parent: Any, include: Any, model: Any, name: str) -> Any:
    """`<frame name=NAME attached_to=CANONICAL><pose relative_to=R>` for the merged model."""
    from lxml import etree

    canonical = canonical_link(model)
    if canonical is None:
        raise ctx.error(include, "the merged model has no link", "give the model a link")
    frame = etree.Element("frame", name=name, attached_to=canonical)
    for mark in MARKS:
        if model.get(mark):
            frame.set(mark, model.get(mark))
    pose = model.find("pose")
    pose = etree.SubElement(frame, "pose") if pose is None else _copy(pose, frame)
    placement = model.get("placement_frame")
    if placement:  # the include's pose places that frame: the model frame is offset from it
        X_R_M = _placed(ctx, model)
        pose.text = " ".join(f"{v:.17g}" for v in _xyz_quat(X_R_M))
        if "degrees" in pose.attrib:
            del pose.attrib["degrees"]
        pose.set("rotation_format", "quat_xyzw")
    if not pose.get("relative_to"):
        pose.set("relative_to", MODEL_FRAME if parent.tag == "model" else "world")
    return frame


def canonical_link(model: Any) -> str | None:
    """The model's canonical link as named from its parent's scope (`nested::link` for one in
    a nested model): `canonical_link`, else the first link, else a nested model's."""
    if model.get("canonical_link"):
        return model.get("canonical_link")
    link = model.find("link")
    if link is not None:
        return link.get("name")
    for nested in model.findall("model"):
        inner = canonical_link(nested)
        if inner is not None:
            return nested.get("name", "") + SEP + inner
    return None


def _to_proxy(ctx: SdfContext, child: Any, proxy: str) -> None:
    """References to the merged model's frame in `child` made references to `proxy`."""
    pose = child.find("pose")
    if child.tag in ("link", "model"):
        if pose is None:
            pose = child.makeelement("pose", {})
            child.insert(0, pose)
        _swap(pose, "relative_to", proxy, empty_too=True)
    elif child.tag == "frame":
        _swap(child, "attached_to", proxy, empty_too=True)
        _swap(pose, "relative_to", proxy)
    elif child.tag == "joint":
        _swap(pose, "relative_to", proxy)
        for role in ("parent", "child"):
            named = child.find(role)
            if named is not None and (named.text or "").strip() == MODEL_FRAME:
                named.text = proxy
        for axis in ("axis", "axis2"):
            _swap(child.find(f"{axis}/xyz"), "expressed_in", proxy)


def _swap(element: Any, attribute: str, proxy: str, empty_too: bool = False) -> None:
    if element is None:
        return
    value = element.get(attribute) or ""
    if value == MODEL_FRAME or (empty_too and not value):
        element.set(attribute, proxy)


def _copy(pose: Any, parent: Any) -> Any:
    from copy import deepcopy

    copied = deepcopy(pose)
    parent.append(copied)
    return copied


def _placed(ctx: SdfContext, model: Any) -> np.ndarray:
    """X_R_M: the model frame in the include pose's frame when that pose places the model's
    `placement_frame`."""
    X_R_P, _ = read_pose(ctx, model)
    return placed_pose(ctx, model, X_R_P)


def _xyz_quat(T: np.ndarray) -> list[float]:
    """x y z qx qy qz qw of a 4×4 transform."""
    import mujoco

    wxyz = np.zeros(4)
    mujoco.mju_mat2Quat(wxyz, np.ascontiguousarray(T[:3, :3]).reshape(-1))
    return [*T[:3, 3].tolist(), *wxyz[1:].tolist(), float(wxyz[0])]
