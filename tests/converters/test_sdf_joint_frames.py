"""SDFormat joint frames and axes, against anchors and axes composed by hand.

A joint's `<pose>` is relative to its child link unless `relative_to` names another frame
(1.7+); the axis `<xyz>` is in the joint frame unless `expressed_in` names another (1.7+, ""
means the joint frame). Before 1.7: 1.5-1.6 `<use_parent_model_frame>` puts the axis in the
model frame, and 1.4 axes are always in the model frame (sdformat's 1.4 → 1.5 converter,
sdf/1.5/1_4.convert, adds use_parent_model_frame=true to every 1.4 axis); link poses are
relative to the model and joint poses to the child link. MuJoCo's `xanchor`/`xaxis` at qpos0
are the model-frame anchor and axis.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from sdf_frame_models import (
    HALF_PI,
    HP,
    LIMIT,
    TOL_M,
    Rx,
    Rz,
    X,
    assert_joint,
    assert_pose,
    body_pose,
    kinematics,
    link,
    write,
)


def _two_links(joint_pose: str, axis_xyz: str = "<xyz>0 0 1</xyz>", extra: str = "") -> str:
    return (
        '<model name="m">'
        + link("P", f"0 0 1 0 0 {HP}")
        + link("C", f"1 1 1 {HP} 0 0")
        + f'<joint name="J" type="revolute">{joint_pose}<parent>P</parent><child>C</child>'
        f"<axis>{axis_xyz}{LIMIT}</axis></joint>" + extra + "</model>"
    )


@pytest.mark.parametrize(
    ("joint_pose", "extra", "anchor", "axis"),
    [
        # Default: relative to the child C (at (1, 1, 1), Rx(90°) = [[1,0,0],[0,0,-1],[0,1,0]]):
        # (1, 1, 1) + Rx(90°)(0, 0.2, 0) = (1, 1, 1) + (0, 0, 0.2); axis Rx(90°)z = (0, -1, 0).
        ("<pose>0 0.2 0 0 0 0</pose>", "", (1, 1, 1.2), (0, -1, 0)),
        # relative_to the parent P (at (0, 0, 1), Rz(90°)): (0, 0, 1) + Rz(90°)(0, 0.2, 0)
        # = (-0.2, 0, 1); axis Rz(90°)z = (0, 0, 1).
        ('<pose relative_to="P">0 0.2 0 0 0 0</pose>', "", (-0.2, 0, 1), (0, 0, 1)),
        # relative_to a frame F on P: F = (0, 0, 1) + Rz(90°)(0, 0, 0.5) = (0, 0, 1.5),
        # R = Rz(90°)·Ry(90°); axis Rz(90°)·Ry(90°)z = Rz(90°)(1, 0, 0) = (0, 1, 0).
        (
            '<pose relative_to="F"/>',
            f'<frame name="F" attached_to="P"><pose>0 0 0.5 0 {HP} 0</pose></frame>',
            (0, 0, 1.5),
            (0, 1, 0),
        ),
    ],
    ids=["child-default", "relative-to-parent", "relative-to-frame"],
)
def test_joint_frame_defaults_to_child_link_or_names_a_frame(
    tmp_path: Path, joint_pose: str, extra: str, anchor, axis
) -> None:
    model, data = kinematics(write(tmp_path, _two_links(joint_pose, extra=extra)))
    assert_joint(model, data, "J", anchor, axis)
    # The joint pose never moves the child link: C stays at (1, 1, 1), Rx(90°).
    assert_pose(body_pose(model, data, "C"), X(1, 1, 1, HALF_PI, 0, 0), "link C")


def test_child_rotates_about_the_sdf_joint_axis_through_the_anchor(tmp_path: Path) -> None:
    model, data = kinematics(
        write(tmp_path, _two_links('<pose relative_to="P">0 0.2 0 0 0 0</pose>'))
    )
    # Anchor a = (-0.2, 0, 1), axis z: turning q moves C's origin to a + Rz(q)(c - a), with
    # c = (1, 1, 1): c - a = (1.2, 1, 0); at q = 0.5 rad its orientation is Rz(0.5)·Rx(90°).
    q = 0.5
    data.qpos[model.joint("J").qposadr[0]] = q
    mujoco.mj_kinematics(model, data)
    a = np.array([-0.2, 0.0, 1.0])
    expected = np.eye(4)
    expected[:3, 3] = a + Rz(q) @ (np.array([1.0, 1.0, 1.0]) - a)
    expected[:3, :3] = Rz(q) @ Rx(HALF_PI)
    assert_pose(body_pose(model, data, "C"), expected, "link C at q = 0.5 rad")
    assert_joint(model, data, "J", anchor=a, axis=(0, 0, 1))


# The joint frame for the axis cases: on C (at (0, 0, 1), pitched 90°), rolled 90°:
# R_M_J = Ry(90°)·Rx(90°). The parent P is yawed 90°; F on P is rolled 90° more.
AXIS_MODEL = (
    '<model name="m">'
    + link("P", f"0 0 0 0 0 {HP}")
    + link("C", f"0 0 1 0 {HP} 0")
    + f'<joint name="J" type="revolute"><pose>0 0 0 {HP} 0 0</pose><parent>P</parent>'
    "<child>C</child><axis>{xyz}" + LIMIT + "</axis></joint>"
    f'<frame name="F" attached_to="P"><pose>0 0 0 {HP} 0 0</pose></frame>'
    "</model>"
)


@pytest.mark.parametrize(
    ("xyz", "axis"),
    [
        # Joint frame: Rx(90°)(0, 1, 0) = (0, 0, 1), then Ry(90°)(0, 0, 1) = (1, 0, 0).
        ("<xyz>0 1 0</xyz>", (1, 0, 0)),
        ('<xyz expressed_in="">0 1 0</xyz>', (1, 0, 0)),
        ('<xyz expressed_in="J">0 1 0</xyz>', (1, 0, 0)),
        # The model frame is the world frame at qpos0: (0, 1, 0) as written.
        ('<xyz expressed_in="__model__">0 1 0</xyz>', (0, 1, 0)),
        # The parent link: Rz(90°)(0, 1, 0) = (-1, 0, 0).
        ('<xyz expressed_in="P">0 1 0</xyz>', (-1, 0, 0)),
        # F: Rz(90°)·Rx(90°)(0, 1, 0) = Rz(90°)(0, 0, 1) = (0, 0, 1).
        ('<xyz expressed_in="F">0 1 0</xyz>', (0, 0, 1)),
        # Not unit length: the direction counts, (0, 3, 0) in the model frame.
        ('<xyz expressed_in="__model__">0 3 0</xyz>', (0, 1, 0)),
    ],
    ids=["default", "empty", "joint", "model", "parent", "frame", "unnormalized"],
)
def test_axis_xyz_expressed_in(tmp_path: Path, xyz: str, axis) -> None:
    model, data = kinematics(write(tmp_path, AXIS_MODEL.format(xyz=xyz)))
    # The anchor is the joint origin, C's origin (0, 0, 1), whatever the axis frame.
    assert_joint(model, data, "J", anchor=(0, 0, 1), axis=axis)


def _legacy_axis_model(axis: str) -> str:
    # AXIS_MODEL without `<frame>` and `expressed_in` (1.7+), for 1.4-1.6.
    return (
        '<model name="m">'
        + link("P", f"0 0 0 0 0 {HP}")
        + link("C", f"0 0 1 0 {HP} 0")
        + f'<joint name="J" type="revolute"><pose>0 0 0 {HP} 0 0</pose><parent>P</parent>'
        f"<child>C</child><axis>{axis}{LIMIT}</axis></joint></model>"
    )


@pytest.mark.parametrize(
    ("version", "axis_xml", "axis"),
    [
        # 1.4: the axis is in the model frame (1_4.convert adds use_parent_model_frame=true).
        ("1.4", "<xyz>0 1 0</xyz>", (0, 1, 0)),
        # 1.5-1.6: the joint frame unless use_parent_model_frame (same arithmetic as above).
        ("1.5", "<xyz>0 1 0</xyz>", (1, 0, 0)),
        ("1.6", "<xyz>0 1 0</xyz>", (1, 0, 0)),
        (
            "1.6",
            "<xyz>0 1 0</xyz><use_parent_model_frame>false</use_parent_model_frame>",
            (1, 0, 0),
        ),
        ("1.5", "<xyz>0 1 0</xyz><use_parent_model_frame>true</use_parent_model_frame>", (0, 1, 0)),
        ("1.6", "<xyz>0 1 0</xyz><use_parent_model_frame>1</use_parent_model_frame>", (0, 1, 0)),
    ],
    ids=["1.4-model", "1.5-joint", "1.6-joint", "1.6-flag-false", "1.5-flag", "1.6-flag"],
)
def test_axis_frame_before_1_7(tmp_path: Path, version: str, axis_xml: str, axis) -> None:
    model, data = kinematics(write(tmp_path, _legacy_axis_model(axis_xml), version=version))
    assert_joint(model, data, "J", anchor=(0, 0, 1), axis=axis)


@pytest.mark.parametrize("version", ["1.4", "1.5", "1.6"])
def test_legacy_links_in_model_frame_and_joints_in_child_frame(
    tmp_path: Path, version: str
) -> None:
    body = (
        '<model name="m">'
        + link("P", f"0 0 1 0 0 {HP}")
        + link("C", f"1 0 1 0 {HP} 0")
        + '<joint name="J" type="revolute"><pose>0 0 0.3 0 0 0</pose><parent>P</parent>'
        f"<child>C</child><axis><xyz>0 0 1</xyz>{LIMIT}</axis></joint>"
        "</model>"
    )
    model, data = kinematics(write(tmp_path, body, version=version))
    # Links from the model frame, not from each other: C at (1, 0, 1), Ry(90°).
    assert_pose(body_pose(model, data, "C"), X(1, 0, 1, 0, HALF_PI, 0), f"{version} link C")
    # Joint from C: (1, 0, 1) + Ry(90°)(0, 0, 0.3) = (1, 0, 1) + (0.3, 0, 0). (Its axis, whose
    # frame changed between versions, is checked above.)
    joint = model.joint("J").id
    np.testing.assert_allclose(
        data.xanchor[joint], (1.3, 0, 1), atol=TOL_M, err_msg=f"{version} joint J anchor [m]"
    )


def test_joint_to_the_world_anchors_the_model(tmp_path: Path) -> None:
    body = (
        '<model name="m">'
        + link("L", f"0 0 1 {HP} 0 0")
        + '<joint name="pin" type="revolute"><pose>0 0.5 0 0 0 0</pose><parent>world</parent>'
        f"<child>L</child><axis><xyz>0 0 1</xyz>{LIMIT}</axis></joint>"
        "</model>"
    )
    model, data = kinematics(write(tmp_path, body))
    assert model.njnt == 1, "only the pin joint: no floating base"
    # pin = L·(0, 0.5, 0): (0, 0, 1) + Rx(90°)(0, 0.5, 0) = (0, 0, 1.5); axis Rx(90°)z = (0, -1, 0).
    assert_joint(model, data, "pin", anchor=(0, 0, 1.5), axis=(0, -1, 0))
    assert_pose(body_pose(model, data, "L"), X(0, 0, 1, HALF_PI, 0, 0), "link L")
