"""Save and load a world: its snapshot (settings, entities with their requests, full state) as JSON.

The file is JSON (floats written with Python's shortest round-trip repr, so every double comes
back bit for bit), written atomically (temporary file in the same folder, fsync, rename). Load
spawns the same requests in the same order, so the compiled model has the same layout, then
restores the saved snapshot: a loaded world continues exactly as the saved one would have.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import asdict, fields, replace
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from converters.errors import ConversionError
from twin_cli.errors import EntityNotFoundError, InvalidRequestError, TwinError, WorldFileError
from twin_cli.files import input_files
from twin_cli.files.output_files import OutputFileError, write_atomically
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import save_upgrades
from twin_cli.world.actuation import JointCommand, Push
from twin_cli.world.decomposing import PENDING
from twin_cli.world.engine import World
from twin_cli.world.entities import Entity, EntityState
from twin_cli.world.pose import Pose
from twin_cli.world.save_schema import OBSOLETE_COMMAND_FIELDS, SaveDocument, checked_document
from twin_cli.world.snapshot import WorldSnapshot
from twin_cli.world.values import WorldSettings

FORMAT = "twin-world"
VERSION = 1
SAVED_BY_TWIN = "give a file written by `twin save`"
DECOMPOSITION_POLL_S = 0.1  # [s] how often a save looks whether a decomposition it waits for ended
# [s] longest a save waits for those decompositions before it writes the hulls that stand in
# (a bin of 3 CPU s of CoACD took 3-9 s on 2 busy cores; a load then decomposes nothing again)
SAVE_WAIT_S = 60.0


def save(
    world: World, path: str | os.PathLike, *, force: bool = False, wait_s: float = SAVE_WAIT_S
) -> None:
    """Writes `world`'s snapshot to `path` atomically; an existing file that is not a twin save
    is replaced only with `force`. Waits up to `wait_s` [s] for the background decompositions
    of entities saved as MJCF (`_await_decompositions`); an autosave, which runs again, waits 0.

    Raises:
        WorldFileError: an entity spawned from an MjSpec cannot be written as MJCF, the folder
            is not writable, or the file is someone else's.
    """
    _await_decompositions(world, wait_s)
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
    _write_atomically(Path(path), json.dumps(document), force)


def _await_decompositions(world: World, wait_s: float) -> None:
    """Waits up to `wait_s` for the background decompositions of entities saved as MJCF (a
    description given as text, a world file's model): a load spawns that MJCF as it is, so a
    convex hull standing in when it was written would stay. An entity spawned from a file needs
    no wait, as a load converts its file again. Each job ends by itself (swapped in, failed with
    the hull kept, cancelled by a delete or a stop); past `wait_s` the hulls are written."""
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline and _waiting(world):
        time.sleep(DECOMPOSITION_POLL_S)


def _waiting(world: World) -> bool:
    """Whether an entity saved as MJCF still waits for its decomposition (one deleted
    meanwhile does not)."""
    for info in world.entities():
        if info.decomposition != PENDING:
            continue
        try:
            if world.entity(info.name).xml is not None:
                return True
        except EntityNotFoundError:
            continue
    return False


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


def is_save(head: bytes) -> bool:
    """Whether a file's first bytes are those of a twin save (`json.dumps` writes "format"
    first)."""
    return head.startswith(b'{"format": "' + FORMAT.encode() + b'"')


def _write_atomically(path: Path, text: str, force: bool) -> None:
    """Atomically, to a regular file only, 0600 (`twin_cli.files.output_files`)."""
    try:
        write_atomically(path, text.encode("utf-8"), ours=is_save, force=force)
    except OutputFileError as exc:
        raise WorldFileError(exc.filename, exc.problem, exc.fix) from exc
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
    world = _new_world(path, doc)
    entities = [_respawn(path, world, item.model_dump()) for item in doc.entities]
    layout, state = save_upgrades.add_rotors(
        world.model, dict(doc.layout), np.array(doc.state, dtype=float)
    )
    layout, state = save_upgrades.add_pushes(world.model, layout, state)
    layout, state = _servo_references(world, layout, state)
    layout, state = _pid_integrals(world.model, layout, state)
    laws = _laws(world)
    layout, state = _own_servos(world, laws, layout, state)
    saved = [JointCommand(**c.model_dump(exclude=OBSOLETE_COMMAND_FIELDS)) for c in doc.commands]
    snapshot = WorldSnapshot(
        doc.name,
        world.settings,
        doc.paused,
        doc.iterations,
        doc.divergences,
        tuple(entities),
        _natives(world, laws, saved, state),
        tuple(Push(p.body, tuple(p.wrench), p.end_step) for p in doc.pushes),
        layout,
        state,
    )
    try:
        world.restore(snapshot)
    except InvalidRequestError as exc:
        raise WorldFileError(
            path, str(exc), "restore the robot files as they were when saved, or spawn afresh"
        ) from exc
    _write_targets(world, snapshot.commands, {c.actuator for c in saved if c.native})
    return world


def _write_targets(world: World, commands: tuple, native: set[str]) -> None:
    """Commands made a servo's own on loading (`_natives`) write their targets as ctrl: the
    state saved with them holds the ctrl of the torque motors they were (0)."""
    for cmd in commands:
        if cmd.native and cmd.actuator not in native:
            entity, joint = cmd.actuator.split("/", 1)
            world.command(entity, joint, mode=cmd.mode, value=cmd.target)


def _laws(world: World) -> dict:
    """The servo laws of the respawned world's model (`native_servos.capture`)."""
    from twin_cli.world import native_servos

    return native_servos.capture(world.model)


def _exported_positions(model, laws: dict) -> list[int]:
    """Actuators that are a description's exported position servos (`native_servos`): before
    a World ran them by ctrl they were torque motors with a servo reference each."""
    return [
        a
        for a in range(model.nu)
        if (law := laws.get(model.actuator(a).name)) is not None
        and law.mode == "position"
        and model.actuator_actnum[a] == 0
        and _exported(model, a)
    ]


def _exported(model, a: int) -> bool:
    """Whether actuator `a`'s joint's control record says the export gave it its servo."""
    from converters.mjcf.export_servos import EXPORTED
    from twin_cli.world.joint_control import record_of

    entity, _, joint = model.actuator(a).name.rpartition("/")
    return EXPORTED in (record_of(model, entity, joint) or {})


def _own_servos(
    world: World, laws: dict, layout: dict[str, int], state: np.ndarray
) -> tuple[dict[str, int], np.ndarray]:
    """A file saved when a description's tagged position joints were torque motors with a
    servo reference (one activation each) loads into their own servos (none): those
    activations are dropped from the state. Other files pass unchanged."""
    model = world.model
    gone = _exported_positions(model, laws)
    if not gone or not _fits_but_na(model, layout) or layout.get("na") != model.na + len(gone):
        return layout, state
    slots, k = [], 0
    for a in range(model.nu):
        width = 1 if a in gone else int(model.actuator_actnum[a])
        if a in gone:
            slots.append(k)
        k += width
    at = 1 + model.nq + model.nv
    return {**layout, "na": int(model.na)}, np.delete(state, [at + s for s in slots])


def _natives(world: World, laws: dict, commands: list[JointCommand], state: np.ndarray) -> tuple:
    """Saved commands in the mode of a joint's own servo, as commands of that servo; a servo
    the file has no command for holds its joint where it was saved, as from load (a file
    saved when such joints were limp motors would otherwise have them pulled to ctrl 0)."""
    from dataclasses import replace as renew

    from twin_cli.world import native_servos, velocity_motors
    from twin_cli.world.actuation import effort_limit

    model = world.model
    out = {}
    for cmd in commands:
        law = laws.get(cmd.actuator)
        if law is not None and law.mode == cmd.mode:  # a saved native row: today's law
            rule = native_servos.rule(law)
            cmd = renew(cmd, kp=law.kp, kv=law.kv, feedforward=0.0, rule=rule, native=True)
        elif cmd.mode == "velocity" and velocity_motors.rotor_of(
            model, model.actuator(cmd.actuator).id
        ):  # a row saved when the joint ran a servo of its own: today's velocity motor
            cmd = renew(
                cmd, kp=0.0, kv=0.0, feedforward=0.0, rule=velocity_motors.RULE, native=False
            )
        out[cmd.actuator] = cmd
    for name, law in laws.items():
        if name in out:
            continue
        a = model.actuator(name).id
        value = native_servos.start_value(model, state[1 : 1 + model.nq], a, law)
        limit = native_servos.velocity_limit(model, name)
        out[name] = JointCommand(
            name, law.mode, value, law.kp, law.kv, effort_limit(model, a), limit, 0.0,
            native_servos.rule(law), native=True,
        )  # fmt: skip
    return tuple(out.values())


def _servo_references(
    world: World, layout: dict[str, int], state: np.ndarray
) -> tuple[dict[str, int], np.ndarray]:
    """A file saved before robots' motors carried a servo reference (no activations, `na` 0)
    gets them where MuJoCo's state keeps activations (after time, qpos and qvel), each at its
    joint's saved position: its commands go on from where the joints were. Other files pass
    unchanged."""
    model = world.model
    if layout.get("na") != 0 or model.na == 0 or not _fits_but_na(model, layout):
        return layout, state
    references = np.zeros(model.na)
    integrals = _pid_slots(model)
    for a in range(model.nu):
        if model.actuator_actadr[a] >= 0 and model.actuator_trntype[a] == 0:  # joint transmission
            joint = int(model.actuator_trnid[a, 0])
            references[model.actuator_actadr[a]] = state[1 + int(model.jnt_qposadr[joint])]
    references[integrals] = 0.0  # a gz-sim PID's integral starts empty
    at = 1 + model.nq + model.nv
    return {**layout, "na": int(model.na)}, np.insert(state, at, references)


def _pid_slots(model: mujoco.MjModel) -> list[int]:
    """The activations that hold a gz-sim PID's integral (MuJoCo's pid actuator plugin)."""
    from twin_cli.world.native_servos import pid_gains

    return [
        int(model.actuator_actadr[a]) for a in range(model.nu) if pid_gains(model, a) is not None
    ]


def _pid_integrals(
    model: mujoco.MjModel, layout: dict[str, int], state: np.ndarray
) -> tuple[dict[str, int], np.ndarray]:
    """A file saved before a gz-sim PID's integral ran (its joint's actuator had no activation)
    gets one per such joint, empty, where MuJoCo's state keeps activations: every other
    activation keeps its saved value. Other files pass unchanged."""
    integrals = _pid_slots(model)
    if (
        not integrals
        or not _fits_but_na(model, layout)
        or layout.get("na") != model.na - len(integrals)
    ):
        return layout, state
    at = 1 + model.nq + model.nv
    saved = iter(state[at : at + int(layout["na"])])
    act = [0.0 if k in integrals else next(saved) for k in range(model.na)]
    new = np.concatenate([state[:at], act, state[at + int(layout["na"]) :]])
    return {**layout, "na": int(model.na)}, new


def _fits_but_na(model: mujoco.MjModel, layout: dict[str, int]) -> bool:
    """Whether the saved layout is `model`'s in every size but its activations (`na`)."""
    return all(v == int(getattr(model, k)) for k, v in layout.items() if k != "na")


def _new_world(path: str | os.PathLike, doc: SaveDocument) -> World:
    """An empty world with the saved settings (checked like any settings)."""
    values = doc.settings.model_dump()
    values["gravity"] = tuple(values["gravity"])
    try:
        return World(WorldSettings(**values), name=doc.name)
    except TwinError as exc:
        raise WorldFileError(
            path, f"settings: {exc}", "give a file written by `twin save`"
        ) from exc


def _read(path: Path) -> SaveDocument:
    """The file's document, checked field by field (`save_schema`).

    Raises:
        WorldFileError: unreadable, not JSON, too deeply nested, or a field that is wrong.
    """
    try:
        data = json.loads(input_files.read_text(path))
    except input_files.InputFileError as exc:
        raise WorldFileError(path, str(exc.strerror), "give a file written by `twin save`") from exc
    except OSError as exc:
        raise WorldFileError(path, f"cannot read ({exc.strerror})", "check the path") from exc
    except json.JSONDecodeError as exc:
        raise WorldFileError(
            path, f"not JSON ({exc.msg}, line {exc.lineno})", "give a file written by `twin save`"
        ) from exc
    except (RecursionError, UnicodeDecodeError) as exc:
        raise WorldFileError(
            path,
            f"not a twin world file ({type(exc).__name__})",
            "give a file written by `twin save`",
        ) from exc
    if not isinstance(data, dict) or data.get("format") != FORMAT or data.get("version") != VERSION:
        raise WorldFileError(
            path, "not a twin world file (version 1)", "give a file written by `twin save`"
        )
    doc, problem = checked_document(data)
    if doc is None:
        raise WorldFileError(path, problem, SAVED_BY_TWIN)
    return doc


def _respawn(path: str | os.PathLike, world: World, item: dict[str, Any]) -> Entity:
    """Spawns a saved entity again; returns its record with the saved spawn state.

    Its saved pose is already on the ground, so it is spawned without on-ground placement;
    its record keeps the request as it was given.
    """
    source: str | mujoco.MjSpec = item["source"]
    if item["xml"] is not None:
        try:
            source = mujoco.MjSpec.from_string(item["xml"])
        except ValueError as exc:
            problem = f"entity [{item['name']}]: its xml (MJCF) is not valid ({exc})"
            raise WorldFileError(path, problem, SAVED_BY_TWIN) from exc
    request = replace(SpawnRequest.from_body(item), source=source, xml=None, base_dir=None)
    try:
        world.spawn(replace(request, on_ground=False), name=item["name"], pose=Pose(**item["pose"]))
    except (TwinError, ConversionError) as exc:
        problem = f"entity [{item['name']}] cannot be spawned from its source again ({exc})"
        raise WorldFileError(path, problem, "restore its source file, or spawn afresh") from exc
    spawn_state = EntityState(**{k: np.array(v) for k, v in item["spawn_state"].items()})
    entity = world.entity(item["name"])
    index = world.index_of(item["name"])
    spawn_state = save_upgrades.add_entity_rotors(world.model, index, spawn_state)
    spawn_state = save_upgrades.add_entity_pushes(world.model, index, spawn_state)
    if spawn_state.act.size != entity.spawn_state.act.size:
        # saved before its motors carried servo references, or before its tagged position
        # joints ran their own servos (no activation): the spawn's activations as spawned now
        spawn_state = replace(spawn_state, act=entity.spawn_state.act.copy())
    return replace(entity, source=item["source"], request=request, spawn_state=spawn_state)
