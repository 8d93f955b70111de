"""SDFormat nested models (1.8), includes and model frames, against poses composed by hand.

A nested model is placed relative to its parent's model frame (or `relative_to` a frame of the
parent scope), its links, joints and frames are named with `::` scopes, `__model__` inside it is
its own frame, and the parent reaches into it with `::` (1.8). The model frame is attached to
`canonical_link`, by default the first link, or with no direct link the first nested model's
frame (1.8); `placement_frame` (1.8) makes `<pose>` place that frame instead of the model frame.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from sdf_frame_models import (
    HALF_PI,
    HP,
    INERTIAL,
    LIMIT,
    Ry,
    Rz,
    X,
    assert_joint,
    assert_pose,
    body_pose,
    kinematics,
    link,
    site_body,
    site_pose,
    write,
)

NESTED = f"""<model name="robot">
  <link name="base"><pose>0 0 0.5 0 0 {HP}</pose>{INERTIAL}</link>
  <model name="arm">
    <pose relative_to="base">1 0 0 0 0 0</pose>
    <link name="upper"><pose>0 0 0.2 0 0 0</pose>{INERTIAL}</link>
    <link name="lower"><pose relative_to="upper">0.3 0 0 0 {HP} 0</pose>{INERTIAL}</link>
    <joint name="elbow" type="revolute"><parent>upper</parent><child>lower</child>
      <axis><xyz expressed_in="__model__">1 0 0</xyz>{LIMIT}</axis></joint>
    <frame name="tool" attached_to="lower"><pose>0 0 0.1 0 0 0</pose></frame>
    <model name="hand">
      <pose>0 0 0.4 0 0 0</pose>
      <link name="palm">{INERTIAL}</link>
      <link name="finger"><pose relative_to="__model__">0.05 0 0 0 0 0</pose>{INERTIAL}</link>
      <joint name="knuckle" type="revolute"><parent>palm</parent><child>finger</child>
        <axis><xyz>0 1 0</xyz>{LIMIT}</axis></joint>
    </model>
    <joint name="wrist" type="revolute"><parent>lower</parent><child>hand::palm</child>
      <axis><xyz>1 0 0</xyz>{LIMIT}</axis></joint>
  </model>
  <joint name="shoulder" type="revolute"><pose>0 0 -0.1 0 0 0</pose>
    <parent>base</parent><child>arm::upper</child><axis><xyz>1 0 0</xyz>{LIMIT}</axis></joint>
  <frame name="above_tool" attached_to="arm::lower">
    <pose relative_to="arm::tool">0 0 0.5 0 0 0</pose></frame>
  <frame name="arm_origin" attached_to="arm"/>
  <frame name="palm_marker"><pose relative_to="arm::hand::palm">0.05 0 0 0 0 0</pose></frame>
</model>"""


def test_nested_models_place_scoped_links_joints_and_frames(tmp_path: Path) -> None:
    model, data = kinematics(write(tmp_path, NESTED))
    yaw = Rz(HALF_PI)
    # arm = X_M_base·(1, 0, 0): (0, 0, 0.5) + Rz(90°)(1, 0, 0) = (0, 1, 0.5), Rz(90°).
    # arm::upper = arm·(0, 0, 0.2) = (0, 1, 0.7), Rz(90°).
    upper = X(0, 1, 0.7, 0, 0, HALF_PI)
    # arm::lower = upper·(0.3, 0, 0, pitch 90°): (0, 1, 0.7) + Rz(90°)(0.3, 0, 0) = (0, 1.3, 0.7);
    # R = Rz(90°)·Ry(90°).
    lower = np.eye(4)
    lower[:3, :3] = yaw @ Ry(HALF_PI)
    lower[:3, 3] = (0, 1.3, 0.7)
    # arm::hand = arm·(0, 0, 0.4) (relative to its parent's model frame) = (0, 1, 0.9), Rz(90°);
    # palm is at hand's frame; finger at hand·(0.05, 0, 0) = (0, 1.05, 0.9).
    palm = X(0, 1, 0.9, 0, 0, HALF_PI)
    finger = X(0, 1.05, 0.9, 0, 0, HALF_PI)
    for name, pose in (
        ("base", X(0, 0, 0.5, 0, 0, HALF_PI)),
        ("arm::upper", upper),
        ("arm::lower", lower),
        ("arm::hand::palm", palm),
        ("arm::hand::finger", finger),
    ):
        assert_pose(body_pose(model, data, name), pose, f"link {name}")
    # Joints at their child (default): shoulder 0.1 m below upper along its z, axis Rz(90°)x.
    assert_joint(model, data, "shoulder", anchor=(0, 1, 0.6), axis=(0, 1, 0))
    # elbow: at lower; its axis x of *arm's* model frame (__model__ inside arm):
    # Rz(90°)(1, 0, 0) = (0, 1, 0) (x of robot's frame would be (1, 0, 0), of the joint frame
    # Rz(90°)Ry(90°)(1, 0, 0) = (0, 0, -1)).
    assert_joint(model, data, "arm::elbow", anchor=(0, 1.3, 0.7), axis=(0, 1, 0))
    assert_joint(model, data, "arm::wrist", anchor=(0, 1, 0.9), axis=(0, 1, 0))
    # knuckle: at finger, axis Rz(90°)(0, 1, 0) = (-1, 0, 0).
    assert_joint(model, data, "arm::hand::knuckle", anchor=(0, 1.05, 0.9), axis=(-1, 0, 0))
    # arm::tool = lower·(0, 0, 0.1): Rz(90°)Ry(90°)(0, 0, 0.1) = Rz(90°)(0.1, 0, 0) = (0, 0.1, 0)
    # → (0, 1.4, 0.7). above_tool = tool·(0, 0, 0.5) → (0, 1.4 + 0.5, 0.7).
    tool = lower.copy()
    tool[:3, 3] = (0, 1.4, 0.7)
    above = lower.copy()
    above[:3, 3] = (0, 1.9, 0.7)
    # arm_origin: the nested model frame (0, 1, 0.5), attached to arm's canonical link upper.
    # palm_marker: palm·(0.05, 0, 0) = finger's pose, attached to robot's canonical link base.
    for name, pose, attached in (
        ("arm::tool", tool, "arm::lower"),
        ("above_tool", above, "arm::lower"),
        ("arm_origin", X(0, 1, 0.5, 0, 0, HALF_PI), "arm::upper"),
        ("palm_marker", finger, "base"),
    ):
        assert_pose(site_pose(model, data, name), pose, f"frame {name}")
        assert site_body(model, name) == attached, f"frame {name}: body it is attached to"


def test_model_frame_is_attached_to_the_canonical_link(tmp_path: Path) -> None:
    # //model/@canonical_link names the link the model frame (and frames left attached to
    # it) moves with; without it, the first link.
    named = (
        '<model name="m" canonical_link="L2">'
        + link("L1")
        + link("L2", "0 0 1 0 0 0")
        + f'<joint name="J" type="revolute"><parent>L1</parent><child>L2</child>'
        f"<axis><xyz>0 0 1</xyz>{LIMIT}</axis></joint>"
        '<frame name="F"><pose>0.5 0 0 0 0 0</pose></frame>'
        "</model>"
    )
    model, data = kinematics(write(tmp_path, named, name="canonical.sdf"))
    assert_pose(site_pose(model, data, "F"), X(0.5, 0, 0), "frame F (relative to the model)")
    assert site_body(model, "F") == "L2", "F is attached to the canonical link L2"


def test_model_without_links_is_attached_to_its_first_nested_model(tmp_path: Path) -> None:
    # 1.8 model.sdf canonical_link: "If the model has no direct /link children, it will instead
    # be attached to the first nested (or included) model's implicit frame."
    nested_only = (
        '<model name="robot">'
        '<model name="chassis"><pose>1 0 0 0 0 0</pose>' + link("body") + "</model>"
        '<frame name="marker"><pose>0 0 1 0 0 0</pose></frame>'
        "</model>"
    )
    model, data = kinematics(write(tmp_path, nested_only, name="nested_only.sdf"))
    assert_pose(body_pose(model, data, "chassis::body"), X(1, 0, 0), "link chassis::body")
    assert_pose(site_pose(model, data, "marker"), X(0, 0, 1), "frame marker")
    assert site_body(model, "marker") == "chassis::body", "marker: via chassis's model frame"


def test_placement_frame_sets_the_pose_of_a_frame_inside_the_nested_model(tmp_path: Path) -> None:
    # 1.8 //model/@placement_frame: <pose> gives the pose of that frame, not the model frame's.
    body = (
        '<model name="robot">'
        + link("base")
        + '<model name="arm" placement_frame="grip"><pose relative_to="base">0 0 1 0 0 0</pose>'
        + link("hand")
        + f'<frame name="grip" attached_to="hand"><pose>0.5 0 0 0 0 {HP}</pose></frame>'
        "</model>"
        '<joint name="mount" type="fixed"><parent>base</parent><child>arm::hand</child></joint>'
        "</model>"
    )
    model, data = kinematics(write(tmp_path, body))
    # X_M_grip = (0, 0, 1), so X_M_arm = X_M_grip·X_arm_grip⁻¹; X_arm_grip⁻¹ has R = Rz(-90°)
    # and p = -Rz(-90°)(0.5, 0, 0) = -(0, -0.5, 0) = (0, 0.5, 0): X_M_arm = (0, 0.5, 1), Rz(-90°).
    assert_pose(site_pose(model, data, "arm::grip"), X(0, 0, 1), "frame arm::grip")
    assert_pose(body_pose(model, data, "arm::hand"), X(0, 0.5, 1, 0, 0, -HALF_PI), "arm::hand")


def test_included_model_is_nested_with_its_name_and_pose(tmp_path: Path, monkeypatch) -> None:
    models = tmp_path / "models"
    (models / "gripper").mkdir(parents=True)
    (models / "gripper" / "model.config").write_text(
        '<?xml version="1.0"?>\n<model><name>gripper</name><sdf version="1.8">model.sdf</sdf>'
        "</model>\n"
    )
    (models / "gripper" / "model.sdf").write_text(
        '<?xml version="1.0"?>\n<sdf version="1.8"><model name="gripper">'
        + link("finger", "0 0 0.1 0 0 0")
        + '<frame name="pad" attached_to="finger"><pose>0.02 0 0 0 0 0</pose></frame>'
        "</model></sdf>\n"
    )
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(models))
    body = (
        '<model name="robot">'
        + link("base", "0 0 1 0 0 0")
        + "<include><uri>model://gripper</uri><name>left</name>"
        f'<pose relative_to="base">0.2 0 0 0 0 {HP}</pose></include>'
        '<joint name="mount" type="fixed"><parent>base</parent><child>left::finger</child></joint>'
        "</model>"
    )
    model, data = kinematics(write(tmp_path, body))
    # left = base·(0.2, 0, 0, yaw 90°) = (0.2, 0, 1); finger = left·(0, 0, 0.1) = (0.2, 0, 1.1);
    # pad = finger·(0.02, 0, 0) = (0.2, 0, 1.1) + Rz(90°)(0.02, 0, 0) = (0.2, 0.02, 1.1).
    assert_pose(body_pose(model, data, "left::finger"), X(0.2, 0, 1.1, 0, 0, HALF_PI), "finger")
    assert_pose(site_pose(model, data, "left::pad"), X(0.2, 0.02, 1.1, 0, 0, HALF_PI), "pad")
    assert site_body(model, "left::pad") == "left::finger", "pad is attached to the finger"


WRAPPED_STATIC = f"""<model name="wrapper">
  <link name="loose"><pose>0 0 1 0 0 0</pose>{INERTIAL}</link>
  <model name="shelf"><static>true</static>
    <link name="board"><pose>2 0 1 0 0 0</pose>{INERTIAL}</link></model>
</model>"""


def test_a_static_model_nested_in_a_moving_one_stays_put(tmp_path):
    # The AWS worlds wrap static furniture in non-static models; it fell and scattered.
    import mujoco

    model, data = kinematics(write(tmp_path, WRAPPED_STATIC, version="1.6"))
    mujoco.mj_step(model, data, nstep=500)  # 0.5 s of free fall for what is not static
    board, loose = model.body("shelf::board").id, model.body("loose").id
    assert np.allclose(data.xpos[board], [2.0, 0.0, 1.0], atol=1e-12), data.xpos[board]
    assert data.xpos[loose][2] < 1.0 - 0.5 * 9.8 * 0.5**2 * 0.9, "the rest still falls"
