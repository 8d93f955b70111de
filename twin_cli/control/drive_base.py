"""What every drive controller shares: a world observer in sim time, the command's duration,
reset handling, encoder odometry integration and the nav_msgs/Odometry reply.

A controller is a world observer (`World.add_observer`) at the rate its plugin declares
(`update_rate`; 0, or a rate faster than the physics step: every step, as Gazebo runs a plugin
whose period is shorter than its step), so the stepping loop calls it between batches, in
simulated time, with the world's lock held, as often as Gazebo calls the plugin and no more. A
subclass says how a command becomes joint targets (`_apply`) and, for encoder odometry, the body
twist its wheels measure (`_encoder_twist`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from twin_cli.control.drive_names import reply_frames
from twin_cli.control.kinematics import Pose2D, integrate_twist

if TYPE_CHECKING:
    from twin_cli.world.engine import World
    from twin_cli.world.entities import Entity


STOP_SLACK = 0.5
"""Fraction of a step a command's end may pass unseen: data.time sums the step, so an update on
the end's instant reads it off by a rounding error that grows with the sum (1e-13 s at 5 s, 1e-9
s after an hour, 2e-8 s after a day at 1 ms); half a step holds at any sim time."""


def update_rate(declared: float, timestep: float) -> float:
    """The rate [Hz] a plugin that declares `declared` [Hz] updates at in a world stepped every
    `timestep` [s]: every step for 0 ("as fast as possible") or a period shorter than a step."""
    every_step = 1.0 / timestep
    return every_step if declared <= 0 else min(declared, every_step)


@dataclass(frozen=True)
class Twist:
    """A base command: forward speed `linear` [m/s], `lateral` [m/s] (holonomic bases), yaw
    rate `angular` [rad/s], or for steered bases a steering angle [rad] or a curvature [1/m]."""

    linear: float = 0.0
    angular: float = 0.0
    lateral: float = 0.0
    steering: float | None = None
    curvature: float | None = None


STOP = Twist()


class DriveController:
    """One entity's drive: commands in, joint targets out, odometry on request.

    Args:
        world: the `twin_cli.world.World` (its lock is re-entrant; callbacks hold it).
        entity: entity name; plugin: its record from `converters.gazebo.drive_records`.
    """

    def __init__(self, world: World, entity: str, plugin: Any) -> None:
        self.world, self.entity, self.plugin = world, entity, plugin
        self.rate = update_rate(plugin.update_rate, float(world.model.opt.timestep))
        self.twist = self._rest()
        self.until = math.inf  # [s] sim time the command stops at
        self.updates = 0
        self.entity_record: Entity | None = None  # the entity this controller was made for
        self._written: dict = {}  # the world's commands after our last write (reset clears them)
        self._model: mujoco.MjModel | None = None  # the model `_joints` was looked up in
        self._joints: dict[str, tuple[int, int]] = {}  # joint → (qpos, dof) address
        self._start()
        self.handle = world.add_observer(self._update, self.rate)
        self.observed_rate = self.rate

    # ------------------------------------------------------------------ subclass hooks
    def _rest(self) -> Twist:
        """The twist the plugin drives before any command and after a world reset: none."""
        return STOP

    def _reset_targets(self) -> None:
        """Forgets ramp state after a world reset (the world stopped the joints)."""

    def _apply(self, dt: float, force: bool) -> None:
        """Moves the targets towards the command by dt [s]; writes them when they changed (or
        `force`)."""
        raise NotImplementedError

    def _encoder_twist(self) -> tuple[float, float]:
        """(v [m/s], ω [rad/s]) the encoder wheels measure now."""
        raise NotImplementedError

    def _encoder_motion(self, dt: float) -> tuple[float, float]:
        """(distance [m], heading change [rad]) the encoders measured over the last `dt` [s]:
        the speeds now times dt, as gazebo_ros' plugins integrate them."""
        v, w = self._encoder_twist()
        return v * dt, w * dt

    def command_reply(self) -> dict[str, Any]:
        """What the command became (wheel and steering goals), for the drive reply."""
        return {}

    # ------------------------------------------------------------------ commands
    def _start(self) -> None:
        """Encoder odometry starts at zero, as every Gazebo drive's does: its odometry frame is
        the base's pose now (`origin`, in the world)."""
        pose = self.world.get_pose(self.entity)
        self.origin = Pose2D(pose.x, pose.y, pose.yaw)
        self.encoder = Pose2D(0.0, 0.0, 0.0)
        self.last_time = float(self.world.data.time)

    def command(self, twist: Twist, duration: float | None) -> None:
        """Holds `twist` for `duration` [s] of sim time (None: until replaced).

        Given between steps, the command reaches the plugin at its next update, as a cmd_vel
        does in Gazebo; its end is a stop that reaches it the same way, at the first update
        after `duration` has passed, so a plugin at any rate runs the command for `duration`
        (stopped at the update the duration ends on, a 10 Hz drive ran it 0.1 s short).
        """
        with self.world.lock:
            self.twist = twist
            now = float(self.world.data.time)
            self.until = math.inf if duration is None else now + duration

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
        """Calls the controller again after `stop`."""
        with self.world.lock:
            self.last_time = float(self.world.data.time)
            self._observe_at(self.rate)

    def _update(self) -> None:
        """One plugin update (world lock held): odometry, timeout, targets."""
        if self.entity not in self.world.entity_names() or (
            self.entity_record is not None
            and self.world.entity(self.entity) is not self.entity_record
        ):
            self.stop()  # deleted, or respawned under the same name: not this drive's robot
            return
        now = float(self.world.data.time)
        if now < self.last_time:  # the world was reset: start over, wheels stopped
            self.twist, self.until = self._rest(), math.inf
            self._reset_targets()
            self._start()
            return
        dt, self.last_time = now - self.last_time, now
        if self.plugin.odometry_source == "encoder" and dt > 0:
            self.encoder = integrate_twist(self.encoder, *self._encoder_motion(dt), 1.0)
        step = float(self.world.model.opt.timestep)
        if now > self.until + STOP_SLACK * step:  # the stop reaches the plugin as a cmd_vel would
            self.twist, self.until = STOP, math.inf
        force = self.updates == 0 or self.world.commands() != self._written
        self._apply(dt, force)
        self.updates += 1

    def _write(self, targets: dict[str, float], mode: str) -> None:
        """Writes joint targets through the world's joint command API (clipped to the joints'
        limits), and remembers the world's commands so a reset is noticed."""
        if targets:
            self.world.command_joints(self.entity, targets, mode=mode, clip=True)
        self._written = dict(self.world.commands())

    def joint_speed(self, joint: str) -> float:
        """A joint's speed [rad/s] now (world lock held); 0 for a joint the model lacks."""
        dof = self._addresses(joint)[1]
        return float(self.world.data.qvel[dof]) if dof >= 0 else 0.0

    def joint_position(self, joint: str) -> float:
        """A hinge joint's angle [rad] now (world lock held); 0 for a joint the model lacks."""
        qpos = self._addresses(joint)[0]
        return float(self.world.data.qpos[qpos]) if qpos >= 0 else 0.0

    def _addresses(self, joint: str) -> tuple[int, int]:
        """The joint's qpos and dof addresses in the world's model ((-1, -1): none), looked up
        once per compiled model (an update may run at every step)."""
        m = self.world.model
        if m is not self._model:
            self._model, self._joints = m, {}
        found = self._joints.get(joint)
        if found is None:
            j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{self.entity}/{joint}")
            found = (int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])) if j >= 0 else (-1, -1)
            self._joints[joint] = found
        return found

    # ------------------------------------------------------------------ odometry
    def odometry(self) -> dict[str, Any]:
        """nav_msgs/Odometry's content: pose in the odom frame, twist in the base frame."""
        with self.world.lock:
            if self.plugin.odometry_source == "encoder":
                v, w = self._encoder_twist()
                pose = self.encoder
                return self._message(
                    [pose.x, pose.y, 0.0], [0.0, 0.0, pose.theta], [v, 0.0, 0.0], [0.0, 0.0, w]
                )
            return self._world_odometry()

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
        t = self.twist
        odometry_frame, base_frame = reply_frames(self.entity, self.plugin)
        return {
            "entity": self.entity,
            "plugin": self.plugin.name,
            "family": self.plugin.family,
            "time": float(self.world.data.time),
            "source": self.plugin.odometry_source,
            "odometry_frame": odometry_frame,
            "robot_base_frame": base_frame,
            "pose": {"position": position, "rpy": rpy},
            "twist": {"linear": linear, "angular": angular},
            "command": {
                "linear": t.linear,
                "angular": t.angular,
                "lateral": t.lateral,
                "steering": t.steering,
                "curvature": t.curvature,
            },
        }
