"""A camera post and a red box for the camera and depth sensor tests, with their pinhole oracle.

The oracle: a red box 2 m ahead and 0.3 m to the left of a camera with horizontal field of view
1.0 rad projects, by the pinhole model (f = (W/2)/tan(hfov/2) px), to a known pixel rectangle.
"""

from __future__ import annotations

import math

import numpy as np

W, H, HFOV = 64, 48, 1.0  # [px], [px], [rad]
CAM_Z = 0.5  # [m] camera height
BOX = (2.0, 0.3, CAM_Z, 0.1)  # centre x, y, z and half size [m]

# Cameras like the two below with other <clip> planes [m] (the box's near face is 1.9 m ahead).
CLIPS = {"depth_short": ("depth", 0.05, 1.5), "depth_long": ("depth", 0.05, 3.0),
         "depth_near": ("depth", 2.5, 10.0), "cam_short": ("camera", 0.05, 1.5),
         "cam_near": ("camera", 2.5, 10.0)}  # fmt: skip
SENSOR = """<sensor type="{kind}" name="{name}"><pose>0 0 {z} 0 0 0</pose><camera>
    <horizontal_fov>{hfov}</horizontal_fov><image><width>{w}</width><height>{h}</height></image>
    <clip><near>{near}</near><far>{far}</far></clip></camera></sensor>"""
CLIPPED = "\n".join(
    SENSOR.format(kind=k, name=n, z=CAM_Z, hfov=HFOV, w=W, h=H, near=near, far=far)
    for n, (k, near, far) in CLIPS.items()
)

POST = f"""<robot name="campost">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <gazebo><static>true</static></gazebo>
  <gazebo reference="base">
  <sensor type="camera" name="cam"><pose>0 0 {CAM_Z} 0 0 0</pose><update_rate>30</update_rate>
    <camera><horizontal_fov>{HFOV}</horizontal_fov><image><width>{W}</width>
    <height>{H}</height></image><clip><near>0.05</near><far>50</far></clip></camera></sensor>
  <sensor type="depth" name="depth"><pose>0 0 {CAM_Z} 0 0 0</pose><update_rate>30</update_rate>
    <camera><horizontal_fov>{HFOV}</horizontal_fov><image><width>{W}</width>
    <height>{H}</height></image><clip><near>0.05</near><far>50</far></clip></camera></sensor>
  {CLIPPED}
  </gazebo>
</robot>"""


# The child's world: the camera post (URDF path `post`) and a red box at BOX (JSON `box`).
SCENE = """
x, y, z, h = json.loads(box)
world = World(WorldSettings(ground=False))
world.spawn(post, name="post")
box = mujoco.MjSpec(); box.modelname = "box"
box.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[h, h, h], pos=[x, y, z],
                       rgba=[1, 0, 0, 1])
world.spawn(box, name="box")
"""


def projection() -> tuple[float, float, float]:
    """Pixel column and row of the box's near-face centre, and its half width [px]."""
    f = (W / 2) / math.tan(HFOV / 2)
    x, y, _, h = BOX
    near = x - h
    u = W / 2 - f * y / near  # image x grows to the camera's right (−y)
    return u, H / 2, f * h / near


def red(rgb: np.ndarray) -> np.ndarray:
    """Where an RGB image is clearly red (the box)."""
    return (rgb[..., 0] > 2 * rgb[..., 1] + 20) & (rgb[..., 0] > 2 * rgb[..., 2] + 20)
