"""Frames and names in older and world-level SDF, as libsdformat 12 reads them.

libsdformat upgrades every file to its newest version as it reads it: a 1.6 file's
`relative_to`, `expressed_in` and `<pose frame>` count, and clashing names of different element
types are renamed, not refused. A world's models may be posed relative to a world `<frame>`.
Expected poses are composed by hand from the SDFormat rules, stated beside each.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from converters import convert
from converters.errors import SDFError
from converters.report import Outcome
from converters.sdf import read_sdf_world

TOL = 1e-9
HALF_PI = "1.5707963267948966"
INERTIAL = (
    "<inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz>"
    "</inertia></inertial>"
)


def _compiled(tmp_path: Path, body: str, version: str):
    path = tmp_path / "m.sdf"
    path.write_text(f'<sdf version="{version}">{body}</sdf>')
    spec, report = convert(path)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return model, data, report


def _link(name: str, pose: str, attributes: str = "") -> str:
    return f'<link name="{name}"><pose{attributes}>{pose}</pose>{INERTIAL}</link>'


def _arm(axis: str, b_pose: str) -> str:
    """a at (1, 0, 0) turned 90° about z; b posed in a's frame; a revolute joint a → b."""
    return (
        '<model name="m">'
        + _link("a", f"1 0 0 0 0 {HALF_PI}")
        + b_pose
        + '<joint name="j" type="revolute"><parent>a</parent><child>b</child>'
        f"<axis>{axis}</axis></joint></model>"
    )


@pytest.mark.parametrize("attribute", ['relative_to="a"', 'frame="a"'])
def test_a_1_6_pose_relative_to_a_link_and_an_axis_expressed_in_it(
    tmp_path: Path, attribute: str
) -> None:
    # b: (1, 0, 0) in a's frame, turned back by -90°: X_M_b = X_M_a · X_a_b, at
    # (1, 0, 0) + Rz(90°)·(1, 0, 0) = (1, 1, 0), with the model frame's orientation.
    # The axis (1, 0, 0) expressed in a: Rz(90°)·(1, 0, 0) = (0, 1, 0); in the joint frame
    # (b's, the default) it would be (1, 0, 0). A 1.6 <pose frame> is relative_to after the
    # 1.6 → 1.7 upgrade.
    b = _link("b", f"1 0 0 0 0 -{HALF_PI}", f" {attribute}")
    model, data, report = _compiled(
        tmp_path, _arm('<xyz expressed_in="a">1 0 0</xyz>', b), version="1.6"
    )
    assert data.xpos[model.body("b").id] == pytest.approx([1.0, 1.0, 0.0], abs=TOL)
    assert data.xmat[model.body("b").id].reshape(3, 3) == pytest.approx(np.eye(3), abs=TOL)
    assert data.xaxis[model.joint("j").id] == pytest.approx([0.0, 1.0, 0.0], abs=TOL)
    assert all("relative_to" not in e.subject for e in report.of(Outcome.IGNORED))


def test_use_parent_model_frame_still_wins_in_1_6(tmp_path: Path) -> None:
    # The upgrade turns use_parent_model_frame=true into expressed_in="__model__": the axis
    # (1, 0, 0) stays along the model's x.
    # (b and a are both turned 90°: in either of their frames it would be (0, 1, 0).)
    b = _link("b", "1 0 0 0 0 0", ' relative_to="a"')
    axis = '<xyz expressed_in="a">1 0 0</xyz><use_parent_model_frame>true</use_parent_model_frame>'
    model, data, _ = _compiled(tmp_path, _arm(axis, b), "1.6")
    assert data.xaxis[model.joint("j").id] == pytest.approx([1.0, 0.0, 0.0], abs=TOL)


def test_a_link_and_a_joint_of_one_name_in_1_6_rename_the_joint(tmp_path: Path) -> None:
    # Before 1.7 names were unique per element type; sdformat renames the later element of
    # the pair, a joint with the suffix _joint, and warns.
    body = (
        '<model name="m">'
        + _link("base", "0 0 0 0 0 0")
        + _link("arm", "0 0 1 0 0 0")
        + '<joint name="arm" type="revolute"><parent>base</parent><child>arm</child>'
        "<axis><xyz>1 0 0</xyz></axis></joint></model>"
    )
    model, data, report = _compiled(tmp_path, body, "1.6")
    assert model.joint("arm_joint").type[0] == mujoco.mjtJoint.mjJNT_HINGE
    assert data.xpos[model.body("arm").id] == pytest.approx([0.0, 0.0, 1.0], abs=TOL)
    mapped = "\n".join(f"{e.subject}: {e.detail}" for e in report.of(Outcome.MAPPED))
    assert "joint 'arm': renamed 'arm_joint'" in mapped, mapped
    with pytest.raises(SDFError, match="used twice"):
        _compiled(tmp_path, body, "1.7")  # from 1.7 a clash is an error, in sdformat too


def test_a_world_model_posed_relative_to_a_world_frame(tmp_path: Path) -> None:
    # pad: (2, 0, 0) turned 90° about z in the world. crate: (1, 0, 0.5) in pad's frame, so
    # (2, 0, 0) + Rz(90°)·(1, 0, 0.5) = (2, 1, 0.5), turned 90°. marker: a frame attached to
    # crate, (0, 0, 1) above it: (2, 1, 1.5). lamp: (0, 0, 0.25) relative to marker.
    world = tmp_path / "w.sdf"
    world.write_text(
        '<sdf version="1.8"><world name="w">'
        f'<frame name="pad"><pose>2 0 0 0 0 {HALF_PI}</pose></frame>'
        '<frame name="marker" attached_to="crate"><pose>0 0 1 0 0 0</pose></frame>'
        f'<model name="crate"><pose relative_to="pad">1 0 0.5 0 0 0</pose>{_link("l", "")}'
        "</model>"
        '<model name="lamp"><static>true</static><pose relative_to="marker">0 0 0.25 0 0 0'
        f"</pose>{_link('l', '')}</model></world></sdf>"
    )
    read = read_sdf_world(world.read_text(), str(world), tmp_path)
    placed = {m.robot.name: m.pose for m in read.models}
    assert placed["crate"][:3, 3] == pytest.approx([2.0, 1.0, 0.5], abs=TOL)
    rz90 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    assert placed["crate"][:3, :3] == pytest.approx(rz90, abs=TOL)
    assert placed["lamp"][:3, 3] == pytest.approx([2.0, 1.0, 1.75], abs=TOL)


def test_a_world_model_relative_to_an_unknown_frame_names_the_known_ones(tmp_path: Path) -> None:
    world = tmp_path / "w.sdf"
    world.write_text(
        '<sdf version="1.8"><world name="w"><frame name="pad"/>'
        f'<model name="m"><pose relative_to="pda">0 0 0 0 0 0</pose>{_link("l", "")}</model>'
        "</world></sdf>"
    )
    with pytest.raises(SDFError, match="frame 'pda' does not exist.*world, m, pad"):
        read_sdf_world(world.read_text(), str(world), tmp_path)
