"""The names a robot's description gives its ROS inputs, read as rclcpp and the controller
manager read them (the YAML's names as pure functions; a drive plugin's through a world's
inputs; no DDS)."""

from __future__ import annotations

import pytest

from twin_cli.ros.plugin_names import Controller, plugin_names


def _robot(plugins: str) -> str:
    return f'<robot name="r"><link name="base"/><gazebo>{plugins}</gazebo></robot>'


def _drive(ros: str) -> str:
    return (
        f'<plugin name="d" filename="libgazebo_ros_diff_drive.so">{ros}<left_joint>'
        "wheel_left_joint</left_joint><right_joint>wheel_right_joint</right_joint></plugin>"
    )


@pytest.mark.parametrize(
    ("ros", "topic"),
    [
        ("", "/bot/cmd_vel"),  # no <ros>: the entity's namespace (twin's)
        ("<ros><namespace>/demo</namespace></ros>", "/demo/cmd_vel"),
        ("<ros><namespace>demo/</namespace><remapping>cmd_vel:=cmd</remapping></ros>", "/demo/cmd"),
        ("<ros><remapping>cmd_vel:=/base/cmd</remapping></ros>", "/base/cmd"),  # absolute
        ("<ros><remapping>~/cmd_vel:=teleop</remapping></ros>", "/bot/teleop"),
        ("<ros><remapping>odom:=odom_demo</remapping></ros>", "/bot/cmd_vel"),  # not cmd_vel
    ],
)
def test_a_drive_plugins_namespace_and_remapping_name_its_cmd_vel(
    tmp_path, ros: str, topic: str
) -> None:
    import drive_models as dm

    from twin_cli.ros.commands import entity_inputs
    from twin_cli.spawn_request import SpawnRequest
    from twin_cli.world import World

    path = tmp_path / "bot.urdf"
    path.write_text(dm.two_wheel_base(_drive(ros)))
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="bot")
    assert {i.topic for i in entity_inputs(world)["bot"] if i.mode is None} == {topic}


def test_the_controller_yaml_names_the_controllers_their_modes_and_joints(tmp_path) -> None:
    params = tmp_path / "controllers.yaml"
    params.write_text(
        "controller_manager:\n  ros__parameters:\n"
        "    jsb: {type: joint_state_broadcaster/JointStateBroadcaster}\n"
        "    arm: {type: joint_trajectory_controller/JointTrajectoryController}\n"
        "    grip: {type: forward_command_controller/ForwardCommandController}\n"
        "    wheels: {type: velocity_controllers/JointGroupVelocityController}\n"
        "arm: {ros__parameters: {joints: [j2, j1]}}\n"
        "grip: {ros__parameters: {joints: [f], interface_name: effort}}\n"
        "/wheels: {ros__parameters: {joints: [l, r]}}\n"
    )
    plugin = (
        '<plugin name="c" filename="libgazebo_ros2_control.so">'
        f"<parameters>{params}</parameters></plugin>"
    )
    assert plugin_names("bot", _robot(plugin)).controllers == (
        Controller("/bot/arm/joint_trajectory", "trajectory", ("j2", "j1")),
        Controller("/bot/grip/commands", "effort", ("f",)),
        Controller("/bot/wheels/commands", "velocity", ("l", "r")),
    )


def test_an_unreadable_controller_yaml_keeps_the_default_names(tmp_path) -> None:
    plugin = (
        '<plugin name="c" filename="libgazebo_ros2_control.so">'
        f"<parameters>{tmp_path / 'missing.yaml'}</parameters></plugin>"
    )
    assert plugin_names("bot", _robot(plugin)).controllers == ()
    assert plugin_names("bot", None).cmd_vel == ()


@pytest.mark.parametrize(
    ("setting", "expected"),
    [
        ("", ("/tb/base/cmd_vel", "geometry_msgs/msg/TwistStamped")),  # Jazzy's, Humble's default
        (", use_stamped_vel: true", ("/tb/base/cmd_vel", "geometry_msgs/msg/TwistStamped")),
        (", use_stamped_vel: false", ("/tb/base/cmd_vel_unstamped", "geometry_msgs/msg/Twist")),
    ],
)
def test_a_diff_drive_controller_takes_one_cmd_vel_of_the_type_use_stamped_vel_chooses(
    tmp_path, setting: str, expected: tuple[str, str]
) -> None:
    """A relative `<parameters>` path starts at the description's folder; the plugin's ign_
    name is a ros2_control plugin as well. One topic, one type, as the controller subscribes."""
    (tmp_path / "ddc.yaml").write_text(
        "controller_manager:\n  ros__parameters:\n"
        "    base: {type: diff_drive_controller/DiffDriveController}\n"
        f"base: {{ros__parameters: {{left_wheel_names: [l], right_wheel_names: [r]{setting}}}}}\n"
    )
    plugin = (
        '<plugin name="c" filename="libign_ros2_control-system.so"><ros><namespace>/tb</namespace>'
        "</ros><parameters>ddc.yaml</parameters></plugin>"
    )
    plugin_names.cache_clear()  # the same text under one path, three files
    names = plugin_names("bot", _robot(plugin), str(tmp_path))
    assert names.cmd_vel == (expected,)
    assert names.controllers == (), "a drive is not a joint command controller"


def test_an_sdf_models_drive_plugin_names_its_cmd_vel_too(tmp_path) -> None:
    """An SDF model has no URDF text: the converter's drive record carries the name its
    gazebo_ros plugin gives cmd_vel, and odom the same way; the plugin subscribes Twist."""
    import drive_models as dm

    from twin_cli.live.catalogue import live_topics
    from twin_cli.ros.commands import entity_inputs
    from twin_cli.spawn_request import SpawnRequest
    from twin_cli.world import World

    plugin = (
        '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><ros><namespace>/sdfbot'
        "</namespace></ros><left_joint>wheel_left_joint</left_joint><right_joint>"
        "wheel_right_joint</right_joint><wheel_separation>0.3</wheel_separation>"
        "<wheel_diameter>0.1</wheel_diameter></plugin>"
    )
    path = tmp_path / "bot.sdf"
    path.write_text(dm.sdf_diff_drive(plugin))
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="b")
    drives = [(i.topic, i.type) for i in entity_inputs(world)["b"] if i.mode is None]
    assert drives == [("/sdfbot/cmd_vel", "geometry_msgs/msg/Twist")], "the plugin's one type"
    assert "/sdfbot/odom" in {t.name for t in live_topics(world)}
