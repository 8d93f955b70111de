"""Attaching an entity's MjSpec to the world's spec at a pose, seeding its first state, and
removing it again.

The world attaches to its live spec with its lock held and, on any failure, removes whatever of
the entity was attached (`remove_entity`): an orphan subtree left by a failed compile would make
every later compile of the world fail.
"""

from __future__ import annotations

import mujoco
import numpy as np

from converters.mjcf.world_rules import min_friction_priorities
from twin_cli.world import fixed_base, servos, shared_meshes
from twin_cli.world.entities import EntityIndex
from twin_cli.world.pose import Pose, quat4, quat_multiply, rotate
from twin_cli.world.scene import adopt_world_globals

HOME_KEY = "home"
ROOT_DEFAULT = "main"  # MjSpec's root default class, "<entity>/main" once attached


def prepare_child(child: mujoco.MjSpec, world: mujoco.MjSpec) -> np.ndarray | None:
    """Makes `child` safe to attach; returns its `home` keyframe qpos (its own layout) or None.

    Names every unnamed body, joint, actuator and equality (state moves by name, and an unnamed
    free joint cannot be found again), gives its motors a servo reference, adopts the world's
    global settings, and removes the
    child's keyframes: attached keyframes get lost or collide ("repeated name 'home'"), so the
    home pose is read here and seeded by the world instead.
    """
    _name_unnamed(child)
    min_friction_priorities(child)  # Gazebo's min-μ rule, as the exported scene has it
    servos.carry_exported_servos(child)  # the file's servos (native_servos); a no-op once loaded
    servos.give_reference(child)  # motors hold their targets under load (servos module)
    adopt_world_globals(child, world)
    if len(child.keys) == 0:
        return None
    key = next((k for k in child.keys if k.name == HOME_KEY), child.keys[0])
    home = _key_qpos(child, key)
    for k in list(child.keys):
        child.delete(k)
    return home


def _key_qpos(child: mujoco.MjSpec, key: mujoco.MjsKey) -> np.ndarray:
    """The key's full qpos; read from the spec when complete, else compiled (qpos0 fill-in).

    Compiling the child only for this costs about 1 ms for a humanoid, a quarter of a spawn.
    """
    nq = sum(fixed_base.QPOS_WIDTH[int(j.type)] for j in child.joints)
    if len(key.qpos) == nq:
        return np.array(key.qpos, dtype=float)
    model = child.copy().compile()
    return np.array(model.key(key.name).qpos) if key.name else np.array(model.key_qpos[0])


def _name_unnamed(child: mujoco.MjSpec) -> None:
    for i, body in enumerate(child.bodies[1:], start=1):
        if not body.name:
            body.name = f"body{i}"
        for k, joint in enumerate(body.joints):
            if not joint.name:
                joint.name = f"{body.name}_joint{k}"
    for kind, items in (("actuator", child.actuators), ("equality", child.equalities)):
        for i, item in enumerate(items):
            if not item.name:
                item.name = f"{kind}{i}"


def attach(world: mujoco.MjSpec, child: mujoco.MjSpec, name: str, pose: Pose) -> None:
    """Attaches `child` to `world` in a frame "<name>/" at `pose`, prefixing names "<name>/"."""
    shares = shared_meshes.uses_shared(child)
    frame = world.worldbody.add_frame(name=f"{name}/", pos=list(pose.position()))
    frame.quat = np.array(pose.quat())
    world.attach(child, frame=frame, prefix=f"{name}/")
    if shares:  # a robot's meshes compile once per world, not once per instance
        shared_meshes.adopt(world, name)


def move_frame(world: mujoco.MjSpec, name: str, pose: Pose) -> None:
    """Moves the attach frame of entity `name` (fixed-base entities) to `pose`."""
    frame = world.frame(f"{name}/")
    frame.pos = np.array(pose.position())
    frame.quat = np.array(pose.quat())


_PREFIXED_LISTS = (
    "meshes",
    "materials",
    "textures",
    "hfields",
    "skins",
    "numerics",
    "texts",
    "tuples",
    "keys",
    "actuators",
    "sensors",
    "tendons",
    "equalities",
    "excludes",
    "pairs",
)


def remove_entity(world: mujoco.MjSpec, name: str) -> None:
    """Deletes entity `name` from `world`: frame, prefixed elements and default classes.

    Also undoes a partial spawn (frame added, attach or compile failed): whatever of the entity
    is present is removed, and the spec writes the same MJCF as before the spawn (tested).
    Assets are copied on attach and are not referenced by bodies, so they are deleted by prefix;
    so is the child's default tree ("<name>/main"); orphans would clash with a later spawn.
    """
    prefix = f"{name}/"
    frame = world.frame(prefix)
    if frame is not None:
        world.delete(frame)
    for attr in _PREFIXED_LISTS:
        for element in list(getattr(world, attr)):
            if element.name.startswith(prefix):
                world.delete(element)
    defaults = world.find_default(f"{prefix}{ROOT_DEFAULT}")
    if defaults is not None:
        world.delete(defaults)
    shared_meshes.prune(world)


def free_offsets(model: mujoco.MjModel, index: EntityIndex) -> list[int]:
    """Where each free joint of the entity starts in its own qpos (`index.qpos` order): the
    root's, and those of an SDF model's other unjoined links."""
    free = [j for j in index.joints if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]
    return [int(np.flatnonzero(index.qpos == model.jnt_qposadr[j])[0]) for j in free]


def initial_qpos(
    model: mujoco.MjModel, index: EntityIndex, home: np.ndarray | None, pose: Pose
) -> np.ndarray:
    """The entity's own initial configuration at its spawn pose, at rest.

    Without a home key this is the compiled `qpos0` (free joints' parts already include the
    attach frame). With one, the key's joint values are used and each free joint's pose
    (expressed in the child's own world) is composed with the attach frame `pose`: the root's,
    and those of an SDF model's other unjoined links, which float on their own.
    """
    q0 = model.qpos0[index.qpos].copy()
    if home is None or len(home) != len(q0):
        return q0
    q = np.array(home, dtype=float)
    frame_quat = pose.quat()
    for at in free_offsets(model, index):
        key_pos = (float(home[at]), float(home[at + 1]), float(home[at + 2]))
        q[at : at + 3] = np.add(pose.position(), rotate(frame_quat, key_pos))
        q[at + 3 : at + 7] = quat_multiply(frame_quat, quat4(home[at + 3 : at + 7]))
    return q
