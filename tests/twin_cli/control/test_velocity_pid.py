"""ros2_control's `velocity_pid` interface runs its PID's p on the speed error, in every order.

gazebo_ros2_control pushes vel_kp·(ω* − ω) (+ vel_ki·∫, + vel_kd·ė) on a joint whose command
interface is `velocity_pid`, and sets the joint's velocity, as for a plain `velocity`
interface, when the joint gives no gains. A rig the test writes: one 0.01 kg m² disc on a
vertical joint, effort limit 2 N m. Oracle: the PID law integrated by hand
(`tests/pid_law.py`), and the effort limit's constant acceleration.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from pid_law import pid_law

from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

INERTIAL = (
    '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
    'iyz="0"/></inertial>'
)


def _rig(interfaces: tuple[str, ...], params: dict[str, float]) -> str:
    commands = "".join(f'<command_interface name="{name}"/>' for name in interfaces)
    gains = "".join(f'<param name="{k}">{v}</param>' for k, v in params.items())
    return f"""<robot name="rig"><link name="world"/><link name="base">{INERTIAL}</link>
  <link name="disc">{INERTIAL}</link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
  <joint name="spin" type="continuous"><parent link="base"/><child link="disc"/>
    <axis xyz="0 0 1"/><limit effort="2" velocity="100"/></joint>
  <ros2_control name="s" type="system"><hardware>
    <plugin>gazebo_ros2_control/GazeboSystem</plugin></hardware>
    <joint name="spin">{commands}{gains}<state_interface name="velocity"/></joint>
  </ros2_control></robot>"""


def _speeds(tmp_path: Path, text: str, times: tuple[float, ...]) -> list[float]:
    path = tmp_path / "rig.urdf"
    path.write_text(text)
    world = World()
    world.spawn(SpawnRequest(str(path)), name="rig")
    world.command_joints("rig", {"spin": 3.0}, mode="velocity")
    h, elapsed, out = world.model.opt.timestep, 0.0, []
    for t in times:
        world.step(round((t - elapsed) / h))
        elapsed = t
        out.append({s.name: s for s in world.joint_states("rig")}["spin"].velocity)
    return out


TIMES = (0.01, 0.02, 0.04, 0.1)


@pytest.mark.parametrize("first", ["velocity_pid", "effort"])
@pytest.mark.parametrize(("kp", "ki"), [(0.2, 0.0), (0.5, 0.0), (0.5, 0.1)])
def test_velocity_pid_spins_the_disc_up_by_its_law(
    tmp_path: Path, first: str, kp: float, ki: float
) -> None:
    """First interface `velocity_pid` (the model's own servo) or `effort` (the World's servo for
    a velocity command): either way p·(ω* − ω) within 2 N m, vel_ki adding under 2 % here."""
    interfaces = (
        ("velocity_pid", "effort") if first == "velocity_pid" else ("effort", "velocity_pid")
    )
    params = {"vel_kp": kp, "vel_ki": ki} if ki else {"vel_kp": kp}
    speeds = _speeds(tmp_path, _rig(interfaces, params), TIMES)
    expected = [pid_law(3.0, kp, ki, t) for t in TIMES]
    assert speeds == pytest.approx(expected, rel=0.05), f"{speeds} rad/s, law {expected}"


def test_velocity_pid_without_gains_sets_the_joints_speed(tmp_path: Path) -> None:
    """No vel_* params: the joint's velocity is set as for a plain velocity interface (Gazebo's
    joint motor): 2 N m on 0.01 kg m² is 200 rad/s², 3 rad/s after 15 ms, then held."""
    speeds = _speeds(tmp_path, _rig(("velocity_pid",), {}), (0.01, 0.1))
    assert speeds == pytest.approx([2.0, 3.0], rel=0.02), f"{speeds} rad/s"
