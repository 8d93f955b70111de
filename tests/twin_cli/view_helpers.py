"""What the viewer tests need from the machine: Debian's chromium and offscreen EGL, detected."""

from __future__ import annotations

import functools
import math
import os
import shutil
import subprocess
import sys

import numpy as np

CHROMIUM = "/usr/bin/chromium"
# Headless, no GPU (WebGL through SwiftShader), nothing fetched from the network.
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
]


def twin_in(world: str, *args: str) -> subprocess.CompletedProcess:
    """`twin ARGS --world WORLD` as a user runs it: a fresh process, output captured."""
    return subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", world],
        capture_output=True,
        text=True,
        timeout=120,
        env=os.environ.copy(),
    )


@functools.cache
def chromium_missing() -> str | None:
    """Why the browser tests cannot run here, or None."""
    if not (os.access(CHROMIUM, os.X_OK) or shutil.which("chromium")):
        return "no Chromium: install Debian's `chromium` package (.ci/run does)"
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "no playwright: pip install -e '.[test]'"
    return None


@functools.cache
def egl_missing() -> str | None:
    """Why offscreen rendering cannot run here (a 8×8 mujoco.Renderer in a child), or None."""
    code = (
        "import mujoco; m = mujoco.MjModel.from_xml_string('<mujoco/>'); "
        "mujoco.Renderer(m, 8, 8).render()"
    )
    env = {**os.environ, "MUJOCO_GL": "egl"}
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    if proc.returncode != 0:
        return "no offscreen EGL: install libegl-mesa0 and libgl1-mesa-dri (.ci/run does)"
    return None


def red_box(size: float = 0.4, name: str = "box") -> str:
    """A free red cube of edge `size` [m], 1 kg, with a visual in pure red (1 0 0)."""
    i = size * size / 6.0
    return f"""<robot name="{name}"><link name="{name}">
  <inertial><mass value="1"/>
    <inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>
  <visual><geometry><box size="{size} {size} {size}"/></geometry>
    <material name="red"><color rgba="1 0 0 1"/></material></visual>
  <collision><geometry><box size="{size} {size} {size}"/></geometry></collision>
</link></robot>"""


def pure_red(pixels: np.ndarray) -> np.ndarray:
    """Mask of pixels lit from a (1, 0, 0) surface: red, with green and blue < 8 % of it
    (the humanoid's shirt, 0.8 0.2 0.2, has 25 %)."""
    rgb = pixels[..., :3].astype(float)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return (r > 40) & (g < 0.08 * r) & (b < 0.08 * r)


def project(points: np.ndarray, camera: dict) -> np.ndarray:
    """Pixel (u, v) of world points [m] through a pinhole free camera (MuJoCo's convention:
    azimuth/elevation [deg] of the view direction, vertical field of view `fovy`)."""
    az, el = math.radians(camera["azimuth"]), math.radians(camera["elevation"])
    forward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    eye = np.asarray(camera["lookat"]) - camera["distance"] * forward
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = np.asarray(points) - eye
    x, y, z = d @ right, d @ up, d @ forward
    w, h = camera["width"], camera["height"]
    focal = (h / 2) / math.tan(math.radians(camera["fovy"]) / 2)
    return np.stack([w / 2 + focal * x / z, h / 2 - focal * y / z], axis=1)


def box_corners(centre: tuple[float, float, float], yaw: float, size: float) -> np.ndarray:
    """The 8 corners [m] of a cube of edge `size` at `centre`, turned by `yaw` [rad]."""
    c, s = math.cos(yaw), math.sin(yaw)
    half = size / 2
    signs = (-half, half)
    local = np.array([[x, y, z] for x in signs for y in signs for z in signs])
    turn = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return local @ turn.T + np.asarray(centre)
