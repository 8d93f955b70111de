"""Save and load a world: its snapshot (settings, entities with their requests, full state) as JSON.

The file is JSON (floats written with Python's shortest round-trip repr, so every double comes
back bit for bit), written atomically (temporary file in the same folder, fsync, rename). Load
spawns the same requests in the same order, so the compiled model has the same layout, then
restores the saved snapshot: a loaded world continues exactly as the saved one would have.
"""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import asdict, fields, replace
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from twin_cli.errors import InvalidRequestError, WorldFileError
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world.actuation import JointCommand, Push
from twin_cli.world.engine import World
from twin_cli.world.entities import Entity, EntityState
from twin_cli.world.pose import Pose
from twin_cli.world.snapshot import WorldSnapshot
from twin_cli.world.values import WorldSettings

FORMAT = "twin-world"
VERSION = 1


def save(world: World, path: str | os.PathLike) -> None:
    """Writes `world`'s snapshot to `path` atomically.

    Raises:
        WorldFileError: an entity spawned from an MjSpec cannot be written as MJCF, or the
            folder is not writable.
    """
    snap = world.snapshot()
    document = {
        "format": FORMAT,
        "version": VERSION,
        "name": snap.name,
        "settings": asdict(snap.settings),
        "paused": snap.paused,
        "iterations": snap.iterations,
        "divergences": snap.divergences,
        "entities": [_entity_dict(e, path) for e in snap.entities],
        "commands": [asdict(c) for c in snap.commands],
        "pushes": [asdict(p) for p in snap.pushes],
        "layout": snap.layout,
        "state": snap.state.tolist(),
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
        "pose": entity.pose.to_dict(),
        "xml": entity.xml,
        **entity.request.options(),
        "spawn_state": state,
    }


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


def load(path: str | os.PathLike) -> World:
    """A new, stopped world rebuilt from a file written by `save`.

    Raises:
        WorldFileError: unreadable, not a twin world file, or its sources changed so that the
            model no longer has the saved layout.
    """
    doc = _read(Path(path))
    settings = doc["settings"]
    settings["gravity"] = tuple(settings["gravity"])
    world = World(WorldSettings(**settings), name=doc["name"])
    entities = [_respawn(world, item) for item in doc["entities"]]
    snapshot = WorldSnapshot(
        doc["name"],
        world.settings,
        bool(doc["paused"]),
        int(doc["iterations"]),
        int(doc["divergences"]),
        tuple(entities),
        tuple(JointCommand(**c) for c in doc["commands"]),
        tuple(Push(p["body"], tuple(p["wrench"]), int(p["end_step"])) for p in doc["pushes"]),
        doc["layout"],
        np.array(doc["state"], dtype=float),
    )
    try:
        world.restore(snapshot)
    except InvalidRequestError as exc:
        raise WorldFileError(
            path,
            f"the sources now compile to {world.snapshot().layout}, saved {doc['layout']}",
            "restore the robot files as they were when saved, or spawn afresh",
        ) from exc
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


def _respawn(world: World, item: dict[str, Any]) -> Entity:
    """Spawns a saved entity again; returns its record with the saved spawn state.

    Its saved pose is already on the ground, so it is spawned without on-ground placement;
    its record keeps the request as it was given.
    """
    source: str | mujoco.MjSpec = item["source"]
    if item["xml"] is not None:
        source = mujoco.MjSpec.from_string(item["xml"])
    request = replace(SpawnRequest.from_body(item), source=source, xml=None, base_dir=None)
    world.spawn(replace(request, on_ground=False), name=item["name"], pose=Pose(**item["pose"]))
    spawn_state = EntityState(**{k: np.array(v) for k, v in item["spawn_state"].items()})
    entity = world.entity(item["name"])
    return replace(entity, source=item["source"], request=request, spawn_state=spawn_state)
