"""Helpers shared by the world tests: MJCF text to a spec, and a world's full state vector."""

from __future__ import annotations

import mujoco
import numpy as np

from twin_cli.world import World

STATE = mujoco.mjtState.mjSTATE_INTEGRATION


def spec_of(xml: str) -> mujoco.MjSpec:
    return mujoco.MjSpec.from_string(xml)


def full_state(world: World) -> np.ndarray:
    """Every integration-state number of the world (time, qpos, qvel, act, ctrl, forces...)."""
    state = np.empty(mujoco.mj_stateSize(world.model, STATE))
    mujoco.mj_getState(world.model, world.data, state, STATE)
    return state
