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
