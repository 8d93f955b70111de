"""What holds a robot from load: its own servos, and its drive plugins' wheels at zero speed.

Gazebo's drive plugins command their wheels on every update from the moment they load, so a base
no one has driven stands on a slope. twin's drive controllers start on a robot's first drive
command; until then these holds stand in for them: after every spawn and every full reset, each
joint `converters.gazebo.drive_records.held_from_load` lists gets its command (wheels a zero
velocity, steering joints the angle 0), as `twin command` would give it. A joint whose motor does
not offer that mode (its tags name other interfaces) is left as it is. A wheel's zero velocity
is its joint's dry friction bounded by the effort limit (`twin_cli.world.speed_holds`): a value
on the model with no gains to derive, so a later velocity command writes its own servo as it
would on a wheel no one held.
"""

from __future__ import annotations

from collections.abc import Iterable

from converters.gazebo.drive_records import held_from_load
from twin_cli.world import driving, joint_control
from twin_cli.world.state import WorldState


def hold_from_load(state: WorldState, names: Iterable[str]) -> None:
    """Commands each entity's joints as from load (the lock is held; entities are committed):
    its own servos where they are (`driving.start_commands`), then its plugin-held joints."""
    names = list(names)
    driving.start_commands(state, names)
    for name in names:
        if not state.entities[name].plugins:  # no drive or controller holds a joint
            continue
        motors = driving.motor_joints(state, name)
        by_mode: dict[str, dict[str, float]] = {}
        for joint, (mode, target) in held_from_load(state.entities[name].plugins).items():
            if joint in motors and mode in joint_control.limits_of(state.model, name, joint).modes:
                by_mode.setdefault(mode, {})[joint] = target
        for mode, targets in by_mode.items():
            driving.command_joints(state, name, targets, mode=mode, clip=True)
        _start_twists(state, name)


def _start_twists(state: WorldState, name: str) -> None:
    """A holonomic drive's twist from load (gz-sim VelocityControl's `initial_linear` and
    `initial_angular`) into its planar servos' ctrl, as the exported home key has it."""
    from converters.gazebo.drive_motors import planar_controls

    for plugin in state.entities[name].plugins:
        twist = getattr(plugin, "initial_twist", None)
        servos = planar_controls(state.model, name, plugin, twist) if twist and any(twist) else None
        if servos is not None:
            ids, ctrl = servos
            state.data.ctrl[ids] = ctrl
