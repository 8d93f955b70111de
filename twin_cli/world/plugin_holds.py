"""What a robot's drive plugins command from load: its wheels held at zero speed.

Gazebo's drive plugins command their wheels on every update from the moment they load, so a base
no one has driven stands on a slope. twin's drive controllers start on a robot's first drive
command; until then these holds stand in for them: after every spawn and every full reset, each
joint `converters.gazebo.drive_records.held_from_load` lists gets its command (wheels a zero
velocity, steering joints the angle 0), as `twin command` would give it. A joint whose motor does
not offer that mode (its tags name other interfaces) is left as it is. The holds' gains are
provisional (`servos.HELD_FROM_LOAD`): a spawn does not yet know which contacts the wheels will
carry the robot through, so the first velocity command derives its own gains and keeps the held
force.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace

from converters.gazebo.drive_records import held_from_load
from twin_cli.world import driving, joint_control
from twin_cli.world.servos import HELD_FROM_LOAD
from twin_cli.world.state import WorldState


def hold_from_load(state: WorldState, names: Iterable[str]) -> None:
    """Commands each entity's plugin-held joints (the lock is held; entities are committed)."""
    for name in names:
        motors = driving.motor_joints(state, name)
        by_mode: dict[str, dict[str, float]] = {}
        for joint, (mode, target) in held_from_load(state.entities[name].plugins).items():
            if joint in motors and mode in joint_control.limits_of(state.model, name, joint).modes:
                by_mode.setdefault(mode, {})[joint] = target
        for mode, targets in by_mode.items():
            for cmd in driving.command_joints(state, name, targets, mode=mode, clip=True):
                state.commands[cmd.actuator] = replace(cmd, rule=HELD_FROM_LOAD)
