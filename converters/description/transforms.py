"""Poses as 4×4 transforms from the forms description files write them in (both formats)."""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np


def pose_matrix(values: tuple[float, ...]) -> np.ndarray:
    """SDF `x y z roll pitch yaw` → 4×4 (R = Rz(yaw)·Ry(pitch)·Rx(roll), extrinsic X-Y-Z)."""
    x, y, z, roll, pitch, yaw = values
    cr, sr, cp, sp, cy, sy = (
        math.cos(roll),
        math.sin(roll),
        math.cos(pitch),
        math.sin(pitch),
        math.cos(yaw),
        math.sin(yaw),
    )
    T = np.eye(4)
    T[:3, :3] = [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
    T[:3, 3] = (x, y, z)
    return T


def quat_matrix(xyzw: tuple[float, ...]) -> np.ndarray:
    x, y, z, w = xyzw
    n = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def vec3(values: Iterable[float]) -> tuple[float, float, float]:
    """Three numbers (a point, a direction or a colour) as floats."""
    x, y, z = values
    return float(x), float(y), float(z)
