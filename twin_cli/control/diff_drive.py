"""One entity's diff drive: gazebo_ros_diff_drive run as a twin controller in sim time.

The controller is a world observer (`World.add_observer`) at the plugin's update rate (at
least MIN_RATE), so the stepping loop calls it between batches, in simulated time, with the
world's lock held: no Python per physics step. Each update it ramps the wheels' rim speeds
towards the commanded twist (`kinematics.ramp`, the plugin's `max_wheel_acceleration`),
writes them as velocity targets through the world's joint command API (a velocity servo whose
force is capped at the wheel motor's ±`max_wheel_torque`, Gazebo's `fmax`), stops the wheels
once the command's duration ran out, and integrates encoder odometry when the plugin asks.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from twin_cli.control.kinematics import Pose2D, body_twist, integrate_encoders, ramp, rim_speeds

if TYPE_CHECKING:
    from converters.gazebo.plugins import DiffDrive
    from twin_cli.world.engine import World
    from twin_cli.world.entities import Entity

FALLBACK_RATE = 100.0  # [Hz] for update_rate 0 ("every step" in Gazebo): no per-step Python
MIN_RATE = 250.0
"""[Hz] slowest controller rate. The world's velocity servo reaches full effort at 1 rad/s of
error, and a wheel of a light robot has tiny inertia (turtlebot3: 2e-5 kg m²): measured, at the
plugin's 30 Hz each ramp step (1 rad/s) saturated the 10 N m motor and the wheels ran away to
175 rad/s; at 100 Hz they held their targets but the robot reared up on each step; at 250 Hz the
start is smooth (heading within 4 % of the unicycle's after 5 s). The acceleration limit is applied
per elapsed sim time, so it is the plugin's at any rate."""


class DiffDriveController:
    """Drives one entity's wheels from (v, ω) commands; reports its odometry.

    Args:
        world: the `twin_cli.world.World` (its lock is re-entrant; callbacks hold it).
        entity: entity name; plugin: its `converters.gazebo.plugins.DiffDrive` record.
    """

    def __init__(self, world: World, entity: str, plugin: DiffDrive) -> None:
        self.world, self.entity, self.plugin = world, entity, plugin
        self.radius = plugin.wheel_diameter / 2.0
        self.plugin_rate = plugin.update_rate if plugin.update_rate > 0 else FALLBACK_RATE
        self.rate = max(self.plugin_rate, MIN_RATE)
        self.target = (0.0, 0.0)  # commanded (v [m/s], ω [rad/s])
        self.until = math.inf  # [s] sim time the command stops at
        self.rims = (0.0, 0.0)  # rim speeds [m/s] written at the last update
        self.updates = 0
        self.entity_record: Entity | None = None  # the entity this controller was made for
        self._written: dict = {}  # the world's commands after our last write (reset clears them)
        self._start()
        self.handle = world.add_observer(self._update, self.rate)
        self.observed_rate = self.rate

    def _start(self) -> None:
        """Odometry frame = the entity's pose now (Gazebo's encoder odometry starts at zero)."""
        pose = self.world.get_pose(self.entity)
        self.encoder = Pose2D(pose.x, pose.y, pose.yaw)
        self.last_time = float(self.world.data.time)

    def command(self, linear: float, angular: float, duration: float | None) -> None:
        """Holds (v [m/s], ω [rad/s]) for `duration` [s] of sim time (None: until replaced)."""
        with self.world.lock:
            self.target = (linear, angular)
            now = float(self.world.data.time)
            self.until = math.inf if duration is None else now + duration
            self._observe_at(self.rate)  # ramping: the fast rate (see MIN_RATE)

    def _observe_at(self, rate: float) -> None:
        """Re-registers the update at `rate` [Hz] (no-op when already there)."""
        if rate != self.observed_rate:
            if self.observed_rate:
                self.world.remove_observer(self.handle)
            self.handle = self.world.add_observer(self._update, rate)
            self.observed_rate = rate

    def stop(self) -> None:
        """Stops calling the controller (entity deleted or world replaced); targets stay."""
        self.world.remove_observer(self.handle)
        self.observed_rate = 0.0

    def resume(self) -> None:
        """Calls the controller again after `stop` (at the fast rate until the wheels settle)."""
        with self.world.lock:
            self.last_time = float(self.world.data.time)
            self._observe_at(self.rate)

    # ------------------------------------------------------------------ the update
    def _update(self) -> None:
        """One plugin update (world lock held): odometry, ramp, wheel velocity targets."""
        if self.entity not in self.world.entity_names():
            self.stop()
            return
        now = float(self.world.data.time)
        if now < self.last_time:  # the world was reset: start over, wheels stopped
            self.target, self.until, self.rims = (0.0, 0.0), math.inf, (0.0, 0.0)
            self._start()
            return
        dt, self.last_time = now - self.last_time, now
        if self.plugin.odometry_source == "encoder" and dt > 0:
            speeds = self.wheel_speeds()
            left, right = float(np.mean(speeds[0])), float(np.mean(speeds[1]))
            self.encoder = integrate_encoders(
                self.encoder, left, right, self.radius, self.plugin.wheel_separation, dt
            )
        if now >= self.until - 1e-9:
            self.target, self.until = (0.0, 0.0), math.inf
        goals = rim_speeds(*self.target, self.plugin.wheel_separation)
        accel = self.plugin.max_wheel_acceleration
        rims = (ramp(self.rims[0], goals[0], accel, dt), ramp(self.rims[1], goals[1], accel, dt))
        if rims != self.rims or self.updates == 0 or self.world.commands() != self._written:
            self.rims = rims
            self._write()  # only on a change: a held command costs the loop no writes
        self.updates += 1
        # Wheels at their goal: the plugin's own rate is enough for timeouts and odometry.
        self._observe_at(self.rate if rims != goals else self.plugin_rate)

    def _write(self) -> None:
        """Writes the rim speeds as wheel velocity targets (through the world's command API)."""
        sides = ((self.plugin.left_joints, self.rims[0]), (self.plugin.right_joints, self.rims[1]))
        for joints, rim in sides:
            for joint in joints:
                self.world.command(self.entity, joint, mode="velocity", value=rim / self.radius)
        self._written = dict(self.world.commands())

    def wheel_speeds(self) -> tuple[list[float], list[float]]:
        """Left and right wheel joint speeds [rad/s] now (world lock held)."""
        m, d = self.world.model, self.world.data

        def speed(joint: str) -> float:
            j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{self.entity}/{joint}")
            return float(d.qvel[m.jnt_dofadr[j]]) if j >= 0 else 0.0

        return (
            [speed(j) for j in self.plugin.left_joints],
            [speed(j) for j in self.plugin.right_joints],
        )

    # ------------------------------------------------------------------ odometry
    def odometry(self) -> dict[str, Any]:
        """nav_msgs/Odometry's content: pose in the odom frame, twist in the base frame."""
        with self.world.lock:
            if self.plugin.odometry_source == "encoder":
                return self._encoder_odometry()
            return self._world_odometry()

    def _encoder_odometry(self) -> dict[str, Any]:
        left, right = self.wheel_speeds()
        v, w = body_twist(
            float(np.mean(left)), float(np.mean(right)), self.radius, self.plugin.wheel_separation
        )
        pose = self.encoder
        return self._message(
            [pose.x, pose.y, 0.0], [0.0, 0.0, pose.theta], [v, 0.0, 0.0], [0.0, 0.0, w]
        )

    def _world_odometry(self) -> dict[str, Any]:
        pose = self.world.get_pose(self.entity)
        ix = self.world.index_of(self.entity)
        linear, angular = [0.0] * 3, [0.0] * 3
        if ix.free_qpos >= 0:
            d, dof = self.world.data, int(ix.dofs[0])
            quat = d.qpos[ix.free_qpos + 3 : ix.free_qpos + 7]
            rot = np.empty(9)
            mujoco.mju_quat2Mat(rot, quat)
            # free joint: linear velocity in the world frame, angular in the body frame
            linear = (rot.reshape(3, 3).T @ d.qvel[dof : dof + 3]).tolist()
            angular = d.qvel[dof + 3 : dof + 6].tolist()
        return self._message(
            [pose.x, pose.y, pose.z], [pose.roll, pose.pitch, pose.yaw], linear, angular
        )

    def _message(self, position: list, rpy: list, linear: list, angular: list) -> dict[str, Any]:
        return {
            "entity": self.entity,
            "plugin": self.plugin.name,
            "time": float(self.world.data.time),
            "source": self.plugin.odometry_source,
            "pose": {"position": position, "rpy": rpy},
            "twist": {"linear": linear, "angular": angular},
            "command": {"linear": self.target[0], "angular": self.target[1]},
        }
