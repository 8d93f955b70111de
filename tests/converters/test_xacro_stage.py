"""xacro without ROS: arguments, `$(find)` through our resolver, unexpanded macro calls."""

from __future__ import annotations

from pathlib import Path

import pytest

from converters.errors import PackageNotFoundError, XacroError
from converters.pipeline import convert_full
from converters.resources.packages import PackageResolver
from converters.urdf.xacro_expand import expand_xacro

XACRO = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="size" default="1"/>
  <xacro:macro name="part" params="n"><link name="${n}"><inertial><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link></xacro:macro>
  <xacro:include filename="$(find helper)/inc.xacro"/>
  <xacro:part n="base_$(arg size)"/>
  <part n="forgotten"/>
  <joint name="j" type="fixed"><parent link="base_$(arg size)"/><child link="from_include"/></joint>
</robot>"""


@pytest.fixture()
def robot(tmp_path: Path) -> Path:
    helper = tmp_path / "helper"
    helper.mkdir()
    (helper / "inc.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="from_include"/></robot>'
    )
    path = tmp_path / "r.urdf.xacro"
    path.write_text(XACRO)
    return path


def test_find_uses_our_resolver_and_args_are_applied(robot: Path) -> None:
    resolver = PackageResolver.create(robot, env={})
    result = expand_xacro(robot, {"size": "7"}, resolver)
    assert 'name="base_7"' in result.text and 'name="from_include"' in result.text
    assert result.unexpanded == ('<part n="forgotten"/>',), "calls without xacro: are reported"


def test_unexpanded_macro_call_is_a_report_warning(robot: Path) -> None:
    from converters.report import Outcome

    report = convert_full(
        robot, args={"size": "2"}, package_paths={"helper": robot.parent / "helper"}
    ).report
    assert any("forgotten" in e.subject for e in report.of(Outcome.WARNING)), report.entries


def test_unknown_find_package_raises_our_error(robot: Path, tmp_path: Path) -> None:
    robot.write_text(XACRO.replace("$(find helper)", "$(find nowhere_pkg)"))
    with pytest.raises(PackageNotFoundError, match="nowhere_pkg"):
        expand_xacro(robot, {}, PackageResolver.create(robot, env={}))


def test_xacro_failure_carries_file_and_message(robot: Path) -> None:
    robot.write_text(XACRO.replace("$(arg size)", "$(arg undeclared)"))
    with pytest.raises(XacroError, match="undeclared") as caught:
        expand_xacro(robot, {}, PackageResolver.create(robot, env={}))
    assert str(robot) in str(caught.value)


def test_a_xacro_file_with_a_urdf_suffix_is_expanded(robot: Path, tmp_path: Path) -> None:
    # ROS launch files run xacro on any file: gz_ros2_control_demos ships `*.xacro.urdf`.
    renamed = tmp_path / "r.xacro.urdf"
    renamed.write_text(XACRO.replace('<part n="forgotten"/>', ""))
    result = convert_full(
        renamed, args={"size": "3"}, package_paths={"helper": robot.parent / "helper"}
    )
    assert sorted(link.name for link in result.description.links) == ["base_3", "from_include"]


def test_an_include_missing_from_a_found_package_names_the_package(robot: Path) -> None:
    # A source checkout or another version of a package lacks files its install has.
    robot.write_text(XACRO.replace("$(find helper)/inc.xacro", "$(find helper)/gone.xacro"))
    helper = robot.parent / "helper"
    with pytest.raises(XacroError) as caught:
        expand_xacro(robot, {}, PackageResolver.create(robot, {"helper": helper}, env={}))
    message = str(caught.value)
    assert f"gone.xacro does not exist in package 'helper', found at {helper}" in message
    assert "--package helper=PATH" in message and "--arg" not in message
    assert message.count("gone.xacro") == 1, message


PLAIN = (
    '<?xml version="1.0"?>\n<!-- made by: xacro $(find my_pkg)/urdf/r.urdf.xacro -->\n'
    '<robot name="plain"><link name="base"><inertial><mass value="1"/><inertia ixx="1" '
    'iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>'
    "<gazebo><plugin name='p' filename='libx.so'><namespace>${namespace}</namespace></plugin>"
    "</gazebo></robot>"
)


def test_substitution_args_in_a_comment_leave_a_urdf_plain(tmp_path: Path) -> None:
    """URDFs note the xacro command that made them in a comment, and keep text placeholders a
    launch file fills (`${namespace}`): read as plain URDF, the placeholder stays as written."""
    path = tmp_path / "plain.urdf"
    path.write_text(PLAIN)
    result = convert_full(path)
    assert [link.name for link in result.description.links] == ["base"]
    assert not any("xacro" in e.subject for e in result.report.entries), result.report.entries


def test_a_urdf_read_as_xacro_for_its_text_says_why_when_xacro_fails(tmp_path: Path) -> None:
    """Outside a comment, `$(arg …)` makes a `.urdf` xacro (as a ROS launch file would run it);
    when xacro then fails on the file, the error says what made it xacro."""
    path = tmp_path / "plain.urdf"
    path.write_text(PLAIN.replace("<link name=", '<link name="$(arg side)x"/><link name=', 1))
    with pytest.raises(XacroError) as caught:
        convert_full(path)
    message = str(caught.value)
    assert str(path) in message and "read as xacro because its text has '$(arg '" in message
