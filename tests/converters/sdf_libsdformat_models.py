"""SDF files for the libsdformat-semantics tests, and the read-back of a world's link poses.

`FRAMES_MODEL` and `PLACEMENT_WORLD` are libsdformat's own placement-frame test files
(`test_model_with_frames` and `placement_frame.sdf`, Apache-2.0), where every placement frame
lands at `PLACED`; `STAND` is a small model with a link and a frame to place.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

INERTIAL = (
    "<inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz>"
    "</inertia></inertial>"
)

FRAMES_MODEL = """<?xml version="1.0" ?>
<sdf version="1.7">
  <model name="test_model_with_frames">
    <frame name="F1"><pose>0 0 0 1.570796 0 0</pose></frame>
    <frame name="F2"><pose relative_to="F1">0 0 0 0 0.785398 0</pose></frame>
    <link name="L1"><pose relative_to="F1"/></link>
    <link name="L2"><pose relative_to="F1">1 0 0 0 0 0</pose></link>
    <link name="L3"><pose relative_to="L2">0 1 0 0 0 0</pose></link>
    <link name="L4"><pose relative_to="__model__">0 0 1 0 0 0</pose></link>
    <joint name="J1" type="universal">
      <pose relative_to="L1"/><parent>L1</parent><child>L2</child>
      <axis><xyz expressed_in="F2">0 0 1</xyz></axis>
      <axis2><xyz expressed_in="F2">1 0 0</xyz></axis2>
    </joint>
    <joint name="J2" type="revolute">
      <pose relative_to="">0 0 1 0 0 0</pose><parent>L2</parent><child>L3</child>
      <axis><xyz expressed_in="__model__">0 0 1</xyz></axis>
    </joint>
    <joint name="J3" type="fixed">
      <pose relative_to="__model__">1 0 1 0 0 0</pose><parent>L3</parent><child>L4</child>
    </joint>
    <model name="M2">
      <pose relative_to="F1">1 0 0 0 0 0</pose>
      <link name="L5"><pose>1 0 0 0 0 0</pose></link>
    </model>
  </model>
</sdf>
"""
FRAMES_CONFIG = """<?xml version="1.0"?>
<model><name>test_model_with_frames</name><sdf version="1.7">model.sdf</sdf></model>
"""

PLACED = "0 10 0 1.570796326794895 0 0"


def _include(name: str, placement: str | None, pose: str = f"<pose>{PLACED}</pose>") -> str:
    frame = "" if placement is None else f"<placement_frame>{placement}</placement_frame>"
    return f"<include><name>{name}</name><uri>test_model_with_frames</uri>{pose}{frame}</include>"


_RELATIVE = "<pose relative_to='frame_1'>1 0 0 0 0 0</pose>"
_FRAME_1 = f"<frame name='frame_1'><pose>-1 10 0 {PLACED.split(maxsplit=3)[3]}</pose></frame>"
_F = (
    '<frame name="F1"><pose>0 0 0 1.570796 0 0</pose></frame>'
    '<frame name="F2"><pose relative_to="F1">0 0 0 0 0.785398 0</pose></frame>'
    '<link name="L1"><pose relative_to="F1"/></link>'
)
PLACEMENT_WORLD = f"""<sdf version='1.8'>
<world name='default'>
  {_include("no_placement_frame", None)}
  {_include("placement_frame_using_link", "L4")}
  {_include("placement_frame_using_frame", "F2")}
  {_include("placement_frame_using_joint", "J2")}
  {_include("placement_frame_using_model", "__model__")}
  {_FRAME_1}
  {_include("include_with_placement_frame_and_pose_relative_to", "L4", _RELATIVE)}
  <model name='parent_model_include'>
    {_include("placement_frame_using_link", "L4")}
    {_include("placement_frame_using_frame", "F2")}
    {_include("placement_frame_using_joint", "J2")}
    {_FRAME_1}
    {_include("placement_frame_using_model", "__model__")}
    {_include("nested_include_with_placement_frame_and_pose_relative_to", "L4", _RELATIVE)}
  </model>
  <model name='model_with_link_placement_frame' placement_frame='L4'>
    <pose>{PLACED}</pose><link name='L4'><pose>0 0 1 0 0 0</pose></link>
  </model>
  <model name='model_with_model_placement_frame' placement_frame='__model__'>
    <pose>{PLACED}</pose><link name='L4'><pose>0 0 1 0 0 0</pose></link>
  </model>
  <model name='model_with_nested_model_placement_frame' placement_frame='nested_model'>
    <pose>{PLACED}</pose><link name='L4'><pose>0 0 1 0 0 0</pose></link>
    <model name ='nested_model'><link name='L4'><pose>0 0 1 0 0 0</pose></link></model>
  </model>
  <model name='model_with_frame_placement_frame' placement_frame='F2'>
    <pose>{PLACED}</pose>{_F}
  </model>
  <model name='model_with_joint_placement_frame' placement_frame='J2'>
    <pose>{PLACED}</pose>{_F}
    <link name="L2"><pose relative_to="F1">1 0 0 0 0 0</pose></link>
    <link name="L3"><pose relative_to="L2">0 1 0 0 0 0</pose></link>
    <joint name="J2" type="revolute">
      <pose relative_to="">0 0 1 0 0 0</pose><parent>L2</parent><child>L3</child>
    </joint>
  </model>
  <model name='model_with_placement_frame_and_pose_relative_to' placement_frame='L4'>
    {_RELATIVE}<link name='L4'><pose>0 0 1 0 0 0</pose></link>
  </model>
</world>
</sdf>
"""

# A stand: `body` 0.5 m above its model frame, `foot` 0.1 m along x turned 180° about z (welded
# to body), and frame `mark` 0.3 m above body, rolled 90°.
STAND = f"""<?xml version="1.0"?>
<sdf version="1.9"><model name="stand">
  <link name="body"><pose>0 0 0.5 0 0 0</pose>{INERTIAL}</link>
  <link name="foot"><pose>0.1 0 0 0 0 3.141592653589793</pose>{INERTIAL}</link>
  <joint name="weld" type="fixed"><parent>body</parent><child>foot</child></joint>
  <frame name="mark" attached_to="body"><pose>0 0 0.3 1.5707963267948966 0 0</pose></frame>
</model></sdf>
"""


def model_dir(root: Path, name: str, sdf: str, config_name: str | None = None) -> Path:
    """`root/name/` holding model.config and model.sdf; returns `root`."""
    directory = root / name
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "model.config").write_text(
        f'<?xml version="1.0"?>\n<model><name>{config_name or name}</name>'
        '<sdf version="1.9">model.sdf</sdf></model>\n'
    )
    (directory / "model.sdf").write_text(sdf)
    return root


def world_link_poses(world) -> dict[str, np.ndarray]:
    """'entity/link' → 4×4 world pose of every body of a loaded world, at its initial state."""
    model = world.model
    data = mujoco.MjData(model)
    data.qpos[:] = world.data.qpos
    mujoco.mj_kinematics(model, data)
    out = {}
    for body in range(1, model.nbody):
        T = np.eye(4)
        T[:3, :3] = data.xmat[body].reshape(3, 3)
        T[:3, 3] = data.xpos[body]
        out[model.body(body).name] = T
    return out
