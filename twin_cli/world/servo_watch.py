"""What the servos of a world need between steps: windup limits and staying awake while moving.

One observer per world, at `servos.WINDUP_RATE` of sim time, present only while a servo moves
(a velocity command, or a position ramp not yet at its target). Each call it limits every
velocity servo's integral (`servos.limit_windup`) and lets the trees of servos that have
arrived sleep again (`sleeping.hold_awake`); when none moves it removes itself.
"""

from __future__ import annotations

from twin_cli.world import servos, sleeping
from twin_cli.world.state import WorldState


def watch(state: WorldState) -> None:
    """Starts the world's servo observer unless it runs (the lock is held)."""
    if state.servo_observer:
        return
    memory = servos.WindupMemory()
    state.servo_observer = state.observers.add(
        lambda: _tend(state, memory),
        servos.WINDUP_RATE,
        float(state.data.time),
        state.model.opt.timestep,
    )


def unwatch(state: WorldState) -> None:
    """Stops the world's servo observer, forgetting what it remembered (the lock is held)."""
    if state.servo_observer:
        state.observers.remove(state.servo_observer)
        state.servo_observer = 0


def _tend(state: WorldState, memory: servos.WindupMemory) -> None:
    model, data = state.model, state.data
    windup, settled, moving = [], [], 0
    for key, cmd in state.commands.items():
        if cmd.mode == "effort":
            continue
        a = memory.servo(model, key)
        if a < 0:
            continue
        if cmd.mode == "velocity":
            moving += 1
            if cmd.kp > 0:
                windup.append((a, cmd))
        elif servos.moving(model, data, a, cmd):
            moving += 1
        else:
            settled.append(a)
    if windup:
        servos.limit_windup(model, data, windup, memory)
    if settled:
        sleeping.hold_awake(model, sleeping.actuator_trees(model, settled), False)
    if not moving:
        unwatch(state)
