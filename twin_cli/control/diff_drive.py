"""One entity's differential drive, run as a twin controller in sim time.

gazebo_ros' diff drive and skid steer, gz-sim's DiffDrive, ros2_control's diff_drive_controller
and vendor diff drives share one open-loop rule: each update ramps the wheels' rim speeds
v ∓ ω·b/2 towards the command (`kinematics.ramp`, the plugin's `max_wheel_acceleration`; gz-sim's
DiffDrive bounds the change of v and of ω instead, `kinematics.limit_change`), b the
plugin's wheel separation (times the controller's `wheel_separation_multiplier`, already in the
record), and writes them over the radius as velocity targets through the world's joint command
API (a velocity servo whose force is capped at the wheel motor's ±`max_wheel_torque`, Gazebo's
`fmax`). gz-sim's speed limits clip the twist first. No plugin reads the base's true heading, and
neither does this controller. A skid steer's wheels are two sides of one diff drive, as its
plugin treats them: it turns as its wheels' friction lets it, about ω/(1 + (a/c)²) under Coulomb
friction (a half the wheel base, c half the track), and its users correct that with the
controller's `wheel_separation_multiplier`, as on the real robot.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from twin_cli.control.drive_base import DriveController
from twin_cli.control.kinematics import body_twist, limit_change, ramp, rim_speeds, signed_bounds

if TYPE_CHECKING:
    from converters.gazebo.drive_records import DiffDrive
    from twin_cli.world.engine import World

# Drive families whose odometry integrates the wheels' joint positions (the others their speeds).
POSITION_ENCODERS = ("gz_", "diff_drive_controller")


class DiffDriveController(DriveController):
    """Drives one entity's wheels from (v, ω) commands; reports its odometry.

    Args:
        world: the `twin_cli.world.World`; entity: entity name; plugin: its `DiffDrive` record.
    """

    plugin: DiffDrive

    def __init__(self, world: World, entity: str, plugin: DiffDrive) -> None:
        self.radius = plugin.wheel_diameter / 2.0
        self.rims = (0.0, 0.0)  # rim speeds [m/s] the ramp has reached and last wrote
        self.limited = (0.0, 0.0)  # the twist (v, ω) a twist-limiting plugin last allowed
        super().__init__(world, entity, plugin)

    def goal_twist(self) -> tuple[float, float]:
        """The commanded (v [m/s], ω [rad/s]) after the plugin's speed limits."""
        p = self.plugin
        lows = p.min_velocities or (-p.max_linear_velocity, -p.max_angular_velocity)
        return (
            min(max(self.twist.linear, lows[0]), p.max_linear_velocity),
            min(max(self.twist.angular, lows[1]), p.max_angular_velocity),
        )

    def goals(self) -> tuple[float, float]:
        """The commanded rim speeds [m/s], after the plugin's speed limits."""
        return rim_speeds(*self.goal_twist(), self.plugin.wheel_separation)

    @property
    def separation(self) -> float:
        """The track [m] the wheels are driven and read with: the plugin's."""
        return self.plugin.wheel_separation

    def _reset_targets(self) -> None:
        self.rims = (0.0, 0.0)
        self.limited = (0.0, 0.0)

    def _apply(self, dt: float, force: bool) -> None:
        bounds = self.plugin.twist_acceleration
        if bounds is None:
            goals = self.goals()
            accel = self.plugin.max_wheel_acceleration
            rims = (
                ramp(self.rims[0], goals[0], accel, dt),
                ramp(self.rims[1], goals[1], accel, dt),
            )
        else:  # the twist's speed limiters: v and ω each bounded on their own
            goal, last = self.goal_twist(), self.limited
            back = self.plugin.reverse_acceleration
            self.limited = (
                limit_change(last[0], goal[0], *signed_bounds(last[0], bounds[:2], back, 0), dt),
                limit_change(last[1], goal[1], *signed_bounds(last[1], bounds[2:], back, 2), dt),
            )
            rims = rim_speeds(*self.limited, self.plugin.wheel_separation)
        if rims != self.rims or force:  # a held command costs nothing
            self.rims = rims
            targets = {j: rims[0] / self.radius for j in self.plugin.left_joints}
            targets.update({j: rims[1] / self.radius for j in self.plugin.right_joints})
            self._write(targets, "velocity")

    def wheel_speeds(self) -> tuple[list[float], list[float]]:
        """Left and right wheel joint speeds [rad/s] now (world lock held)."""
        return (
            [self.joint_speed(j) for j in self.plugin.left_joints],
            [self.joint_speed(j) for j in self.plugin.right_joints],
        )

    def _start(self) -> None:
        super()._start()
        self.angles = self.wheel_angles()

    def wheel_angles(self) -> tuple[float, float]:
        """The mean left and right wheel joint angles [rad] now (world lock held)."""
        p = self.plugin
        left = sum(self.joint_position(j) for j in p.left_joints) / len(p.left_joints)
        right = sum(self.joint_position(j) for j in p.right_joints) / len(p.right_joints)
        return left, right  # plain sums: numpy's mean cost 4x a step at every update

    def _encoder_motion(self, dt: float) -> tuple[float, float]:
        """gz-sim's DiffDrive and ros2_control's diff_drive_controller measure how far the wheels
        turned since the last update (their joint positions), so their odometry holds at any
        update rate; gazebo_ros' plugins sample
        the wheels' speeds. Measured on gz-sim bases' 1.2 m turns: 6-7 mm from the world pose
        from positions, 8-9 mm from sampled speeds."""
        if not self.plugin.family.startswith(POSITION_ENCODERS):
            return super()._encoder_motion(dt)
        angles = self.wheel_angles()
        (left0, right0), self.angles = self.angles, angles
        distance, turn = body_twist(
            angles[0] - left0, angles[1] - right0, self.radius, self.separation
        )
        return distance, turn

    def _encoder_twist(self) -> tuple[float, float]:
        left, right = self.wheel_speeds()
        mean_left, mean_right = sum(left) / len(left), sum(right) / len(right)
        return body_twist(mean_left, mean_right, self.radius, self.separation)

    def command_reply(self) -> dict[str, Any]:
        left, right = self.goals()
        return {"wheel_speeds": {"left": left / self.radius, "right": right / self.radius}}
