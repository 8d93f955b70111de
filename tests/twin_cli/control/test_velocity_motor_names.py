"""A velocity motor's rotor is hidden from the entity's joints by its name mark, which no robot
file writes: SDF's nested model `arm` with a joint named `motor` flattens to `arm::motor`, and
that joint stays listed, commandable and reported."""

from __future__ import annotations

from pathlib import Path

import pytest

from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

INERTIA = (
    "<inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia>"
    "</inertial>"
)
NESTED = f"""<sdf version="1.9"><model name="bot"><link name="base">{INERTIA}</link>
<joint name="anchor" type="fixed"><parent>world</parent><child>base</child></joint>
<joint name="mount" type="fixed"><parent>base</parent><child>arm::hub</child></joint>
<model name="arm"><link name="hub">{INERTIA}</link><link name="disc">{INERTIA}</link>
<joint name="motor" type="revolute"><parent>hub</parent><child>disc</child><axis>
<xyz>0 0 1</xyz><limit><lower>-1e16</lower><upper>1e16</upper><effort>5</effort></limit>
</axis></joint></model></model></sdf>"""


@pytest.mark.parametrize("speed", [0.5, 2.0])
def test_a_nested_joint_named_motor_is_listed_and_commanded(tmp_path: Path, speed: float) -> None:
    path = tmp_path / "bot.sdf"
    path.write_text(NESTED)
    world = World()
    world.spawn(SpawnRequest(str(path)), name="bot")
    names = [s.name for s in world.joint_states("bot")]
    assert "arm::motor" in names, names
    world.command_joints("bot", {"arm::motor": speed}, mode="velocity")
    world.step(500)
    state = {s.name: s for s in world.joint_states("bot")}["arm::motor"]
    assert state.velocity == pytest.approx(speed, rel=1e-3), f"{state.velocity} rad/s"


SPINNER = """<robot name="bot"><link name="world"/>
<link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0"
  ixz="0" iyz="0"/></inertial></link>
<link name="disc"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0"
  ixz="0" iyz="0"/></inertial></link>
<joint name="anchor" type="fixed"><parent link="world"/><child link="base"/></joint>
<joint name="spin" type="continuous"><parent link="base"/><child link="disc"/>
  <axis xyz="0 0 1"/><limit effort="5" velocity="10"/></joint>
<ros2_control name="s" type="system"><hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin>
  </hardware><joint name="spin"><command_interface name="velocity"/>
  <command_interface name="effort"/><state_interface name="velocity"/></joint>
</ros2_control></robot>"""


def test_a_rotor_is_no_link_to_push(tmp_path: Path) -> None:
    """Only the robot's own links take a push: the rotor body is the motor's speed reference."""
    from converters.mjcf.velocity_motors import rotor_name
    from twin_cli.errors import PartNotFoundError

    path = tmp_path / "bot.urdf"
    path.write_text(SPINNER)
    world = World()
    world.spawn(SpawnRequest(str(path)), name="bot")
    rotor = rotor_name("spin")
    bodies = [world.model.body(b).name for b in range(world.model.nbody)]
    assert f"bot/{rotor}" in bodies, f"the joint has its velocity motor: {bodies}"
    with pytest.raises(PartNotFoundError) as caught:
        world.push("bot", torque=(0.0, 0.0, 1.0), link=rotor)
    assert "velocity_motor" not in str(caught.value).split("its links:", 1)[1], caught.value
    world.command_joints("bot", {"spin": 0.0}, mode="effort")  # the disc free to turn
    world.push("bot", torque=(0.0, 0.0, 0.01), link="disc", duration=0.1)
    world.step(100)
    speed = {s.name: s for s in world.joint_states("bot")}["spin"].velocity
    assert speed == pytest.approx(0.1, rel=0.02), "the disc takes the push: τ·t/I"
