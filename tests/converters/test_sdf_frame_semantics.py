"""SDFormat pose frame semantics (1.7+) for links and frames, against poses composed by hand.

The cases re-write, with our own numbers, the examples of SDFormat's "pose frame semantics"
proposal (sdformat.org, 1.7): a link's `<pose>` is relative to the model frame `__model__`, a
`<frame>`'s to the frame it is `attached_to` (itself `__model__`, so the canonical link, by
default), unless `<pose relative_to>` names another frame; `relative_to` fixes only the initial
pose, `attached_to` the link the frame moves with (a joint counts as its child link). A pose
`x y z roll pitch yaw` has R = Rz(yaw)·Ry(pitch)·Rx(roll). Each expected pose is composed from
the file's numbers (the arithmetic is in the comments), never read from twin.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest
from sdf_frame_models import (
    HALF_PI,
    HP,
    INERTIAL,
    LIMIT,
    TOL_M,
    TOL_R,
    Rx,
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
    text_of,
    write,
)


# --- poses and rotations -----------------------------------------------------------------
def test_pose_rotation_is_extrinsic_roll_then_pitch_then_yaw(tmp_path: Path) -> None:
    body = (
        '<model name="m"><static>true</static>'
        + link("quarter_turns", f"0.1 0.2 0.3 {HP} 0 {HP}")
        + link("general", "0 0 0 0.3 -0.7 1.1")
        + "</model>"
    )
    model, data = kinematics(write(tmp_path, body))
    # Rz(90°)·Rx(90°): Rx(90°) = [[1,0,0],[0,0,-1],[0,1,0]], Rz(90°) = [[0,-1,0],[1,0,0],[0,0,1]];
    # row by row Rz·Rx = [[0,0,1],[1,0,0],[0,1,0]] (intrinsic X-Y-Z, Rx·Rz, would give
    # [[0,-1,0],[0,0,-1],[1,0,0]]).
    quarter = np.eye(4)
    quarter[:3, :3] = [[0, 0, 1], [1, 0, 0], [0, 1, 0]]
    quarter[:3, 3] = (0.1, 0.2, 0.3)
    assert_pose(body_pose(model, data, "quarter_turns"), quarter, "link quarter_turns")
    # R = Rz(1.1)·Ry(-0.7)·Rx(0.3).
    general = np.eye(4)
    general[:3, :3] = Rz(1.1) @ Ry(-0.7) @ Rx(0.3)
    assert_pose(body_pose(model, data, "general"), general, "link general")


def test_pose_in_degrees_and_quaternions_from_1_9(tmp_path: Path) -> None:
    body = (
        '<model name="m"><static>true</static>'
        '<link name="degrees"><pose degrees="true">0 0 1 90 0 90</pose>' + INERTIAL + "</link>"
        '<link name="quat"><pose rotation_format="quat_xyzw">1 0 0 0 0 '
        f"{math.sin(math.pi / 4)!r} {math.cos(math.pi / 4)!r}</pose>" + INERTIAL + "</link>"
        "</model>"
    )
    model, data = kinematics(write(tmp_path, body, version="1.9"))
    # 90° 0 90° in degrees is the quarter-turn pose above: Rz(90°)·Rx(90°).
    assert_pose(body_pose(model, data, "degrees"), X(0, 0, 1, HALF_PI, 0, HALF_PI), "degrees")
    # (x y z w) = (0, 0, sin 45°, cos 45°) is a 90° turn about z.
    assert_pose(body_pose(model, data, "quat"), X(1, 0, 0, 0, 0, HALF_PI), "quat_xyzw")


def test_link_poses_default_to_the_model_frame_or_name_another_link(tmp_path: Path) -> None:
    # The proposal's `link_pose_relative_to` model, our numbers.
    body = (
        '<model name="m"><static>true</static>'
        + link("L1", f"1 2 0 0 0 {HP}")
        + link("L2", "0 0 3 0 0 0", relative_to="")
        + link("L3", "0.5 0 0.25 0 0 0", relative_to="L1")
        + link("L4", f"0 0 0 {HP} 0 0", relative_to="L3")
        + link("L5", "0 0 -1 0 0 0", relative_to="__model__")
        + "</model>"
    )
    model, data = kinematics(write(tmp_path, body))
    # L2: relative_to="" means the model frame: (0, 0, 3).
    assert_pose(body_pose(model, data, "L2"), X(0, 0, 3), "L2 (relative_to empty)")
    # L3 = X_M_L1·X_L1_L3: (1, 2, 0) + Rz(90°)(0.5, 0, 0.25) = (1, 2, 0) + (0, 0.5, 0.25)
    #    = (1, 2.5, 0.25), rotated Rz(90°).
    assert_pose(body_pose(model, data, "L3"), X(1, 2.5, 0.25, 0, 0, HALF_PI), "L3")
    # L4 = X_M_L3·X(roll 90°): same origin, R = Rz(90°)·Rx(90°).
    L4 = X(1, 2.5, 0.25, HALF_PI, 0, HALF_PI)
    assert_pose(body_pose(model, data, "L4"), L4, "L4 (chain L4 → L3 → L1 → M)")
    assert_pose(body_pose(model, data, "L5"), X(0, 0, -1), "L5 (relative_to __model__)")


def test_non_static_model_floats_from_its_root_link_pose(tmp_path: Path) -> None:
    body = '<model name="m">' + link("root", f"1 2 3 0 0 {math.pi / 3!r}") + "</model>"
    model, data = kinematics(write(tmp_path, body))
    joint = model.joint("floating_base")
    assert joint.type[0] == mujoco.mjtJoint.mjJNT_FREE, "floating_base is a free joint"
    assert model.body(model.jnt_bodyid[joint.id]).name == "root", "it moves the root link"
    qpos0 = model.qpos0[joint.qposadr[0] : joint.qposadr[0] + 7]
    # A 60° yaw is the quaternion (cos 30°, 0, 0, sin 30°) = (√3/2, 0, 0, 1/2).
    np.testing.assert_allclose(qpos0[:3], [1, 2, 3], atol=TOL_M, err_msg="qpos0 position [m]")
    quat = [math.sqrt(3) / 2, 0, 0, 0.5]
    sign = np.sign(qpos0[3])
    np.testing.assert_allclose(sign * qpos0[3:], quat, atol=TOL_R, err_msg="qpos0 quat (w x y z)")
    assert_pose(body_pose(model, data, "root"), X(1, 2, 3, 0, 0, math.pi / 3), "root at qpos0")


def test_static_model_welds_its_root_link_at_its_pose(tmp_path: Path) -> None:
    body = '<model name="m"><static>true</static>' + link("root", "1 2 3 0 0 0.5") + "</model>"
    model, data = kinematics(write(tmp_path, body))
    assert model.njnt == 0, "a static model has no joints"
    assert_pose(body_pose(model, data, "root"), X(1, 2, 3, 0, 0, 0.5), "welded root")


# --- frames --------------------------------------------------------------------------------
def test_frame_defaults_and_chains_of_frames(tmp_path: Path) -> None:
    # The proposal's `frame_attaching` and `frame_pose_relative_to` models, our numbers.
    body = (
        '<model name="m">'
        + link("L", f"1 0 0 0 0 {HP}")  # first link: the canonical link
        + link("L2", "0 0 2 0 0 0")
        + f'<joint name="J" type="revolute"><parent>L</parent><child>L2</child>'
        f"<axis><xyz>0 0 1</xyz>{LIMIT}</axis></joint>"
        '<frame name="F0"><pose>0 0 1 0 0 0</pose></frame>'
        '<frame name="F00" attached_to=""><pose>0 0 1 0 0 0</pose></frame>'
        '<frame name="F1" attached_to="L"><pose>0.5 0 0 0 0 0</pose></frame>'
        '<frame name="F2" attached_to="L"><pose relative_to="">0.5 0 0 0 0 0</pose></frame>'
        '<frame name="F3"><pose relative_to="L">0 0 0.2 0 0 0</pose></frame>'
        '<frame name="F4" attached_to="F1"><pose>0 0.3 0 0 0 0</pose></frame>'
        '<frame name="F5" attached_to="F4"><pose relative_to="F0">0.1 0 0 0 0 0</pose></frame>'
        '<frame name="FJ" attached_to="J"><pose>0 0 0.1 0 0 0</pose></frame>'
        '<frame name="FJ2" attached_to="FJ"><pose>0.2 0 0 0 0 0</pose></frame>'
        "</model>"
    )
    model, data = kinematics(write(tmp_path, body))
    yaw = HALF_PI
    expected = {
        # F0, F00: attached to __model__, pose relative to it: (0, 0, 1).
        "F0": (X(0, 0, 1), "L"),
        "F00": (X(0, 0, 1), "L"),
        # F1, F2: relative to L: (1, 0, 0) + Rz(90°)(0.5, 0, 0) = (1, 0.5, 0), Rz(90°).
        "F1": (X(1, 0.5, 0, 0, 0, yaw), "L"),
        "F2": (X(1, 0.5, 0, 0, 0, yaw), "L"),
        # F3: relative to L, attached to the model (so to L): (1, 0, 0.2), Rz(90°).
        "F3": (X(1, 0, 0.2, 0, 0, yaw), "L"),
        # F4 = F1·(0, 0.3, 0): (1, 0.5, 0) + Rz(90°)(0, 0.3, 0) = (1 - 0.3, 0.5, 0).
        "F4": (X(0.7, 0.5, 0, 0, 0, yaw), "L"),
        # F5: attached to F4 (so to L) but posed from F0: (0, 0, 1) + (0.1, 0, 0).
        "F5": (X(0.1, 0, 1), "L"),
        # FJ: a joint frame is its child's (L2 at (0, 0, 2)): (0, 0, 2.1), on L2.
        "FJ": (X(0, 0, 2.1), "L2"),
        "FJ2": (X(0.2, 0, 2.1), "L2"),
    }
    for name, (pose, attached) in expected.items():
        assert_pose(site_pose(model, data, name), pose, f"frame {name}")
        assert site_body(model, name) == attached, f"frame {name}: body it is attached to"


def test_spec_joint_frame_example_jp_jc(tmp_path: Path) -> None:
    # The proposal's example 1: P, C, J posed from P, and the frames Jp, Jc, Jc1, Jc2 at J.
    body = (
        '<model name="M">'
        + link("P", f"1 0 0.5 0 0 {HP}", relative_to="__model__")
        + link("C", f"0.4 0 0 {HP} 0 0", relative_to="P")
        + f'<joint name="J" type="revolute"><pose relative_to="P">0.2 0 0.1 0 {HP} 0</pose>'
        f"<parent>P</parent><child>C</child><axis><xyz>0 0 1</xyz>{LIMIT}</axis></joint>"
        '<frame name="Jp" attached_to="P"><pose relative_to="J"/></frame>'
        '<frame name="Jc" attached_to="C"><pose relative_to="J"/></frame>'
        '<frame name="Jc1" attached_to="J"><pose relative_to="J"/></frame>'
        '<frame name="Jc2" attached_to="J"/>'
        "</model>"
    )
    model, data = kinematics(write(tmp_path, body))
    # C = X_M_P·X_P_C: (1, 0, 0.5) + Rz(90°)(0.4, 0, 0) = (1, 0.4, 0.5); R = Rz(90°)·Rx(90°).
    assert_pose(body_pose(model, data, "C"), X(1, 0.4, 0.5, HALF_PI, 0, HALF_PI), "link C")
    # J = X_M_P·X_P_J: (1, 0, 0.5) + Rz(90°)(0.2, 0, 0.1) = (1, 0.2, 0.6); R = Rz(90°)·Ry(90°).
    X_M_J = np.eye(4)
    X_M_J[:3, :3] = Rz(HALF_PI) @ Ry(HALF_PI)
    X_M_J[:3, 3] = (1, 0.2, 0.6)
    # The axis z of J: Ry(90°)z = (1, 0, 0), then Rz(90°)(1, 0, 0) = (0, 1, 0).
    assert_joint(model, data, "J", anchor=(1, 0.2, 0.6), axis=(0, 1, 0))
    for name, attached in (("Jp", "P"), ("Jc", "C"), ("Jc1", "C"), ("Jc2", "C")):
        assert_pose(site_pose(model, data, name), X_M_J, f"frame {name} (at J)")
        assert site_body(model, name) == attached, f"frame {name}: body it is attached to"


def test_frame_moves_with_the_link_it_is_attached_to_not_its_relative_to(tmp_path: Path) -> None:
    # The proposal's `not_a_cycle` model: F1 attached to L2, posed from L1; L2 posed from F1.
    body = (
        '<model name="m">'
        + link("L1", f"0 1 0 0 0 {HP}")
        + '<frame name="F1" attached_to="L2"><pose relative_to="L1">1 0 0 0 0 0</pose></frame>'
        + link("L2", f"0 0 1 0 {HP} 0", relative_to="F1")
        + '<joint name="hinge" type="revolute"><parent>L1</parent><child>L2</child>'
        f"<axis><xyz>1 0 0</xyz>{LIMIT}</axis></joint>"
        "</model>"
    )
    model, data = kinematics(write(tmp_path, body))
    # F1 = X_M_L1·(1, 0, 0): (0, 1, 0) + Rz(90°)(1, 0, 0) = (0, 2, 0), Rz(90°).
    X_M_F1 = X(0, 2, 0, 0, 0, HALF_PI)
    assert_pose(site_pose(model, data, "F1"), X_M_F1, "frame F1")
    # L2 = X_M_F1·(0, 0, 1, pitch 90°): (0, 2, 0) + Rz(90°)(0, 0, 1) = (0, 2, 1);
    # R = Rz(90°)·Ry(90°).
    X_M_L2 = np.eye(4)
    X_M_L2[:3, :3] = Rz(HALF_PI) @ Ry(HALF_PI)
    X_M_L2[:3, 3] = (0, 2, 1)
    assert_pose(body_pose(model, data, "L2"), X_M_L2, "link L2")
    assert site_body(model, "F1") == "L2", "F1 is attached to L2"
    # Turning the hinge carries F1 with L2: F1 = X_M_L2(q)·X_L2_F1, X_L2_F1 = X_M_L2⁻¹·X_M_F1.
    data.qpos[model.joint("hinge").qposadr[0]] = 0.7
    mujoco.mj_kinematics(model, data)
    expected = body_pose(model, data, "L2") @ np.linalg.inv(X_M_L2) @ X_M_F1
    assert_pose(site_pose(model, data, "F1"), expected, "frame F1 after the hinge turned 0.7 rad")


def test_collision_and_visual_poses_relative_to_a_model_frame(tmp_path: Path) -> None:
    # The proposal's LED example: shapes of one link placed from frames of the model.
    box = "<geometry><box><size>0.01 0.01 0.001</size></box></geometry>"
    body = (
        '<model name="m"><static>true</static>'
        f'<frame name="led1" attached_to="leds"><pose>0.1 0 0 0 0 {HP}</pose></frame>'
        '<frame name="led2" attached_to="leds"><pose>-0.1 0 0 0 0 0</pose></frame>'
        f'<link name="leds"><pose>0 0 1 0 {HP} 0</pose>{INERTIAL}'
        f'<collision name="led1_collision"><pose relative_to="led1"/>{box}</collision>'
        f'<visual name="led1_visual"><pose relative_to="led1"/>{box}</visual>'
        f'<collision name="led2_collision"><pose relative_to="led2">0 0 0.01 0 0 0</pose>{box}'
        "</collision></link></model>"
    )
    model, data = kinematics(write(tmp_path, body))
    # leds at (0, 0, 1), Ry(90°) = [[0,0,1],[0,1,0],[-1,0,0]].
    # led1 = leds·(0.1, 0, 0, yaw 90°): (0, 0, 1) + Ry(90°)(0.1, 0, 0) = (0, 0, 0.9);
    # R = Ry(90°)·Rz(90°).
    led1 = np.eye(4)
    led1[:3, :3] = Ry(HALF_PI) @ Rz(HALF_PI)
    led1[:3, 3] = (0, 0, 0.9)
    # led2's collision = leds·(-0.1, 0, 0)·(0, 0, 0.01): (0, 0, 1) + Ry(90°)(-0.1, 0, 0.01)
    # = (0, 0, 1) + (0.01, 0, 0.1) = (0.01, 0, 1.1); R = Ry(90°).
    led2 = X(0.01, 0, 1.1, 0, HALF_PI, 0)
    geoms = {model.geom(g).name: g for g in range(model.ngeom)}
    shapes = [g for g in geoms if g.startswith("leds_")]
    assert len(shapes) == 3, f"three shapes: {sorted(geoms)}"
    for name, expected in zip(sorted(shapes), (led1, led2, led1), strict=True):
        g = geoms[name]
        pose = np.eye(4)
        pose[:3, :3] = data.geom_xmat[g].reshape(3, 3)
        pose[:3, 3] = data.geom_xpos[g]
        assert_pose(pose, expected, f"geom {name}")


# --- URDF-style kinematics written with relative_to (the proposal's "parity with URDF") ----
X_L1_J1 = X(0.3, 0.1, 0.2, 0.1, 0.2, 0.3)
X_L1_J2 = X(-0.2, 0.4, 0, 0, 0.5, -0.4)
X_L3_J3 = X(0, 0, 0.6, -0.3, 0, 1.0)


def _parity_joints(poses: dict[str, str]) -> str:
    out = ""
    for joint, parent, child in (
        ("joint1", "link1", "link2"),
        ("joint2", "link1", "link3"),
        ("joint3", "link3", "link4"),
    ):
        out += (
            f'<joint name="{joint}" type="revolute">{poses[joint]}<parent>{parent}</parent>'
            f"<child>{child}</child><axis><xyz>0 0 1</xyz>{LIMIT}</axis></joint>"
        )
    return out


URDF_PARITY = (
    '<model name="model">'
    + link("link1")
    + link("link2", "", relative_to="joint1")
    + link("link3", "", relative_to="joint2")
    + link("link4", "", relative_to="joint3")
    + _parity_joints(
        {
            "joint1": f'<pose relative_to="link1">{text_of(X_L1_J1)}</pose>',
            "joint2": f'<pose relative_to="link1">{text_of(X_L1_J2)}</pose>',
            "joint3": f'<pose relative_to="link3">{text_of(X_L3_J3)}</pose>',
        }
    )
    + "</model>"
)
FRAME_PARITY = (
    '<model name="model">'
    f'<frame name="joint1_frame" attached_to="link1"><pose>{text_of(X_L1_J1)}</pose></frame>'
    f'<frame name="joint2_frame" attached_to="link1"><pose>{text_of(X_L1_J2)}</pose></frame>'
    f'<frame name="joint3_frame" attached_to="link3"><pose>{text_of(X_L3_J3)}</pose></frame>'
    '<frame name="link2_frame" attached_to="joint1"/>'
    '<frame name="link3_frame" attached_to="joint2"/>'
    '<frame name="link4_frame" attached_to="joint3"/>'
    + link("link1")
    + link("link2", "", relative_to="link2_frame")
    + link("link3", "", relative_to="link3_frame")
    + link("link4", "", relative_to="link4_frame")
    + _parity_joints(
        {j: f'<pose relative_to="{j}_frame"/>' for j in ("joint1", "joint2", "joint3")}
    )
    + "</model>"
)


@pytest.mark.parametrize("body", [URDF_PARITY, FRAME_PARITY], ids=["relative_to", "frames"])
def test_urdf_kinematics_written_with_relative_to(tmp_path: Path, body: str) -> None:
    model, data = kinematics(write(tmp_path, body))
    # As URDF composes them: link2 = J1, link3 = J2, link4 = X_L1_J2·X_L3_J3 (link1 at M).
    expected = {"link2": X_L1_J1, "link3": X_L1_J2, "link4": X_L1_J2 @ X_L3_J3}
    for name, pose in expected.items():
        assert_pose(body_pose(model, data, name), pose, name)
    # Each joint sits at its child's origin and turns about the child's z.
    for joint, child in (("joint1", "link2"), ("joint2", "link3"), ("joint3", "link4")):
        pose = expected[child]
        assert_joint(model, data, joint, anchor=pose[:3, 3], axis=pose[:3, 2])
    if body is FRAME_PARITY:
        sites = {
            "joint1_frame": (X_L1_J1, "link1"),
            "joint3_frame": (X_L1_J2 @ X_L3_J3, "link3"),
            "link2_frame": (X_L1_J1, "link2"),  # attached to joint1, so to its child link2
            "link4_frame": (X_L1_J2 @ X_L3_J3, "link4"),
        }
        for name, (pose, attached) in sites.items():
            assert_pose(site_pose(model, data, name), pose, f"frame {name}")
            assert site_body(model, name) == attached, f"frame {name}: body it is attached to"
