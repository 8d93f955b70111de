"""Name clashes between a model's links, joints, frames and nested models, and between a world's
frames and models, as sdformat settles them: before SDFormat 1.7 names had to be unique per
element type only, so sdformat renames the later of two clashing elements of a model (`arm` →
`arm_joint`), and a world frame that has a model's name (`ground` → `ground_frame`), and warns;
from 1.7 a clash is an error (`poses.PoseGraph`, `world_frames.WorldFrames` refuse it)."""

from __future__ import annotations

from typing import Any

from converters.sdf.document import SdfContext

# Elements whose names share the model's frame namespace; the suffix sdformat adds to each.
SUFFIXES = {"link": "_link", "joint": "_joint", "frame": "_frame"}


def rename_clashes(ctx: SdfContext, model: Any) -> None:
    """Rename, in `model` and its nested models of 1.4-1.6 files, each link, joint or frame
    whose name an earlier element of another type already took (or an earlier renaming gave),
    as sdformat does. Two elements of one type and name stay a duplicate, which is an error."""
    if ctx.before_frames(model):
        _rename_children(ctx, model)
    for nested in model.findall("model"):
        rename_clashes(ctx, nested)


def _rename_children(ctx: SdfContext, model: Any) -> None:
    taken: set[str] = set()  # names given so far, renamed ones included
    written: dict[str, set[str]] = {tag: set() for tag in (*SUFFIXES, "model")}  # as written
    for child in [c for c in model if isinstance(c.tag, str) and c.tag in written]:
        name = child.get("name")
        if not name or name in written[child.tag]:
            continue  # a nameless or same-type duplicate: the pose graph refuses it
        written[child.tag].add(name)
        if name in taken and child.tag in SUFFIXES:
            child.set("name", _free(name, SUFFIXES[child.tag], taken))
            ctx.report.mapped(
                f"{child.tag} '{name}'",
                f"renamed '{child.get('name')}': another element of the model has its name "
                f"(allowed before SDFormat 1.7, renamed by sdformat)",
            )
        taken.add(child.get("name"))


def rename_world_clashes(ctx: SdfContext, world: Any) -> None:
    """Rename, in a 1.4-1.6 world, each `<frame>` whose name a model (or an earlier frame)
    already has, as sdformat does: frames are checked after every model, in file order."""
    if not ctx.before_frames(world):
        return
    taken = {m.get("name") for m in world.findall("model")}
    for frame in world.findall("frame"):
        name = frame.get("name") or ""
        if name in taken:
            frame.set("name", _free(name, SUFFIXES["frame"], taken))
            ctx.report.mapped(
                f"world frame '{name}'",
                f"renamed '{frame.get('name')}': a model of the world has its name "
                f"(allowed before SDFormat 1.7, renamed by sdformat)",
            )
        taken.add(frame.get("name"))


def _free(name: str, suffix: str, taken: set[str]) -> str:
    """sdformat's choice: NAME_SUFFIX, else NAME_SUFFIX0, NAME_SUFFIX1, …"""
    candidate, index = name + suffix, 0
    while candidate in taken:
        candidate = f"{name}{suffix}{index}"
        index += 1
    return candidate
