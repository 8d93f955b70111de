"""The rules that finish every twin world, shared by the world engine and the exported scene.xml.

A twin World and the `scene.xml` that `twin convert` writes are built by these functions alone,
so plain MuJoCo steps the exported scene exactly as `twin validate` stepped the world:
  - `world_spec`: Gazebo's empty world (ground, sun) with the world's options and flags;
  - `min_friction_priorities`: Gazebo's min-μ friction rule on geoms that state no priority;
  - `cap_contact_stiffness`, `cap_spec_contact_stiffness`: direct solrefs the step resolves;
  - `pose_free_constants`: a floating robot's contact softness independent of where it spawned.
Here rather than in `twin_cli`: converters never import twin_cli.
"""

from __future__ import annotations

import copy
import math

import mujoco
import numpy as np

from converters.gazebo.contact import (
    add_gazebo_ground,
    friction_priority,
    max_contact_stiffness,
)
from converters.gazebo.friction_pairs import follow_geom_solrefs
from converters.mjcf.world_options import WorldOptions, apply_world_options

# Gazebo's empty.world sun: directional, from above, casting shadows.
SUN_POS = (0.0, 0.0, 10.0)
# Unit length as written, so scene.xml carries the world's direction to the last bit.
SUN_DIR = tuple(v / math.sqrt(0.5**2 + 0.1**2 + 0.9**2) for v in (-0.5, 0.1, -0.9))
# A diverging entity must not reset the whole world (twin resets only that entity).
DISABLED = int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
FREE = int(mujoco.mjtJoint.mjJNT_FREE)
CANONICAL_FREE = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
# The qpos0 constants a free robot's pose changes only by rounding: inverse weights (contact
# regularisers), the mass matrix diagonal, actuator accelerations, dof lengths (sleep speeds).
POSE_FREE_FIELDS = (
    "body_invweight0",
    "dof_invweight0",
    "tendon_invweight0",
    "dof_M0",
    "actuator_acc0",
    "dof_length",
)


def world_spec(
    options: WorldOptions = WorldOptions(), *, ground: bool = True, name: str = "world"
) -> mujoco.MjSpec:
    """An empty world: Gazebo's ground (μ=100, μ2=50) if asked, the sun, the world's physics."""
    spec = mujoco.MjSpec()
    spec.modelname = name
    if ground:
        add_gazebo_ground(spec)
    spec.worldbody.add_light(name="sun", pos=list(SUN_POS), dir=list(SUN_DIR), castshadow=True)
    apply_world_physics(spec, options)
    return spec


def apply_world_physics(spec: mujoco.MjSpec, options: WorldOptions = WorldOptions()) -> None:
    """The world's options (`apply_world_options`) and flags in `spec.option`."""
    apply_world_options(spec, options)
    spec.option.disableflags |= DISABLED


def min_friction_priorities(spec: mujoco.MjSpec) -> None:
    """Gives geoms without a priority the converter's min-μ priority (`friction_priority`).

    MuJoCo combines friction by maximum unless priorities differ; Gazebo by minimum. Converted
    robots already carry `friction_priority(μ)` on collision geoms; a plain MJCF geom (priority
    0) would otherwise take the ground's μ=100, which MuJoCo's friction cone cannot resolve:
    measured, a 1 kg ball falls through such a ground.
    """
    for geom in spec.geoms:
        if geom.priority == 0:
            geom.priority = friction_priority(float(geom.friction[0]))


def capped_solrefs(solref: np.ndarray, timestep: float) -> tuple[np.ndarray, np.ndarray]:
    """Direct solrefs (n, 2) capped at the stiffest S a contact gets at step h
    (`max_contact_stiffness`), keeping the damping ratio B/(2√S).

    Returns:
        The capped solrefs and a mask of the rows that were capped.
    """
    solref = np.asarray(solref, dtype=float).reshape(-1, 2)
    limit = max_contact_stiffness(timestep)
    stiffness = -solref[:, 0]
    over = (solref[:, 0] < 0) & (stiffness > limit)
    capped = solref.copy()
    capped[over, 0] = -limit
    capped[over, 1] = solref[over, 1] * np.sqrt(limit / stiffness[over])
    return capped, over


def cap_contact_stiffness(model: mujoco.MjModel, original: np.ndarray | None = None) -> int:
    """Caps every direct geom solref of a compiled model at its timestep (friction pairs
    follow their geoms); returns how many geoms were capped.

    Args:
        model: `geom_solref` is changed in place.
        original: the uncapped solrefs (ngeom, 2) to start from (default: the model's own).
    """
    solref = model.geom_solref if original is None else original
    capped, over = capped_solrefs(solref, float(model.opt.timestep))
    model.geom_solref[:] = capped
    follow_geom_solrefs(model)  # mu1/mu2 pairs copy their deciding geom's solref
    return int(over.sum())


def cap_spec_contact_stiffness(spec: mujoco.MjSpec, timestep: float) -> int:
    """Caps every direct geom solref of `spec` at `timestep` [s]; returns how many."""
    geoms = list(spec.geoms)
    if not geoms:
        return 0
    capped, over = capped_solrefs(np.array([g.solref for g in geoms]), timestep)
    for geom, row in zip(geoms, capped, strict=True):
        geom.solref = row
    return int(over.sum())


def pose_free_constants(model: mujoco.MjModel) -> None:
    """The constants MuJoCo derives at qpos0 (`POSE_FREE_FIELDS`) computed with every free joint
    at the origin.

    A contact's regulariser comes from `body_invweight0`/`dof_invweight0`, which the compiler
    computes at qpos0, where a spawned robot stands at its spawn pose: its values then differ in
    the last bits with the pose (6e-13 at z = 1.5 m), which ground contact amplifies to 4.5e-8 m
    of the root in 1 s. At the origin they are the robot file's own (`scene.xml` compiles its
    robot there), so a robot steps alike wherever it spawns and in the exported scene.
    """
    free = np.flatnonzero(model.jnt_type == FREE)
    starts = [int(model.jnt_qposadr[j]) for j in free]
    if all(np.array_equal(model.qpos0[a : a + 7], CANONICAL_FREE) for a in starts):
        return  # already there (a loaded robot file): no scratch data to build
    scratch = copy.copy(model)  # mj_setConst rewrites more (sleep policies, light offsets)
    for at in starts:
        scratch.qpos0[at : at + 7] = CANONICAL_FREE
    mujoco.mj_setConst(scratch, mujoco.MjData(scratch))
    for field in POSE_FREE_FIELDS:
        getattr(model, field)[:] = getattr(scratch, field)


def finish_world_model(model: mujoco.MjModel, original: np.ndarray | None = None) -> int:
    """What every compiled world model gets: contact stiffness capped at its step and pose-free
    qpos0 constants; returns how many solrefs were capped."""
    pose_free_constants(model)
    return cap_contact_stiffness(model, original)


def finish_robot_spec(spec: mujoco.MjSpec, options: WorldOptions = WorldOptions()) -> None:
    """A robot's spec as a world attaches it: min-μ priorities, solrefs capped at the step."""
    min_friction_priorities(spec)
    cap_spec_contact_stiffness(spec, options.timestep)
