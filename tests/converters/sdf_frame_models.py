"""Hand composition of SDF poses and read-back of compiled models, for the SDF frame tests.

A pose `x y z roll pitch yaw` has R = Rz(yaw)·Ry(pitch)·Rx(roll) (extrinsic X-Y-Z rotations,
SDFormat's and URDF's convention). `X` builds the 4×4 transform of such a pose so that tests
compose expected poses from a file's numbers, never from twin. At qpos0 a model's frame is
MuJoCo's world frame, so `body_pose`/`site_pose` read model-frame poses.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np

from converters import convert

TOL_M = 1e-9  # [m] positions
TOL_R = 1e-9  # rotation-matrix entries and unit axes
HALF_PI = math.pi / 2
HP = repr(HALF_PI)  # π/2 as written in the files, to 17 digits
INERTIAL = (
    "<inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz>"
    "</inertia></inertial>"
)
LIMIT = "<limit><lower>-1</lower><upper>1</upper></limit>"


# --- hand composition --------------------------------------------------------------------
def Rx(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def Ry(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def Rz(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def X(x: float, y: float, z: float, roll: float = 0, pitch: float = 0, yaw: float = 0):
    """The 4×4 transform an SDF `<pose>x y z roll pitch yaw</pose>` stands for."""
    T = np.eye(4)
    T[:3, :3] = Rz(yaw) @ Ry(pitch) @ Rx(roll)
    T[:3, 3] = (x, y, z)
    return T


def text_of(T: np.ndarray) -> str:
    """`x y z roll pitch yaw` of a transform (no gimbal lock), each to 17 digits."""
    R = T[:3, :3]
    rpy = (math.atan2(R[2, 1], R[2, 2]), math.asin(-R[2, 0]), math.atan2(R[1, 0], R[0, 0]))
    return " ".join(repr(float(v)) for v in (*T[:3, 3], *rpy))


# --- conversion and read-back ------------------------------------------------------------
def write(tmp_path: Path, body: str, version: str = "1.8", name: str = "frames.sdf") -> Path:
    path = tmp_path / name
    path.write_text(f'<?xml version="1.0"?>\n<sdf version="{version}">\n{body}\n</sdf>\n')
    return path


def kinematics(path: Path) -> tuple[mujoco.MjModel, mujoco.MjData]:
    spec, _ = convert(path)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return model, data


def link(name: str, pose: str | None = None, relative_to: str | None = None) -> str:
    attribute = "" if relative_to is None else f' relative_to="{relative_to}"'
    written = "" if pose is None else f"<pose{attribute}>{pose}</pose>"
    return f'<link name="{name}">{written}{INERTIAL}</link>'


def body_pose(model: mujoco.MjModel, data: mujoco.MjData, name: str) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = data.xmat[model.body(name).id].reshape(3, 3)
    T[:3, 3] = data.xpos[model.body(name).id]
    return T


def site_pose(model: mujoco.MjModel, data: mujoco.MjData, name: str) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = data.site_xmat[model.site(name).id].reshape(3, 3)
    T[:3, 3] = data.site_xpos[model.site(name).id]
    return T


def assert_pose(actual: np.ndarray, expected: np.ndarray, what: str) -> None:
    np.testing.assert_allclose(
        actual[:3, 3], expected[:3, 3], rtol=0, atol=TOL_M, err_msg=f"{what}: position [m]"
    )
    np.testing.assert_allclose(
        actual[:3, :3], expected[:3, :3], rtol=0, atol=TOL_R, err_msg=f"{what}: rotation matrix"
    )


def assert_joint(model, data, name: str, anchor, axis) -> None:
    joint = model.joint(name).id
    np.testing.assert_allclose(
        data.xanchor[joint], anchor, rtol=0, atol=TOL_M, err_msg=f"joint {name}: anchor [m]"
    )
    np.testing.assert_allclose(
        data.xaxis[joint], axis, rtol=0, atol=TOL_R, err_msg=f"joint {name}: axis (unit)"
    )


def site_body(model: mujoco.MjModel, name: str) -> str:
    return model.body(model.site_bodyid[model.site(name).id]).name
