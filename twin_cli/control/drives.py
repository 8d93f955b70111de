"""The diff drives of a world: `twin drive` and `twin odom` behind one checked entry each.

A world's controllers are created on the first command to an entity and kept beside the world
(keyed weakly, so a replaced world takes its controllers with it). Every request is checked
before anything changes: an unknown entity, an entity without a diff-drive plugin, or a
non-finite value raises one TwinError and leaves the world as it was.
"""

from __future__ import annotations

import math
import threading
import weakref
from typing import TYPE_CHECKING, Any

from twin_cli.control.diff_drive import DiffDriveController
from twin_cli.errors import InvalidRequestError

if TYPE_CHECKING:
    from twin_cli.world.engine import World

_CONTROLLERS: weakref.WeakKeyDictionary[Any, dict[str, DiffDriveController]] = (
    weakref.WeakKeyDictionary()
)
_GUARD = threading.Lock()


def drive(
    world: World, entity: str, linear: float, angular: float, duration: float | None = None
) -> dict[str, Any]:
    """Commands entity's base at (v [m/s], ω [rad/s]), for `duration` [s] of sim time or until
    replaced (the lesson's /cmd_vel); returns the command as applied.

    Raises:
        EntityNotFoundError: no such entity. InvalidRequestError: no diff-drive plugin, or a
            value is not finite, or the duration is not > 0.
    """
    _check_finite("linear", linear, "m/s")
    _check_finite("angular", angular, "rad/s")
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise InvalidRequestError(
            "drive duration", f"{duration} s is not a positive number", "give e.g. --duration 5"
        )
    controller = controller_of(world, entity)
    controller.command(linear, angular, duration)
    return {
        "entity": entity,
        "plugin": controller.plugin.name,
        "linear": linear,
        "angular": angular,
        "duration": duration,
        "update_rate": controller.rate,
    }


def odometry(world: World, entity: str) -> dict[str, Any]:
    """The entity's odometry (pose and twist) as its diff drive reports it."""
    return controller_of(world, entity).odometry()


def controller_of(world: World, entity: str) -> DiffDriveController:
    """The entity's diff-drive controller, created on first use.

    Raises:
        EntityNotFoundError, InvalidRequestError: see `drive`.
    """
    with world.lock, _GUARD:
        found = world.entity(entity)  # raises EntityNotFoundError
        controllers = _CONTROLLERS.setdefault(world, {})
        controller = controllers.get(entity)
        if controller is not None and found is controller.entity_record:
            return controller
        drives = [p for p in found.plugins if type(p).__name__ == "DiffDrive"]
        if not drives:
            raise InvalidRequestError(
                f"entity [{entity}]",
                "has no diff-drive plugin (libgazebo_ros_diff_drive.so)",
                "add one to its <gazebo> tags, or drive its joints one by one",
            )
        if controller is not None:
            controller.stop()  # an entity respawned under the same name
        controller = DiffDriveController(world, entity, drives[0])
        controller.entity_record = found
        controllers[entity] = controller
        return controller


def _check_finite(what: str, value: float, unit: str) -> None:
    if not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InvalidRequestError(
            f"drive {what} velocity", f"{value!r} is not a finite number", f"give {unit}"
        )
