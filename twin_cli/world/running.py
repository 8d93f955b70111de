"""Stepping a world: step, reset, stats, and recovery from a diverging entity.

Functions of a world's state (`twin_cli.world.state`). `advance` is what the stepping loop and
`step` run with the lock held; everything else takes the lock itself.
"""

from __future__ import annotations

from dataclasses import replace
from functools import partial
from time import perf_counter
from typing import TYPE_CHECKING

import mujoco

from twin_cli.errors import InvalidRequestError
from twin_cli.world import actuation as control
from twin_cli.world import native_servos
from twin_cli.world.divergence import (
    Divergence,
    batch_healthy,
    find_divergent,
    speed_bounds,
    warning_counts,
)
from twin_cli.world.entities import index_entities, write_state
from twin_cli.world.plugin_holds import hold_from_load
from twin_cli.world.recompile import commit
from twin_cli.world.sensor_rings import align_sensor_ticks, shift_sensor_history
from twin_cli.world.state import STATE, WorldState
from twin_cli.world.values import Stats

if TYPE_CHECKING:
    from twin_cli.world.loop import SteppingLoop

mj_step = mujoco.mj_step  # one global lookup per split instead of two


def step(state: WorldState, n: int = 1) -> None:
    """Steps `n` times now (paused or not)."""
    if not isinstance(n, int) or n < 0:
        raise InvalidRequestError(
            "step count", f"{n!r} is not a whole number >= 0", "give e.g. 100"
        )
    with state.lock:
        advance(state, n)


def reset(state: WorldState, loop: SteppingLoop, *, time_only: bool = False) -> None:
    """Puts every entity back to its spawn state and time to 0 (or only time and iterations).

    A full reset also clears pushes and joint commands (motors back to zero effort), except the
    holds robots' drive plugins keep from load (`plugin_holds`).
    """
    with state.lock:
        if time_only:
            state.pushes = [
                replace(p, end_step=p.end_step - state.iterations) for p in state.pushes
            ]
            shift_sensor_history(state.model, state.data, -float(state.data.time))
            state.data.time, state.iterations = 0.0, 0
            align_sensor_ticks(state.model, state.data)  # the grid of the new clock
            loop.reset_clock()
            return
        state.commands, state.pushes, state.perturbation = {}, [], {}
        model = state.spec.compile()
        state.native = native_servos.capture(model)
        data = mujoco.MjData(model)
        index = index_entities(model, list(state.entities))
        for n, e in state.entities.items():
            write_state(data, index[n], e.spawn_state)
        state.iterations = 0
        commit(state, state.spec, (model, data, index))
        hold_from_load(state, state.entities)
        loop.reset_clock()


def stats(state: WorldState, loop: SteppingLoop) -> Stats:
    """`gz stats` figures (factor averaged over the last 20 samples of 0.2 s)."""
    with state.lock:
        fig = loop.figures()
        return Stats(
            fig.factor, float(state.data.time), fig.real_time, state.iterations, state.paused
        )


def advance(state: WorldState, n: int) -> None:
    """Steps n times, splitting at push expiries; caller holds the lock."""
    while n > 0:
        due = min((p.end_step for p in state.pushes), default=None)
        chunk = n if due is None else max(1, min(n, due - state.iterations))
        _step_chunk(state, chunk)
        n -= chunk
        if due is not None and state.iterations >= due:
            _expire_pushes(state)


def _step_chunk(state: WorldState, n: int) -> None:
    """Steps n times; on divergence, replays the batch step by step to catch its origin.

    NaNs spread to other entities through collisions within a few steps, so a divergence
    found after a batch is traced back: the batch-start state is restored and stepped one
    step at a time, and the entity that goes bad first is reset to its spawn state. The speed
    bounds (`divergence.SpeedBounds`) are kept per compiled model in `state.speed_bounds`.
    """
    m, d = state.model, state.data
    if n > 1:
        mujoco.mj_getState(m, d, state.scratch_state, STATE)
    before = warning_counts(d)
    # MuJoCo's default handler prints and appends to ./MUJOCO_LOG.TXT; keep its text instead
    # (set once per chunk, not per observer split: each set is a Python call).
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(state.mujoco_warnings.append)
    try:
        if state.observers:
            state.observers.run(n, partial(_mj_steps, state), d, m.opt.timestep)
        else:
            _mj_steps(state, n)
    finally:
        mujoco.set_mju_user_warning(previous)
    state.iterations += n
    bounds = state.speed_bounds
    if bounds is None or bounds.model is not m:  # the first batch after a compile
        bounds = state.speed_bounds = speed_bounds(m, state.index)
    if batch_healthy(d, before, bounds.bound):
        return
    bad = find_divergent(d, before, state.index, bounds)
    if bad and n == 1:
        _recover(state, bad)
    elif bad:
        mujoco.mj_setState(m, d, state.scratch_state, STATE)
        state.observers.replaying(float(d.time))
        state.iterations -= n
        for _ in range(n):
            _step_chunk(state, 1)


def _mj_steps(state: WorldState, n: int) -> None:
    """n MuJoCo steps in one call (Gazebo's dampingFactor is joint damping in the model).

    Called between observer calls with the interpreter's caches cold from the last step, so it
    makes as few lookups as it can: each costs ~0.5 µs there.
    """
    start = perf_counter()
    mj_step(state.model, state.data, n)
    state.stepping_time += perf_counter() - start


def _recover(state: WorldState, bad: dict[str, str]) -> None:
    """Resets the offending entities to their spawn state; the others keep their state.

    MuJoCo's auto-reset (which would reset the whole world) is disabled in every world
    spec (scene.apply_physics), so within one step a diverging entity's NaNs stay its own.
    """
    for name, reason in bad.items():
        write_state(state.data, state.index[name], state.entities[name].spawn_state)
        state.divergences += 1
        state.divergence_log.append(Divergence(name, float(state.data.time), reason))


def _expire_pushes(state: WorldState) -> None:
    ended = {p.body for p in state.pushes if p.end_step <= state.iterations}
    state.pushes = [p for p in state.pushes if p.end_step > state.iterations]
    control.apply_pushes(state.model, state.data, state.pushes, ended, state.perturbation)
