"""`<ros2_control>` and `<transmission>` tags → command modes, bounds and gains, per form."""

from __future__ import annotations

import json

import mujoco
import pytest
from models import write_urdf

from converters import convert

LINKS = """<link name="base"><inertial><mass value="1"/>
<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>""" + "".join(
    f"""<link name="l{i}"><inertial><mass value="1"/>
<inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="j{i}" type="revolute"><parent link="base"/><child link="l{i}"/>
<limit lower="-1" upper="1" effort="10" velocity="2"/></joint>"""
    for i in range(3)
)


def _records(tmp_path, tags: str) -> dict[str, dict]:
    spec, _ = convert(write_urdf(tmp_path, f'<robot name="r">{LINKS}{tags}</robot>'))
    model = spec.compile()
    assert model.ntext == 1  # one text for all motors: a delete costs one element, not one each
    assert mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_TEXT, 0) == "control"
    return json.loads(bytes(model.text_data[: model.text_size[0] - 1]).decode())


def _transmission(joint: str, interface: str, on_actuator: bool = False) -> str:
    hw = f"<hardwareInterface>{interface}</hardwareInterface>"
    return (
        f'<transmission name="t_{joint}"><type>transmission_interface/SimpleTransmission</type>'
        f'<joint name="{joint}">{"" if on_actuator else hw}</joint>'
        f'<actuator name="m_{joint}">{hw if on_actuator else ""}</actuator></transmission>'
    )


@pytest.mark.parametrize(
    ("interface", "on_actuator", "mode"),
    [
        ("hardware_interface/EffortJointInterface", False, "effort"),
        ("PositionJointInterface", False, "position"),  # hyq writes it without the prefix
        ("hardware_interface/VelocityJointInterface", True, "velocity"),  # deprecated place
    ],
)
def test_transmission_hardware_interface_is_the_joints_one_mode(
    tmp_path, interface, on_actuator, mode
):
    records = _records(tmp_path, _transmission("j0", interface, on_actuator))
    assert records["j0"]["modes"] == [mode] and records["j0"]["source"] == "transmission"
    assert records["j0"]["velocity_limit"] == 2.0, "the joint's velocity limit travels along"
    others = {records[j]["source"] for j in set(records) - {"j0"}}
    assert others <= {"passive"}, "the other joints only keep a passive motor"


def test_ros2_control_interfaces_bounds_and_pid_gains(tmp_path):
    tags = """<ros2_control name="arm" type="system"><hardware><plugin>x</plugin></hardware>
      <joint name="j0"><command_interface name="position">
        <param name="min">-0.5</param><param name="max">0.7</param></command_interface>
        <command_interface name="velocity"/><state_interface name="position"/></joint>
      <joint name="j1"><param name="pos_kp">120</param><param name="pos_kd">4</param>
        <param name="pos_ki">1</param><command_interface name="position_pid"/></joint>
      <joint name="j2"><command_interface name="acceleration"/></joint>
    </ros2_control>"""
    records = _records(tmp_path, tags)
    assert records["j0"]["modes"] == ["position", "velocity"]
    assert records["j0"]["bounds"] == {"position": [-0.5, 0.7]}
    assert records["j1"]["modes"] == ["position"] and records["j1"]["pid"] == {
        "position": [120.0, 1.0, 4.0]
    }
    assert records["j2"]["modes"] == ["position", "velocity", "effort"], (
        "a joint without a command interface twin can drive keeps every mode"
    )


def test_a_bad_number_in_a_param_names_the_joint(tmp_path):
    from converters.errors import ConversionError

    tags = """<ros2_control name="arm" type="system"><joint name="j0">
      <command_interface name="position"><param name="min">low</param></command_interface>
    </joint></ros2_control>"""
    with pytest.raises(ConversionError, match="joint 'j0'.*min.*'low' is not a number"):
        _records(tmp_path, tags)


def test_every_interface_of_a_joint_is_kept_across_tags_and_transmissions(tmp_path):
    # j0: one <ros2_control> joint with two interfaces, one of them bounded, plus a transmission
    # adding effort. j1: three same-named transmissions (franka_description's form) and a
    # franka_hw state transmission twin cannot drive. j2: one transmission, two interfaces.
    tags = (
        """<ros2_control name="arm" type="system"><joint name="j0">
          <command_interface name="position"><param name="min">-0.5</param></command_interface>
          <command_interface name="velocity"/></joint></ros2_control>"""
        + _transmission("j0", "hardware_interface/EffortJointInterface")
        + "".join(
            _transmission("j1", f"hardware_interface/{kind}JointInterface")
            for kind in ("Velocity", "Effort", "Position")
        )
        + _transmission("j1", "franka_hw/FrankaStateInterface").replace("t_j1", "state")
        + """<transmission name="both"><joint name="j2">
          <hardwareInterface>PositionJointInterface</hardwareInterface>
          <hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface>
          </joint><actuator name="m2"/></transmission>"""
    )
    records = _records(tmp_path, tags)
    assert records["j0"]["modes"] == ["position", "velocity", "effort"], records["j0"]
    assert records["j0"]["source"] == "ros2_control+transmission"
    assert records["j0"]["bounds"] == {"position": [-0.5, None]}, "bounds stay with their mode"
    assert records["j1"]["modes"] == ["velocity", "effort", "position"], "in the files' order"
    assert records["j1"]["where"] == "<transmission name='t_j1'>", "a state interface adds none"
    assert records["j2"]["modes"] == ["position", "effort"] and records["j2"]["source"] == (
        "transmission"
    )


def test_the_report_gives_one_modes_line_per_group_of_alike_joints(tmp_path):
    tags = "".join(
        _transmission(j, f"hardware_interface/{kind}JointInterface")
        for j in ("j0", "j1")
        for kind in ("Position", "Velocity")
    ) + _transmission("j2", "hardware_interface/EffortJointInterface")
    _, report = convert(write_urdf(tmp_path, f'<robot name="r">{LINKS}{tags}</robot>'))
    lines = {e.subject: e.detail for e in report.entries if "command modes" in e.subject}
    assert lines == {
        "2 joints 'j0', 'j1' command modes": "position, velocity from <transmission>; servo "
        "gains from the reflected inertia; no gazebo_ros(2)_control plugin: Gazebo would not "
        "drive it",
        "joint 'j2' command modes": "effort from <transmission>; servo gains from the reflected "
        "inertia; no gazebo_ros(2)_control plugin: Gazebo would not drive it",
    }, lines


def test_panda_arm_joints_offer_position_velocity_and_effort_in_one_report_line(tmp_path):
    from interface_models import PANDA_JOINTS, panda_arm

    spec, report = convert(write_urdf(tmp_path, panda_arm()))
    model = spec.compile()
    records = json.loads(bytes(model.text_data[: model.text_size[0] - 1]).decode())
    assert set(records) == set(PANDA_JOINTS), "a motor on each arm joint, none on joint8"
    for joint, (*_, velocity, _) in PANDA_JOINTS.items():
        assert records[joint]["modes"] == ["position", "velocity", "effort"], joint
        assert records[joint]["velocity_limit"] == velocity, joint
    lines = [e for e in report.entries if "command modes" in e.subject]
    assert len(lines) == 1 and lines[0].subject.startswith("7 joints 'panda_joint1'"), lines
    assert lines[0].detail.startswith("position, velocity, effort from <transmission>;"), lines
    assert "libgazebo_ros_control.so" in lines[0].detail, lines


def test_interfaces_twin_does_not_drive_are_reported_as_ignored(tmp_path):
    tags = (
        """<ros2_control name="arm" type="system"><joint name="j0">
          <command_interface name="acceleration"/></joint></ros2_control>"""
        + _transmission("j1", "hardware_interface/EffortJointInterface")
        + _transmission("j1", "franka_hw/FrankaStateInterface").replace("t_j1", "state")
    )
    _, report = convert(write_urdf(tmp_path, f'<robot name="r">{LINKS}{tags}</robot>'))
    ignored = {e.subject: e.detail for e in report.entries if e.outcome.value == "ignored"}
    assert set(ignored) == {
        "joint 'j0' interfaces acceleration",
        "joint 'j1' interfaces franka_hw/FrankaStateInterface",
    }, ignored
    modes = {e.subject: e.detail for e in report.entries if "command modes" in e.subject}
    assert modes["joint 'j0' command modes"].startswith(
        "position, velocity, effort (its tags declare none twin drives)"
    ), modes
    assert modes["joint 'j1' command modes"].startswith("effort from <transmission>"), modes
