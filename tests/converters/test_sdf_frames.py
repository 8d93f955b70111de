"""SDFormat pose frame semantics, proved on compiled models against poses computed by hand.

The cases follow the rules of SDFormat's pose-frame-semantics specification (1.7+): a link's
pose is relative to the model frame, a joint's to its child link, a frame's to the frame it is
attached to, unless `relative_to` names another frame; `::` reaches into nested models.
Expected values are composed here from the numbers in each file, never read from twin.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from converters import convert
from converters.errors import SDFError
from converters.report import Outcome

TOL = 1e-9  # [m] and rotation-matrix entries
INERTIAL = (
    "<inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz>"
    "</inertia></inertial>"
)


def Rz(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def Ry(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _kinematics(tmp_path: Path, model: str, version: str = "1.8"):
    path = tmp_path / "m.sdf"
    path.write_text(f'<sdf version="{version}">{model}</sdf>')
    spec, report = convert(path)
    compiled = spec.compile()
    data = mujoco.MjData(compiled)
    mujoco.mj_kinematics(compiled, data)
    mujoco.mj_comPos(compiled, data)
    return compiled, data, report


def _link(name: str, pose: str = "", relative_to: str | None = None) -> str:
    attribute = f' relative_to="{relative_to}"' if relative_to else ""
    return f'<link name="{name}"><pose{attribute}>{pose or "0 0 0 0 0 0"}</pose>{INERTIAL}</link>'


def test_link_relative_to_another_link(tmp_path: Path) -> None:
    model = (
        '<model name="m">'
        + _link("a", "1 0 0 0 0 1.5707963267948966")
        + _link("b", "1 0 0 0 0 0", relative_to="a")
        + '<joint name="j" type="fixed"><parent>a</parent><child>b</child></joint></model>'
    )
    compiled, data, _ = _kinematics(tmp_path, model)
    # X_M_b = X_M_a · X_a_b: a at (1, 0, 0) yawed 90°, b 1 m along a's x → (1, 1, 0), yawed 90°.
    assert data.xpos[compiled.body("b").id] == pytest.approx([1.0, 1.0, 0.0], abs=TOL)
    assert data.xmat[compiled.body("b").id].reshape(3, 3) == pytest.approx(Rz(np.pi / 2), abs=TOL)


def test_frames_chain_and_attach_to_the_link_they_name(tmp_path: Path) -> None:
    model = (
        '<model name="m">'
        + _link("base", "0 0 1 0 0 0")
        + '<frame name="f1" attached_to="base"><pose>0.5 0 0 0 0 1.5707963267948966</pose></frame>'
        + '<frame name="f2" attached_to="f1"><pose>0.2 0 0 0 0 0</pose></frame>'
        + '<frame name="f3" attached_to="base"><pose relative_to="f2">0 0 0.3 0 0 0</pose></frame>'
        + "</model>"
    )
    compiled, data, _ = _kinematics(tmp_path, model)
    # f1 = base (0,0,1) + (0.5,0,0), yaw 90°; f2 = f1 + Rz(90°)(0.2,0,0) = (0.5, 0.2, 1);
    # f3 = f2 + Rz(90°)(0, 0, 0.3) = (0.5, 0.2, 1.3), though it is attached to base.
    expected = {"f1": (0.5, 0.0, 1.0), "f2": (0.5, 0.2, 1.0), "f3": (0.5, 0.2, 1.3)}
    for name, position in expected.items():
        site = compiled.site(name)
        assert data.site_xpos[site.id] == pytest.approx(position, abs=TOL), name
        assert data.site_xmat[site.id].reshape(3, 3) == pytest.approx(Rz(np.pi / 2), abs=TOL)
    assert compiled.site("f3").bodyid[0] == compiled.body("base").id, "fixed to base"


def _arm(joint_pose: str, axis: str) -> str:
    return (
        '<model name="m"><static>true</static>'
        + _link("base")
        + _link("arm", "0 0 1 0 0 1.5707963267948966")
        + f'<joint name="j" type="revolute">{joint_pose}<parent>base</parent><child>arm</child>'
        + f"<axis>{axis}<limit><lower>-1</lower><upper>1</upper></limit></axis></joint></model>"
    )


def test_joint_pose_defaults_to_the_child_frame(tmp_path: Path) -> None:
    compiled, data, _ = _kinematics(
        tmp_path, _arm("<pose>0.1 0 0 0 0 0</pose>", "<xyz>1 0 0</xyz>")
    )
    joint = compiled.joint("j").id
    # The joint frame is 0.1 m along the child's x; the child is yawed 90° at (0, 0, 1).
    assert data.xanchor[joint] == pytest.approx([0.0, 0.1, 1.0], abs=TOL), "anchor [m]"
    assert data.xaxis[joint] == pytest.approx([0.0, 1.0, 0.0], abs=TOL), "x of the child frame"


def test_joint_pose_relative_to_the_parent_link(tmp_path: Path) -> None:
    pose = '<pose relative_to="base">0.1 0 0 0 0 0</pose>'
    compiled, data, _ = _kinematics(tmp_path, _arm(pose, "<xyz>1 0 0</xyz>"))
    joint = compiled.joint("j").id
    # Now the joint frame is base's (identity) moved 0.1 m along x: anchor (0.1, 0, 0), axis x.
    assert data.xanchor[joint] == pytest.approx([0.1, 0.0, 0.0], abs=TOL), "anchor [m]"
    assert data.xaxis[joint] == pytest.approx([1.0, 0.0, 0.0], abs=TOL)


def test_axis_expressed_in_the_model_frame(tmp_path: Path) -> None:
    axis = '<xyz expressed_in="__model__">1 0 0</xyz>'
    compiled, data, _ = _kinematics(tmp_path, _arm("", axis))
    assert data.xaxis[compiled.joint("j").id] == pytest.approx([1.0, 0.0, 0.0], abs=TOL)


def test_nested_model_placed_relative_to_a_parent_link(tmp_path: Path) -> None:
    model = (
        '<model name="outer"><static>true</static>'
        + _link("table", "2 0 0 0 0 0")
        + '<model name="lamp"><pose relative_to="table">0 0 0.5 0 1.5707963267948966 0</pose>'
        + _link("bulb", "0 0 0.1 0 0 0")
        + '<frame name="tip" attached_to="bulb"><pose>0 0 0.05 0 0 0</pose></frame></model>'
        + '<frame name="above_bulb" attached_to="lamp::bulb"><pose>0 0 1 0 0 0</pose></frame>'
        + "</model>"
    )
    compiled, data, _ = _kinematics(tmp_path, model)
    R = Ry(np.pi / 2)
    lamp = np.array([2.0, 0.0, 0.5])
    bulb = lamp + R @ [0.0, 0.0, 0.1]  # (2.1, 0, 0.5): the lamp is pitched 90° about y
    assert data.xpos[compiled.body("lamp::bulb").id] == pytest.approx(bulb, abs=TOL)
    tip = bulb + R @ [0.0, 0.0, 0.05]
    assert data.site_xpos[compiled.site("lamp::tip").id] == pytest.approx(tip, abs=TOL)
    above = bulb + R @ [0.0, 0.0, 1.0]
    assert data.site_xpos[compiled.site("above_bulb").id] == pytest.approx(above, abs=TOL)


def test_before_1_7_relative_to_counts_as_sdformat_upgrades_the_file(tmp_path: Path) -> None:
    # sdformat reads a 1.6 file upgraded to its newest version, relative_to included:
    # X_M_b = X_M_a · X_a_b = (1, 0, 0) + (0, 1, 0) = (1, 1, 0).
    model = '<model name="m">' + _link("a", "1 0 0 0 0 0") + _link("b", "0 1 0 0 0 0", "a")
    compiled, data, report = _kinematics(tmp_path, model + "</model>", version="1.6")
    assert data.xpos[compiled.body("b").id] == pytest.approx([1.0, 1.0, 0.0], abs=TOL)
    assert not any("relative_to" in e.subject for e in report.of(Outcome.IGNORED))


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        (_link("a", "0 0 0 0 0 0", relative_to="nowhere"), "frame 'nowhere' does not exist"),
        (
            '<frame name="f1" attached_to="a"><pose relative_to="f2"/></frame>'
            '<frame name="f2" attached_to="a"><pose relative_to="f1"/></frame>' + _link("a"),
            "cycle",
        ),
    ],
)
def test_bad_frames_name_file_line_and_frames(tmp_path: Path, body: str, needle: str) -> None:
    path = tmp_path / "bad.sdf"
    path.write_text(f'<sdf version="1.8">\n<model name="m">\n{body}\n</model></sdf>')
    with pytest.raises(SDFError) as caught:
        convert(path)
    message = str(caught.value)
    assert needle in message and f"{path}:3" in message, message
