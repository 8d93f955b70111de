"""Divergence: find which entities went unstable (NaN/Inf, MuJoCo bad-state warnings) in a batch.

MuJoCo itself checks qpos, qvel and qacc at every step; on a bad value it warns (recording the
offending qpos or dof address in `warning.lastinfo`) and resets the *whole* data. The world
therefore snapshots the state before each batch, and when this module reports an offender, it
restores the snapshot and resets only the offending entities to their spawn state.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from twin_cli.world.entities import EntityIndex

_W = mujoco.mjtWarning
BAD_STATE = (_W.mjWARN_BADQPOS, _W.mjWARN_BADQVEL, _W.mjWARN_BADQACC)


@dataclass(frozen=True)
class Divergence:
    """One entity reset for instability.

    Attributes:
        entity: entity name; sim_time: simulation time [s] of the batch start; reason: what was
        seen (e.g. "MuJoCo warning mjWARN_BADQACC at dof 8", "non-finite qvel").
    """

    entity: str
    sim_time: float
    reason: str


def warning_counts(data: mujoco.MjData) -> tuple[int, ...]:
    """How many times each bad-state warning fired so far."""
    return tuple(int(data.warning[w].number) for w in BAD_STATE)


def find_divergent(
    data: mujoco.MjData, before: tuple[int, ...], indices: dict[str, EntityIndex]
) -> dict[str, str]:
    """Entities that diverged since `before` (from `warning_counts`), with the reason.

    Returns:
        {entity: reason}; empty when the batch was healthy. A divergence that no entity owns
        is attributed to every entity.
    """
    found: dict[str, str] = {}
    for kind, count0 in zip(BAD_STATE, before, strict=True):
        if data.warning[kind].number > count0:
            address = int(data.warning[kind].lastinfo)
            field = "qpos" if kind == _W.mjWARN_BADQPOS else "dofs"
            reason = (
                f"MuJoCo warning {kind.name} at {'qpos' if field == 'qpos' else 'dof'} {address}"
            )
            found.update(dict.fromkeys(_owners(indices, field, [address]), reason))
    for field, values in (("qpos", data.qpos), ("dofs", data.qvel), ("dofs", data.qacc)):
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            found.update(dict.fromkeys(_owners(indices, field, bad), f"non-finite {field}"))
    if found and not set(found) <= set(indices):
        return dict.fromkeys(indices, next(iter(found.values())))
    return found


def _owners(indices: dict[str, EntityIndex], field: str, addresses: object) -> list[str]:
    owners = [n for n, ix in indices.items() if np.isin(getattr(ix, field), addresses).any()]
    return owners or ["<world>"]
