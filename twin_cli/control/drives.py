"""The drives of a world: `twin drive` and `twin odom` behind one checked entry each.

A world's controllers are created on the first command to an entity and kept beside the world
(keyed weakly, so a replaced world takes its controllers with it). The entity's first drive
record decides the controller: a differential drive, a steered base (Ackermann, tricycle) or a
holonomic one (planar move, mecanum, VelocityControl). Every request is checked before anything
changes: an unknown entity, an entity without a drive, an option its drive does not take, or a
non-finite value raises one TwinError and leaves the world as it was.
"""

from __future__ import annotations

import math
import threading
import weakref
from typing import TYPE_CHECKING, Any

from twin_cli.control.diff_drive import DiffDriveController
from twin_cli.control.drive_base import DriveController, Twist
from twin_cli.control.holonomic_drive import HolonomicController
from twin_cli.control.steered_drive import SteeredDriveController
from twin_cli.errors import InvalidRequestError

if TYPE_CHECKING:
    from twin_cli.world.engine import World

_CONTROLLERS: weakref.WeakKeyDictionary[Any, dict[str, DriveController]] = (
    weakref.WeakKeyDictionary()
)
_GUARD = threading.Lock()
CONTROLLERS: dict[str, type[DriveController]] = {
    "DiffDrive": DiffDriveController,
    "AckermannDrive": SteeredDriveController,
    "TricycleDrive": SteeredDriveController,
    "HolonomicDrive": HolonomicController,
}
DRIVE_NAMES = (
    "gazebo_ros diff drive, skid steer, Ackermann, tricycle or planar move; gz-sim DiffDrive, "
    "AckermannSteering, MecanumDrive or VelocityControl; or a vendor diff drive"
)


def drive(
    world: World,
    entity: str,
    linear: float,
    angular: float = 0.0,
    duration: float | None = None,
    *,
    lateral: float = 0.0,
    steering: float | None = None,
    curvature: float | None = None,
) -> dict[str, Any]:
    """Commands entity's base for `duration` [s] of sim time or until replaced (/cmd_vel).

    Args:
        linear: forward speed [m/s]; angular: yaw rate [rad/s]; lateral: sideways speed [m/s]
            (holonomic bases); steering: bicycle steering angle [rad], curvature: path
            curvature [1/m] (steered bases, instead of `angular`).

    Returns:
        The command as applied, with what it became (wheel speeds, steering angles).

    Raises:
        EntityNotFoundError: no such entity. InvalidRequestError: no drive plugin, an option
            its drive does not take, a value that is not finite, or a duration not > 0.
    """
    for what, value, unit in (
        ("linear", linear, "m/s"),
        ("angular", angular, "rad/s"),
        ("lateral", lateral, "m/s"),
        ("steering", steering, "rad"),
        ("curvature", curvature, "1/m"),
    ):
        if value is not None:
            _check_finite(what, value, unit)
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise InvalidRequestError(
            "drive duration", f"{duration} s is not a positive number", "give e.g. --duration 5"
        )
    twist = Twist(linear, angular, lateral, steering, curvature)
    _check_options(entity, *_drive_of(world, entity), twist)  # before a controller exists
    controller = controller_of(world, entity)
    if not controller.observed_rate:  # a joint command stopped it: run it again
        controller.resume()
    controller.command(twist, duration)
    with world.lock:
        applied = controller.command_reply()
    return {
        "entity": entity,
        "plugin": controller.plugin.name,
        "family": controller.plugin.family,
        "linear": linear,
        "angular": angular,
        "lateral": lateral,
        "steering": steering,
        "curvature": curvature,
        "duration": duration,
        "update_rate": controller.rate,
        "applied": applied,
    }


def release_joints(world: World, entity: str, joints: list[str]) -> list[str]:
    """Stops the entity's running drive if it turns any of `joints`, so that a joint command
    given by hand is not overwritten at the drive's next update (as Gazebo's plugin would);
    returns a note for each drive stopped. `twin drive` starts it again.

    The caller holds the world lock, with the joint command already accepted.
    """
    controller = _CONTROLLERS.get(world, {}).get(entity)
    if controller is None or not controller.observed_rate:
        return []
    owned = sorted(set(joints) & set(controller.plugin.wheel_joints()))
    if not owned:
        return []
    controller.stop()
    return [
        f"drive [{controller.plugin.name}] ({controller.plugin.family}) of [{entity}] stopped: "
        f"it turns {', '.join(owned)}; twin drive {entity} starts it again"
    ]


def odometry(world: World, entity: str) -> dict[str, Any]:
    """The entity's odometry (pose and twist, with the plugin's frame names)."""
    return controller_of(world, entity).odometry()


def controller_of(world: World, entity: str) -> DriveController:
    """The entity's drive controller, created on first use.

    Raises:
        EntityNotFoundError, InvalidRequestError: see `drive`.
    """
    with world.lock, _GUARD:
        found = world.entity(entity)  # raises EntityNotFoundError
        controllers = _CONTROLLERS.setdefault(world, {})
        controller = controllers.get(entity)
        if controller is not None and found is controller.entity_record:
            return controller
        cls, record = _drive_of(world, entity)
        if controller is not None:
            controller.stop()  # an entity respawned under the same name
        controller = cls(world, entity, record)
        controller.entity_record = found
        controllers[entity] = controller
        return controller


def _drive_of(world: World, entity: str) -> tuple[type[DriveController], Any]:
    """The controller class and the record of the entity's first drive.

    Raises:
        EntityNotFoundError: no such entity. InvalidRequestError: it has no drive.
    """
    drives = [p for p in world.entity(entity).plugins if type(p).__name__ in CONTROLLERS]
    if not drives:
        raise _no_drive(world, entity)
    return CONTROLLERS[type(drives[0]).__name__], drives[0]


def _no_drive(world: World, entity: str) -> InvalidRequestError:
    """The error for an entity without a drive; its fix names only what works for it."""
    rows = world.joint_commands(entity)
    wheels = [j for j, row in rows.items() if "velocity" in row["modes"]]
    held = [j for j, row in rows.items() if "position" in row["modes"]]
    if wheels:
        fix = (
            f"drive its joints one by one, e.g. twin command {entity} {wheels[0]}=2 --mode "
            "velocity (rad/s), or give it a drive <plugin>"
        )
    elif held:  # joints a gz-sim position or trajectory controller owns
        fix = (
            f"move its joints, e.g. twin command {entity} {held[0]}=0.5 --mode position (rad "
            f"or m), or send a trajectory with twin trajectory {entity} FILE"
        )
    else:
        fix = "give it a drive <plugin> (in its URDF's <gazebo> or its SDF <model>); it has no "
        fix += "joint to command"
    return InvalidRequestError(f"entity [{entity}]", f"has no drive plugin ({DRIVE_NAMES})", fix)


def _check_options(entity: str, cls: type[DriveController], record: Any, twist: Twist) -> None:
    """Refuses options the entity's drive does not take, naming the ones it does."""
    family = record.family
    steered = issubclass(cls, SteeredDriveController)
    if not steered and (twist.steering is not None or twist.curvature is not None):
        raise InvalidRequestError(
            f"drive of [{entity}] ({family})",
            "--steering/--curvature are for steered bases (Ackermann, tricycle)",
            "give a yaw rate with --angular",
        )
    if steered and twist.steering is not None and twist.curvature is not None:
        raise InvalidRequestError(
            f"drive of [{entity}] ({family})",
            "takes --steering or --curvature, not both",
            "give one of them",
        )
    if steered and twist.angular and (twist.steering is not None or twist.curvature is not None):
        raise InvalidRequestError(
            f"drive of [{entity}] ({family})",
            "takes a yaw rate (--angular) or a steering angle/curvature, not both",
            "give one of them",
        )
    if twist.lateral and not issubclass(cls, HolonomicController):
        raise InvalidRequestError(
            f"drive of [{entity}] ({family})",
            "cannot move sideways (--lateral is for planar move and mecanum bases)",
            "drive it with --linear and --angular",
        )


def _check_finite(what: str, value: float, unit: str) -> None:
    if not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InvalidRequestError(
            f"drive {what} velocity", f"{value!r} is not a finite number", f"give one in {unit}"
        )
