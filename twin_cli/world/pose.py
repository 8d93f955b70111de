"""Poses in Gazebo's convention: position [m] plus roll, pitch, yaw [rad] (extrinsic X-Y-Z)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

Quat = tuple[float, float, float, float]


@dataclass(frozen=True)
class Pose:
    """A rigid pose in the world frame.

    Orientation is Gazebo's/SDF's roll-pitch-yaw: rotate about the fixed X axis by `roll`, then
    the fixed Y axis by `pitch`, then the fixed Z axis by `yaw` (R = Rz(yaw) Ry(pitch) Rx(roll)).

    Attributes:
        x, y, z: position [m].
        roll, pitch, yaw: orientation [rad].
    """

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0

    @classmethod
    def from_quat(cls, x: float, y: float, z: float, quat_wxyz: Iterable[float]) -> Pose:
        """Builds a pose from a position [m] and a unit quaternion (w, x, y, z)."""
        w, qx, qy, qz = (float(v) for v in quat_wxyz)
        norm = math.sqrt(w * w + qx * qx + qy * qy + qz * qz) or 1.0
        w, qx, qy, qz = w / norm, qx / norm, qy / norm, qz / norm
        roll = math.atan2(2.0 * (w * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy))
        sin_pitch = max(-1.0, min(1.0, 2.0 * (w * qy - qz * qx)))
        pitch = math.asin(sin_pitch)
        yaw = math.atan2(2.0 * (w * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
        return cls(float(x), float(y), float(z), roll, pitch, yaw)

    @classmethod
    def at(cls, position: Iterable[float], quat_wxyz: Iterable[float]) -> Pose:
        """Builds a pose from a position (x, y, z) [m] and a unit quaternion (w, x, y, z)."""
        x, y, z = position
        return cls.from_quat(x, y, z, quat_wxyz)

    def quat(self) -> Quat:
        """The orientation as a unit quaternion (w, x, y, z) = q_yaw * q_pitch * q_roll."""
        cr, sr = math.cos(self.roll / 2), math.sin(self.roll / 2)
        cp, sp = math.cos(self.pitch / 2), math.sin(self.pitch / 2)
        cy, sy = math.cos(self.yaw / 2), math.sin(self.yaw / 2)
        return (
            cy * cp * cr + sy * sp * sr,
            cy * cp * sr - sy * sp * cr,
            cy * sp * cr + sy * cp * sr,
            sy * cp * cr - cy * sp * sr,
        )

    def position(self) -> tuple[float, float, float]:
        """The position (x, y, z) [m]."""
        return (self.x, self.y, self.z)

    def to_dict(self) -> dict[str, float]:
        """A JSON-ready view: x, y, z [m], roll, pitch, yaw [rad]."""
        return {
            "x": self.x,
            "y": self.y,
            "z": self.z,
            "roll": self.roll,
            "pitch": self.pitch,
            "yaw": self.yaw,
        }


def vec3(values: Iterable[float]) -> tuple[float, float, float]:
    """Three numbers (a position or a vector, e.g. a row of a MuJoCo array) as floats."""
    x, y, z = values
    return float(x), float(y), float(z)


def quat4(values: Iterable[float]) -> Quat:
    """Four numbers (a quaternion w, x, y, z, e.g. a row of a MuJoCo array) as floats."""
    w, x, y, z = values
    return float(w), float(x), float(y), float(z)


def quat_multiply(a: Quat, b: Quat) -> Quat:
    """The Hamilton product a * b of two quaternions (w, x, y, z)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def rotate(q: Quat, v: tuple[float, float, float]) -> tuple[float, float, float]:
    """The vector `v` rotated by the unit quaternion `q` (w, x, y, z)."""
    w, x, y, z = quat_multiply(quat_multiply(q, (0.0, *v)), (q[0], -q[1], -q[2], -q[3]))
    del w
    return (x, y, z)


def check_finite(pose: Pose, subject: str) -> Pose:
    """Returns `pose` when every value is finite.

    Raises:
        InvalidRequestError: a NaN or infinite value (it would poison the world's state).
    """
    from twin_cli.errors import InvalidRequestError

    values = (pose.x, pose.y, pose.z, pose.roll, pose.pitch, pose.yaw)
    if not all(math.isfinite(v) for v in values):
        raise InvalidRequestError(subject, f"{values} is not finite", "give finite numbers")
    return pose
