"""One entity's differential drive, run as a twin controller in sim time.

gazebo_ros' diff drive and skid steer, gz-sim's DiffDrive and vendor diff drives share the rules
of gazebo_ros_diff_drive: each update ramps the wheels' rim speeds v ∓ ω·b/2 towards the command
(`kinematics.ramp`, the plugin's `max_wheel_acceleration`) and writes them as velocity targets
through the world's joint command API (a velocity servo whose force is capped at the wheel
motor's ±`max_wheel_torque`, Gazebo's `fmax`). gz-sim's speed limits clip the twist first. A skid
steer's four wheels are two sides of one diff drive, as its plugin treats them; a drive with
several wheels a side also trims their differential from the base's heading (`skid_trim`) and
softens their contacts while it turns (`skid_contacts`), so it turns as commanded.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from twin_cli.control.drive_base import STOP, DriveController
from twin_cli.control.kinematics import body_twist, ramp, rim_speeds
from twin_cli.control.skid_contacts import WheelContacts
from twin_cli.control.skid_trim import CHI_RANGE, SkidTrim

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
        self.rims = (0.0, 0.0)  # rim speeds [m/s] the ramp has reached
        self.written = (0.0, 0.0)  # rim speeds [m/s] written at the last update
        skids = len(set(plugin.left_joints)) > 1 or len(set(plugin.right_joints)) > 1
        self.trim: SkidTrim | None = None
        self.contacts: WheelContacts | None = None
        if skids:
            self.trim = SkidTrim(chi=_coulomb_chi(world, entity, plugin))
            self.contacts = WheelContacts(world, entity, plugin.left_joints + plugin.right_joints)
        super().__init__(world, entity, plugin)

    def goals(self) -> tuple[float, float]:
        """The commanded rim speeds [m/s], after the plugin's speed limits."""
        p = self.plugin
        v = _clip(self.twist.linear, p.max_linear_velocity)
        w = _clip(self.twist.angular, p.max_angular_velocity)
        return rim_speeds(v, w, p.wheel_separation)

    def stop(self) -> None:
        """Stops the controller; a turning skid steer's wheels get their rigid contacts back
        (a replaced model has them already)."""
        super().stop()
        if self.contacts:
            self.contacts.restore()

    @property
    def separation(self) -> float:
        """The track [m] the wheels are driven and read with: the plugin's, times the skid
        steer's learned multiplier χ."""
        chi = self.trim.chi if self.trim else 1.0
        return self.plugin.wheel_separation * chi

    def _reset_targets(self) -> None:
        self.rims = self.written = (0.0, 0.0)
        if self.trim and self.contacts:
            self.trim = SkidTrim(chi=_coulomb_chi(self.world, self.entity, self.plugin))
            self.contacts.restore()

    def _apply(self, dt: float, force: bool) -> bool:
        goals = self.goals()
        accel = self.plugin.max_wheel_acceleration
        self.rims = (
            ramp(self.rims[0], goals[0], accel, dt),
            ramp(self.rims[1], goals[1], accel, dt),
        )
        wheels, trimming = self._trimmed(self.rims, dt)
        if trimming and self.trim:  # the heading loop's corrections obey the acceleration too
            asked = wheels
            wheels = (
                ramp(self.written[0], asked[0], accel, dt),
                ramp(self.written[1], asked[1], accel, dt),
            )
            self.trim.learning = wheels == asked  # χ does not wind up while the bound binds
        if wheels != self.written or force:
            # written only on a change: a held command costs nothing (a skid steer's heading
            # loop changes them at each update while it moves)
            self.written = wheels
            targets = {j: wheels[0] / self.radius for j in self.plugin.left_joints}
            targets.update({j: wheels[1] / self.radius for j in self.plugin.right_joints})
            self._write(targets, "velocity")
        return self.rims == goals and not trimming

    def _trimmed(self, rims: tuple[float, float], dt: float) -> tuple[tuple[float, float], bool]:
        """The rim speeds to write for the ramped `rims`, and whether the heading loop runs (it
        then keeps the fast rate its gains are set for). Without a trim: `rims` as they are."""
        if self.trim is None or self.contacts is None:
            return rims, False
        b = self.plugin.wheel_separation
        v, omega = (rims[0] + rims[1]) / 2.0, (rims[1] - rims[0]) / b
        heading = self.world.get_pose(self.entity).yaw
        if rims == (0.0, 0.0) and self.twist == STOP:
            held = self.trim.hold(heading, dt)  # turned back to the commanded heading, briefly
            if held is None:
                self.contacts.restore()  # parked: rigid contacts hold it
                return rims, False
            return rim_speeds(0.0, held, b), True
        if omega != 0.0:
            self.contacts.soften()  # its wheels slide sideways (`skid_contacts`)
        else:
            self.contacts.restore()
        return rim_speeds(v, self.trim.update(omega, heading, dt), b), True

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
        left = [self.joint_position(j) for j in p.left_joints]
        right = [self.joint_position(j) for j in p.right_joints]
        return float(np.mean(left)), float(np.mean(right))

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
        return body_twist(float(np.mean(left)), float(np.mean(right)), self.radius, self.separation)

    def command_reply(self) -> dict[str, Any]:
        left, right = self.goals()
        reply: dict[str, Any] = {
            "wheel_speeds": {"left": left / self.radius, "right": right / self.radius}
        }
        if self.trim:
            reply["track_multiplier"] = self.trim.chi
        return reply


def _clip(value: float, limit: float) -> float:
    return value if math.isinf(limit) else max(-limit, min(limit, value))


def _coulomb_chi(world: World, entity: str, plugin: DiffDrive) -> float:
    """χ that Coulomb friction predicts for the wheels' layout, 1 + (a/c)², so that the loop
    starts there instead of learning it from 1. c is half the distance between the left and
    right wheels, a the wheels' mean distance from their centre along the base (exact for two
    axles of equal loads; a start for more). Measured at the wheel joints in the base's frame,
    on kinematics of the world's current posture (a fresh recompile has none computed yet)."""
    m = world.model
    d = mujoco.MjData(m)
    d.qpos[:] = world.data.qpos
    mujoco.mj_kinematics(m, d)
    root = world.index_of(entity).root
    rot = np.asarray(d.xmat[root]).reshape(3, 3)

    def local(joints: tuple[str, ...]) -> np.ndarray:
        found = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{entity}/{j}") for j in joints]
        return np.array(
            [rot.T @ (np.asarray(d.xanchor[j]) - np.asarray(d.xpos[root])) for j in found if j >= 0]
        ).reshape(-1, 3)

    left, right = local(plugin.left_joints), local(plugin.right_joints)
    if not len(left) or not len(right) or len(left) + len(right) < 3:
        return 1.0
    c = float(np.linalg.norm(left[:, :2].mean(axis=0) - right[:, :2].mean(axis=0))) / 2.0
    both = np.vstack([left, right])[:, :2]
    across = (right[:, :2].mean(axis=0) - left[:, :2].mean(axis=0)) / max(2.0 * c, 1e-12)
    along = np.array([across[1], -across[0]])  # the base's forward axis, normal to the axles' span
    a = float(np.abs((both - both.mean(axis=0)) @ along).mean())
    if not c > 0:
        return 1.0
    return min(max(1.0 + (a / c) ** 2, CHI_RANGE[0]), CHI_RANGE[1])
