"""Where a spawned entity starts: overlaps with the ground or others. Its lowest point is the
converter's rule (`converters.mjcf.lowest_point`), which the exported `home` keyframe stands a
floating robot by too."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np

from converters.mjcf.lowest_point import collision_geoms
from twin_cli.world.entities import EntityIndex

PENETRATION_TOL = 1e-4  # [m] overlap below this is resting contact, not a bad start


@dataclass(frozen=True)
class Overlap:
    """The deepest overlap between the new entity and one other party.

    Attributes:
        other: "ground", "entity [name]" or a geom name.
        depth: penetration depth [m] (> 0).
    """

    other: str
    depth: float


def positioned(model: mujoco.MjModel, qpos: np.ndarray) -> mujoco.MjData:
    """A scratch MjData at configuration `qpos` with kinematics and contacts computed.

    The world's own data is never touched, so checking a spawn cannot change any trajectory.
    """
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_fwdPosition(model, data)
    return data


def overlaps(
    data: mujoco.MjData,
    geoms: np.ndarray,
    party_of: Callable[[int], str],
) -> list[Overlap]:
    """The deepest overlap of `geoms` with each other party, deepest first.

    Args:
        data: positioned data (see `positioned`) whose contacts are computed.
        geoms: the new entity's geom ids.
        party_of: names the owner of a geom outside `geoms` ("ground", "entity [x]").
    """
    mine = np.isin(data.contact.geom, geoms)  # (ncon, 2): which side is the new entity's
    deepest: dict[str, float] = {}
    for (g1, g2), (in1, in2), dist in zip(data.contact.geom, mine, data.contact.dist, strict=True):
        if in1 == in2 or -dist <= PENETRATION_TOL:
            continue
        other = party_of(int(g2 if in1 else g1))
        deepest[other] = max(deepest.get(other, 0.0), -float(dist))
    return sorted((Overlap(o, d) for o, d in deepest.items()), key=lambda o: -o.depth)


def overlap_warnings(name: str, z: float, found: list[Overlap]) -> list[str]:
    """One warning per overlap, with the depth and the spawn height that clears it."""
    return [
        f"entity [{name}]: collision geometry starts {o.depth:.4f} m inside {o.other}; "
        f"spawn at z >= {z + o.depth:.4f} m to clear it, or use --on-ground"
        for o in found
    ]


def start_warnings(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    index: dict[str, EntityIndex],
    name: str,
    z: float,
) -> list[str]:
    """Warnings for entity `name` starting inside the ground or another entity.

    Args:
        model, data: the world with the new entity seeded (data is not modified).
        index: every entity's index in `model`; name: the new entity; z: its spawn height [m].
    """
    scratch = positioned(model, data.qpos)
    body_owner = {int(b): n for n, ix in index.items() for b in ix.bodies}

    def party_of(geom: int) -> str:
        owner = body_owner.get(int(model.geom_bodyid[geom]))
        if owner:
            return f"entity [{owner}]"
        geom_name = model.geom(geom).name
        return "the ground" if geom_name == "ground" else f"geom [{geom_name}]"

    geoms = collision_geoms(model, index[name].geoms)
    found = overlap_warnings(name, z, overlaps(scratch, geoms, party_of))
    return found + self_overlap_warnings(model, scratch, name, geoms)


def self_overlaps(
    model: mujoco.MjModel, data: mujoco.MjData, geoms: np.ndarray
) -> dict[tuple[str, str], float]:
    """The deepest overlap [m] between two of an entity's own links, per pair of body names.

    Only pairs that collide show up: MuJoCo leaves out parent and child, and the converter
    excludes every pair Gazebo does not collide (self_collide off), so a pair here is one the
    robot's own description asks to collide.
    """
    mine = np.isin(data.contact.geom, geoms)
    deepest: dict[tuple[str, str], float] = {}
    for (g1, g2), (in1, in2), dist in zip(data.contact.geom, mine, data.contact.dist, strict=True):
        if not (in1 and in2) or -dist <= PENETRATION_TOL:
            continue
        pair = sorted(model.body(int(model.geom_bodyid[g])).name for g in (g1, g2))
        key = (pair[0], pair[1])
        deepest[key] = max(deepest.get(key, 0.0), -float(dist))
    return deepest


def self_overlap_warnings(
    model: mujoco.MjModel, data: mujoco.MjData, name: str, geoms: np.ndarray
) -> list[str]:
    """One warning per pair of the entity's links that start inside each other."""
    prefix = f"{name}/"
    return [
        f"entity [{name}]: links '{a.removeprefix(prefix)}' and '{b.removeprefix(prefix)}' start "
        f"{depth:.4f} m inside each other with self-collision on; choose a start posture that "
        "separates them (-J JOINT=POS) or turn self_collide off for one of them"
        for (a, b), depth in sorted(self_overlaps(model, data, geoms).items(), key=lambda i: -i[1])
    ]
