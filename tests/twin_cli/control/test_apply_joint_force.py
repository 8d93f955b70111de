"""gz-sim's ApplyJointForce: the force its `cmd_force` topic carries, on one joint, held until the
next. twin runs it as the joint's effort command (`twin command ENTITY JOINT=τ --mode effort`).
Oracle: a disc (I = 0.05 kg m² about its vertical hinge, no load, no damping) under a held
torque τ spins up at τ/I: ω = τ·t/I."""

from __future__ import annotations

from pathlib import Path

import pytest

from converters.pipeline import convert_full
from converters.report import Outcome
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

DISC = """<sdf version="1.9"><model name="disc"><link name="base"/>
  <joint name="fix" type="fixed"><parent>world</parent><child>base</child></joint>
  <link name="disc"><inertial><mass>1</mass><inertia><ixx>0.03</ixx><iyy>0.03</iyy>
    <izz>0.05</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial></link>
  <joint name="spin" type="revolute"><parent>base</parent><child>disc</child>
    <axis><xyz>0 0 1</xyz><limit><lower>-1e16</lower><upper>1e16</upper></limit></axis></joint>
  <plugin filename="gz-sim-apply-joint-force-system" name="gz::sim::systems::ApplyJointForce">
    <joint_name>spin</joint_name></plugin></model></sdf>"""


@pytest.mark.parametrize("torque", [0.5, -2.0])
def test_its_joint_takes_a_held_effort_as_the_topic_would_give_it(
    tmp_path: Path, torque: float
) -> None:
    path = tmp_path / "disc.sdf"
    path.write_text(DISC)
    lines = [e.detail for e in convert_full(path).report.of(Outcome.MAPPED)]
    assert any("--mode effort" in line for line in lines), lines
    world = World()
    world.spawn(SpawnRequest(str(path)), name="disc")
    assert world.joint_commands("disc")["spin"]["modes"] == ["effort"], "an effort motor"
    world.step(round(1.0 / world.model.opt.timestep))
    assert world.joint_states("disc")[0].velocity == 0.0, "no force before a command"
    world.command_joints("disc", {"spin": torque}, mode="effort")
    world.step(round(2.0 / world.model.opt.timestep))
    speed = world.joint_states("disc")[0].velocity
    assert speed == pytest.approx(torque * 2.0 / 0.05, rel=1e-3), f"{speed:.4f} rad/s"
