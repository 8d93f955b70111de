"""Entities of a world: what was spawned, where each lives in the compiled model, its state.

An entity's elements carry the prefix "<name>/" in the world spec. Element ids change at every
recompile (spawn, delete), so the world re-indexes all entities from the model's names after
each one and moves state by name, never by position.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

import mujoco
import numpy as np

from converters.description.robot import MODEL_SITE
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world.pose import Pose

_QPOS_WIDTH = np.array([7, 4, 1, 1])  # by mjtJoint: free, ball, slide, hinge
_DOF_WIDTH = np.array([6, 3, 1, 1])
_INT = np.int64


@dataclass(frozen=True)
class EntityIndex:
    """Where one entity lives in one compiled model (all arrays are ids or addresses).

    Attributes:
        bodies: body ids, tree order; `root` is the first body whose parent is the world.
        root: root body id, or -1 when the entity has no body.
        joints: joint ids; `qpos`/`dofs`: their qpos and dof addresses, concatenated.
        free_qpos: qpos address of the root's free joint, or -1 (fixed base).
        actuators: actuator ids; `acts`: their activation addresses.
        equalities, mocaps, geoms: equality ids, mocap ids, geom ids (of the entity's bodies).
        model_site: id of the site marking the model frame (`<name>/__model__`, SDF models
            whose frame is not their root link's), or -1.
    """

    bodies: np.ndarray
    root: int
    joints: np.ndarray
    qpos: np.ndarray
    dofs: np.ndarray
    free_qpos: int
    actuators: np.ndarray
    acts: np.ndarray
    equalities: np.ndarray
    mocaps: np.ndarray
    geoms: np.ndarray
    model_site: int = -1


@dataclass(frozen=True)
class EntityState:
    """The integration state of one entity, in its own element order (see EntityIndex)."""

    qpos: np.ndarray
    qvel: np.ndarray
    qacc_warmstart: np.ndarray
    qfrc_applied: np.ndarray
    act: np.ndarray
    ctrl: np.ndarray
    xfrc_applied: np.ndarray
    eq_active: np.ndarray
    mocap_pos: np.ndarray
    mocap_quat: np.ndarray


@dataclass(frozen=True)
class Entity:
    """What was spawned and how, so that it can be reset, listed, saved and spawned again.

    Attributes:
        name: entity name (the prefix of its elements, without the "/").
        source: absolute path of the file it came from, `<xml>` or "<MjSpec>".
        request: the spawn request it came from (args, packages, `-J`, on-ground, repair).
        pose: spawn pose (after `on_ground` placement).
        spawn_state: the state `reset` returns it to.
        report: the converter's report as a dict (URDF/xacro sources), else None.
        xml: MJCF text of an MjSpec or text source (for save/load), else None.
        description: the URDF text after xacro (for `/robot_description`), else None.
        sensors: its Gazebo sensors (`converters.description.sensors.SensorSpec`), if any.
        plugins: its drive and rotor plugins (`converters.gazebo.drive_records`), if any.
    """

    name: str
    source: str
    request: SpawnRequest
    pose: Pose
    spawn_state: EntityState
    report: dict | None = None
    xml: str | None = field(default=None, repr=False)
    description: str | None = field(default=None, repr=False)
    sensors: tuple = field(default=(), repr=False)
    plugins: tuple = field(default=(), repr=False)


def element_names(model: mujoco.MjModel, adr: np.ndarray) -> list[str]:
    """Names stored at `adr` (e.g. `model.name_bodyadr`) in the model's name buffer."""
    buffer = bytes(model.names)
    return [buffer[a : buffer.index(b"\0", a)].decode() for a in adr]


def _owner(names: list[str]) -> dict[str, list[int]]:
    groups: dict[str, list[int]] = {}
    for i, name in enumerate(names):
        head, sep, _ = name.partition("/")
        if sep:
            groups.setdefault(head, []).append(i)
    return groups


def index_entities(model: mujoco.MjModel, names: list[str]) -> dict[str, EntityIndex]:
    """Indexes every entity in `names` from the element names of `model`."""
    groups = {
        kind: _owner(element_names(model, adr))
        for kind, adr in (
            ("body", model.name_bodyadr),
            ("joint", model.name_jntadr),
            ("actuator", model.name_actuatoradr),
            ("equality", model.name_eqadr),
        )
    }
    parts = {name: [np.array(groups[k].get(name, []), _INT) for k in groups] for name in names}
    body_owner = np.full(model.nbody, -1, _INT)
    for k, name in enumerate(names):
        body_owner[parts[name][0]] = k
    geom_owner = body_owner[model.geom_bodyid]
    return {
        name: replace(
            _index_one(model, parts[name], np.flatnonzero(geom_owner == k).astype(_INT)),
            model_site=mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{name}/{MODEL_SITE}"),
        )
        for k, name in enumerate(names)
    }


def _index_one(model: mujoco.MjModel, parts: list[np.ndarray], geoms: np.ndarray) -> EntityIndex:
    """One entity's index from its bodies, joints, actuators and equalities (`parts`)."""
    bodies, joints, actuators, equalities = parts
    roots = bodies[model.body_parentid[bodies] == 0]
    root = int(roots[0]) if len(roots) else -1
    types = model.jnt_type[joints]
    free = joints[(types == mujoco.mjtJoint.mjJNT_FREE) & (model.jnt_bodyid[joints] == root)]
    has_act = model.actuator_actadr[actuators] >= 0
    mocaps = model.body_mocapid[bodies]
    return EntityIndex(
        bodies=bodies,
        root=root,
        joints=joints,
        qpos=_spans(model.jnt_qposadr[joints], _QPOS_WIDTH[types]),
        dofs=_spans(model.jnt_dofadr[joints], _DOF_WIDTH[types]),
        free_qpos=int(model.jnt_qposadr[free[0]]) if len(free) else -1,
        actuators=actuators,
        acts=_spans(
            model.actuator_actadr[actuators][has_act], model.actuator_actnum[actuators][has_act]
        ),
        equalities=equalities,
        mocaps=mocaps[mocaps >= 0].astype(_INT),
        geoms=geoms,
    )


def _spans(starts: np.ndarray, widths: np.ndarray) -> np.ndarray:
    """The addresses start, start+1, ..., start+width-1 of every span, concatenated."""
    widths = np.asarray(widths, _INT)
    if widths.size == 0:
        return np.zeros(0, _INT)
    first = np.repeat(np.cumsum(widths) - widths, widths)
    return np.repeat(np.asarray(starts, _INT), widths) + np.arange(int(widths.sum())) - first


# EntityState field -> the EntityIndex addresses it is read at (data.<field>[index.<part>]).
_STATE_PARTS = (
    ("qpos", "qpos"),
    ("qvel", "dofs"),
    ("qacc_warmstart", "dofs"),
    ("qfrc_applied", "dofs"),
    ("act", "acts"),
    ("ctrl", "actuators"),
    ("xfrc_applied", "bodies"),
    ("eq_active", "equalities"),
    ("mocap_pos", "mocaps"),
    ("mocap_quat", "mocaps"),
)


def capture_state(data: mujoco.MjData, index: EntityIndex) -> EntityState:
    """Copies one entity's integration state out of `data`."""
    return EntityState(
        **{attr: getattr(data, attr)[getattr(index, part)].copy() for attr, part in _STATE_PARTS}
    )


def write_state(data: mujoco.MjData, index: EntityIndex, state: EntityState) -> None:
    """Writes one entity's integration state into `data` (same entity, any compiled model)."""
    for attr, part in _STATE_PARTS:
        getattr(data, attr)[getattr(index, part)] = getattr(state, attr)


def move_states(
    source: mujoco.MjData,
    source_index: dict[str, EntityIndex],
    target: mujoco.MjData,
    target_index: dict[str, EntityIndex],
    names: list[str],
) -> None:
    """Copies the state of entities `names` from `source` into `target` (another model's data).

    Equivalent to `write_state(target, ..., capture_state(source, ...))` per entity, with one
    gather and one scatter per field for all entities (spawn latency grows with their number).
    """
    if not names:
        return
    for attr, part in _STATE_PARTS:
        old = np.concatenate([getattr(source_index[n], part) for n in names])
        new = np.concatenate([getattr(target_index[n], part) for n in names])
        getattr(target, attr)[new] = getattr(source, attr)[old]


def rest_state(model: mujoco.MjModel, index: EntityIndex, qpos: np.ndarray) -> EntityState:
    """The state of an entity at configuration `qpos`, at rest, with nothing applied."""
    nv, nb = len(index.dofs), len(index.bodies)
    return EntityState(
        qpos=np.array(qpos, dtype=float),
        qvel=np.zeros(nv),
        qacc_warmstart=np.zeros(nv),
        qfrc_applied=np.zeros(nv),
        act=np.zeros(len(index.acts)),
        ctrl=np.zeros(len(index.actuators)),
        xfrc_applied=np.zeros((nb, 6)),
        eq_active=model.eq_active0[index.equalities].astype(np.uint8),
        mocap_pos=model.body_pos[index.bodies[np.isin(index.bodies, _mocap_bodies(model))]],
        mocap_quat=model.body_quat[index.bodies[np.isin(index.bodies, _mocap_bodies(model))]],
    )


def _mocap_bodies(model: mujoco.MjModel) -> np.ndarray:
    return np.flatnonzero(model.body_mocapid >= 0)


def typed_like(reference: EntityState, loaded: EntityState) -> EntityState:
    """`loaded` with each array's dtype and shape taken from `reference` (a state read back
    from JSON has lists where the world keeps typed arrays).

    Raises:
        InvalidRequestError: an array whose size is not the reference's.
    """
    from twin_cli.errors import InvalidRequestError

    typed = {}
    for f in fields(EntityState):
        ref, got = getattr(reference, f.name), np.asarray(getattr(loaded, f.name))
        if got.size != ref.size:
            raise InvalidRequestError(
                f"spawn state '{f.name}'",
                f"{got.size} values, the entity has {ref.size}",
                "give the state of the same robot",
            )
        typed[f.name] = got.astype(ref.dtype).reshape(ref.shape)
    return EntityState(**typed)
