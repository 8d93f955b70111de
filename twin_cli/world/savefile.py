"""Save and load a world: settings, entities with their sources, and the full integration state.

The file is JSON (floats written with Python's shortest round-trip repr, so every double comes
back bit for bit), written atomically (temporary file in the same folder, fsync, rename). Load
spawns the same sources in the same order, so the compiled model has the same layout, then
writes the saved `mj_getState(mjSTATE_INTEGRATION)` vector: a loaded world continues exactly as
the saved one would have.
"""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import asdict, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from twin_cli.errors import WorldFileError
from twin_cli.world.actuation import JointCommand, Push
from twin_cli.world.entities import Entity, EntityState
from twin_cli.world.pose import Pose

if TYPE_CHECKING:
    from twin_cli.world.engine import World

FORMAT = "twin-world"
VERSION = 1
_STATE = mujoco.mjtState.mjSTATE_INTEGRATION


def save(world: World, path: str | os.PathLike) -> None:
    """Writes `world` to `path` atomically; the caller holds the world's lock.

    Raises:
        WorldFileError: an entity spawned from an MjSpec cannot be written as MJCF, or the
            folder is not writable.
    """
    document = {
        "format": FORMAT,
        "version": VERSION,
        "name": world.name,
        "settings": asdict(world.settings),
        "paused": world.paused,
        "iterations": world._iterations,
        "divergences": world.divergences,
        "entities": [_entity_dict(e, path) for e in world._entities.values()],
        "commands": [asdict(c) for c in world._commands.values()],
        "pushes": [asdict(p) for p in world._pushes],
        "layout": _layout(world.model),
        "state": _state(world.model, world.data).tolist(),
    }
    _write_atomically(Path(path), json.dumps(document))


def _entity_dict(entity: Entity, path: str | os.PathLike) -> dict[str, Any]:
    if entity.source == "<MjSpec>" and entity.xml is None:
        raise WorldFileError(
            path,
            f"entity [{entity.name}] came from an MjSpec that cannot be written as MJCF",
            "spawn it from a file to be able to save the world",
        )
    state = {f.name: getattr(entity.spawn_state, f.name).tolist() for f in fields(EntityState)}
    return {
        "name": entity.name,
        "source": entity.source,
        "args": entity.args,
        "package_paths": entity.package_paths,
        "pose": entity.pose.to_dict(),
        "on_ground": entity.on_ground,
        "xml": entity.xml,
        "joints": entity.joints,
        "env": entity.env,
        "repair_inertia": entity.repair_inertia,
        "spawn_state": state,
    }


def _layout(model: mujoco.MjModel) -> dict[str, int]:
    return {k: int(getattr(model, k)) for k in ("nq", "nv", "na", "nu", "nbody", "neq", "nmocap")}


def _state(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    state = np.empty(mujoco.mj_stateSize(model, _STATE))
    mujoco.mj_getState(model, data, state, _STATE)
    return state


def _write_atomically(path: Path, text: str) -> None:
    try:
        with tempfile.NamedTemporaryFile(
            "w", dir=path.parent, prefix=f".{path.name}.", delete=False, encoding="utf-8"
        ) as tmp:
            tmp.write(text)
            tmp.flush()
            os.fsync(tmp.fileno())
        os.replace(tmp.name, path)
    except OSError as exc:
        raise WorldFileError(
            path, f"cannot write ({exc.strerror})", "choose a writable folder"
        ) from exc


def load(cls: type[World], path: str | os.PathLike) -> World:
    """A new, stopped world rebuilt from a file written by `save`.

    Raises:
        WorldFileError: unreadable, not a twin world file, or its sources changed so that the
            model no longer has the saved layout.
    """
    doc = _read(Path(path))
    from twin_cli.world.values import WorldSettings

    settings = doc["settings"]
    settings["gravity"] = tuple(settings["gravity"])
    world = cls(WorldSettings(**settings), name=doc["name"])
    for item in doc["entities"]:
        _respawn(world, item)
    if _layout(world.model) != doc["layout"]:
        raise WorldFileError(
            path,
            f"the sources now compile to {_layout(world.model)}, saved {doc['layout']}",
            "restore the robot files as they were when saved, or spawn afresh",
        )
    _restore_runtime(world, doc)
    return world


def _read(path: Path) -> dict[str, Any]:
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise WorldFileError(path, f"cannot read ({exc.strerror})", "check the path") from exc
    except json.JSONDecodeError as exc:
        raise WorldFileError(
            path, f"not JSON ({exc.msg}, line {exc.lineno})", "give a file written by `twin save`"
        ) from exc
    if not isinstance(doc, dict) or doc.get("format") != FORMAT or doc.get("version") != VERSION:
        raise WorldFileError(
            path, "not a twin world file (version 1)", "give a file written by `twin save`"
        )
    return doc


def _respawn(world: World, item: dict[str, Any]) -> None:
    source: Any = item["source"]
    if item["xml"] is not None:
        source = mujoco.MjSpec.from_string(item["xml"])
    world.spawn(
        source,
        name=item["name"],
        pose=Pose(**item["pose"]),
        args=item["args"] or None,
        package_paths=item["package_paths"] or None,
        joints=item.get("joints") or None,  # absent in files saved before -J existed
        env=item.get("env"),  # these two: absent in files saved before spawn sent them
        repair_inertia=bool(item.get("repair_inertia", False)),
    )
    spawn_state = EntityState(**{k: np.array(v) for k, v in item["spawn_state"].items()})
    entity = world._entities[item["name"]]
    world._entities[item["name"]] = Entity(
        entity.name,
        item["source"],
        entity.args,
        entity.package_paths,
        entity.pose,
        item["on_ground"],
        _typed_like(entity.spawn_state, spawn_state),
        entity.report,
        entity.xml,
        entity.joints,
        entity.description,
        sensors=entity.sensors,
        plugins=entity.plugins,
        env=entity.env,
        repair_inertia=entity.repair_inertia,
    )


def _typed_like(reference: EntityState, loaded: EntityState) -> EntityState:
    """`loaded` with each array's dtype and shape taken from `reference`."""
    return EntityState(
        **{
            f.name: np.asarray(
                getattr(loaded, f.name), dtype=getattr(reference, f.name).dtype
            ).reshape(getattr(reference, f.name).shape)
            for f in fields(EntityState)
        }
    )


def _restore_runtime(world: World, doc: dict[str, Any]) -> None:
    with world.lock:
        mujoco.mj_setState(world.model, world.data, np.array(doc["state"]), _STATE)
        world._iterations = int(doc["iterations"])
        world.divergences = int(doc["divergences"])
        world._paused = bool(doc["paused"])
        world._commands = {c["actuator"]: JointCommand(**c) for c in doc["commands"]}
        world._reapply_commands(world.model, world.data)
        world._pushes = [
            Push(p["body"], tuple(p["wrench"]), int(p["end_step"])) for p in doc["pushes"]
        ]
