"""gz-sim's VelocityControl: a model's twist in its own frame, run from load and by `twin drive`.

The system sets the velocity of the model's canonical link's origin (gz-physics gives the free
group's velocity at that link) to its twist rotated into the world, at every step, starting with
`initial_linear`/`initial_angular`. twin drives the planar part (x, y, yaw) through the root
link's planar servos, which push at the centre of mass and are given the centre's velocity for
that twist. Oracle: a body moving at a constant body-frame twist (vx, vy, ωz) from heading 0
puts its reference point at x = (vx·sin ωt − vy·(1 − cos ωt))/ω, y = (vx·(1 − cos ωt) +
vy·sin ωt)/ω. The slab (1 m × 0.8 m, μ 0.2, sliding) has its centre of mass 0.16 m from
its link's origin, so a servo that moved the centre along that path would leave the origin up to
0.3 m off it.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from twin_cli.control import drive
from twin_cli.control.drives import odometry
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

SLAB = """<sdf version="1.9"><model name="slab"><link name="body"><pose>{link_pose}</pose>
  <inertial><pose>0.15 0.05 0 0 0 0</pose><mass>5</mass><inertia><ixx>0.05</ixx><iyy>0.08</iyy>
    <izz>0.1</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
  <collision name="c"><geometry><box><size>1.0 0.8 0.1</size></box></geometry>
    <surface><friction><ode><mu>0.2</mu><mu2>0.2</mu2></ode></friction></surface></collision>
  </link>
  <plugin filename="gz-sim-velocity-control-system" name="gz::sim::systems::VelocityControl">
    {tags}</plugin></model></sdf>"""


def _unicycle(twist: tuple[float, float, float], t: float) -> tuple[float, float, float]:
    """(x, y, yaw) of a point moving at a constant body-frame twist for t s from heading 0."""
    vx, vy, wz = twist
    s, c = math.sin(wz * t), 1.0 - math.cos(wz * t)
    return (vx * s - vy * c) / wz, (vx * c + vy * s) / wz, wz * t


def _slab(tmp_path: Path, tags: str, link_pose: str = "0 0 0 0 0 0") -> World:
    path = tmp_path / "slab.sdf"
    path.write_text(SLAB.format(tags=tags, link_pose=link_pose))
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="slab")
    return world


@pytest.mark.parametrize(
    ("twist", "link_pose"),
    [
        ((0.4, 0.0, 0.2), "0 0 0 0 0 0"),
        ((0.3, -0.1, -0.5), "0 0 0 0 0 0"),
        ((-0.2, 0.15, 1.0), "0 0 0 0 0 0"),
        ((0.4, 0.1, 0.3), "0 0 0 0 0 1.5708"),  # the link turned in its model: the model's axes
    ],
)
def test_its_initial_twist_moves_the_links_origin_from_load(
    tmp_path: Path, twist: tuple[float, float, float], link_pose: str
) -> None:
    """The world and the exported scene.xml (from its home key) alike, every 2 s for 6 s. gz-sim
    turns the twist by the model's pose, so a link turned in its model still moves along the
    model's axes."""
    import mujoco

    from converters.mjcf.writer import write_model
    from converters.pipeline import convert_full

    vx, vy, wz = twist
    tags = (
        f"<initial_linear>{vx} {vy} 0</initial_linear><initial_angular>0 0 {wz}</initial_angular>"
    )
    world = _slab(tmp_path, tags, link_pose)
    start = world.get_pose("slab")
    done = convert_full(tmp_path / "slab.sdf")
    scene = write_model(done.spec, done.report, tmp_path / "out" / "slab").parent / "scene.xml"
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    origin = data.qpos[:3].copy()
    for t in (2.0, 4.0, 6.0):
        world.step(round(2.0 / world.model.opt.timestep))
        mujoco.mj_step(model, data, nstep=round(2.0 / model.opt.timestep))
        x, y, yaw = _unicycle(twist, t)
        pose = world.get_pose("slab")
        moved = (pose.x - start.x, pose.y - start.y)
        assert moved == pytest.approx((x, y), abs=5e-3), f"world at {t} s: {moved}, law {x, y}"
        lag = math.remainder(pose.yaw - yaw, math.tau) / t  # the mean yaw-rate error [rad/s]
        assert abs(lag) < 1e-3, f"yaw at {t} s: {pose.yaw:.4f} rad, law {yaw:.4f}"
        exported = tuple(data.qpos[:2] - origin[:2])
        assert exported == pytest.approx((x, y), abs=5e-3), f"scene.xml at {t} s: {exported}"


def test_twin_drive_replaces_its_twist_as_a_cmd_vel_does(tmp_path: Path) -> None:
    """A still slab (no initial twist) takes `twin drive` twists as gz-sim's /cmd_vel: once the
    command is reached, the origin turns at ωz and moves at √(vx² + vy²)."""
    world = _slab(tmp_path, "")
    still = world.get_pose("slab").position()
    world.step(500)
    assert world.get_pose("slab").position() == pytest.approx(still, abs=1e-4), "no twist yet"
    drive(world, "slab", 0.3, 0.4, lateral=0.1)
    world.step(1000)  # the twin controller's ramp reaches the command in 0.1 s
    a = world.get_pose("slab")
    world.step(100)
    b = world.get_pose("slab")
    speed = math.hypot(b.x - a.x, b.y - a.y) / 0.1
    turn = math.remainder(b.yaw - a.yaw, math.tau) / 0.1
    assert speed == pytest.approx(math.hypot(0.3, 0.1), rel=0.01), f"{speed:.4f} m/s"
    assert turn == pytest.approx(0.4, rel=0.01), f"{turn:.4f} rad/s"


def test_reading_its_odometry_leaves_its_initial_twist_running(tmp_path: Path) -> None:
    """`twin odom` reads: the slab keeps the 0.3 m/s and 0.2 rad/s it drives from load."""
    world = _slab(
        tmp_path,
        "<initial_linear>0.3 0 0</initial_linear><initial_angular>0 0 0.2</initial_angular>",
    )
    world.step(1000)
    odometry(world, "slab")
    world.step(500)
    a = world.get_pose("slab")
    world.step(100)
    b = world.get_pose("slab")
    speed = math.hypot(b.x - a.x, b.y - a.y) / 0.1
    turn = math.remainder(b.yaw - a.yaw, math.tau) / 0.1
    assert (speed, turn) == pytest.approx((0.3, 0.2), rel=0.01), f"{speed:.4f} m/s, {turn:.4f}"


@pytest.mark.parametrize("value", ["0.3 0", "0.3 zero 0", "0.3 0 inf"])
def test_a_twist_that_is_not_three_numbers_is_refused_naming_its_tag(
    tmp_path: Path, value: str
) -> None:
    """gz-sim reads `initial_linear` as a 3-vector: anything else is refused, the tag named."""
    from converters.errors import GazeboTagError
    from converters.pipeline import convert

    path = tmp_path / "slab.sdf"
    tags = f"<initial_linear>{value}</initial_linear>"
    path.write_text(SLAB.format(tags=tags, link_pose="0 0 0 0 0 0"))
    with pytest.raises(GazeboTagError, match=r"<plugin/initial_linear>") as caught:
        convert(path)
    assert f"value '{value}' is not three numbers" in str(caught.value), str(caught.value)
    assert "e.g. <plugin/initial_linear>1 0 0<" in str(caught.value), "the fix, as an example"
