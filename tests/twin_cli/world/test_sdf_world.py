"""Gazebo worlds and SDF models in a running twin: physics, entities, poses, spawning from text."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from sdf_models import LESSON_BOX, WORLD

import scenarios
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World
from twin_cli.world.sdf_world import world_from_sdf

HUMANOID = Path(scenarios.HUMANOID)
MOON_G = 1.62  # [m/s²], the file's gravity


@pytest.fixture
def world_file(tmp_path: Path) -> Path:
    path = tmp_path / "moon_lab.world"
    path.write_text(WORLD)
    return path


def test_world_file_sets_physics_gravity_and_entities(world_file: Path) -> None:
    world = world_from_sdf(world_file)
    physics = world.physics()
    assert (physics["timestep"], physics["rate"], physics["iterations"]) == (0.002, 500.0, 80)
    assert world.gravity() == (0.0, 0.0, -MOON_G), "gravity [m/s²]"
    model = world.model
    lights = {model.light(i).name: i for i in range(model.nlight)}
    assert list(lights) == ["sun"], "the file's lights (the included sun) replace the default"
    assert model.light_type[lights["sun"]] == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    assert [e.name for e in world.entities()] == ["ground_plane", "crate", "table"]
    sources = {e.name: e.source for e in world.entities()}
    assert sources["crate"] == f"{world_file.resolve()}#crate", "the file and model, not <MjSpec>"
    assert world.get_pose("crate") == Pose(1.0, 0.0, 2.0), "model pose as in the file"
    table = world.get_pose("table")
    assert (table.x, table.y, table.z, table.yaw) == pytest.approx((-1.0, 0.5, 0.0, 0.5), abs=1e-12)
    links = world.link_poses("table")
    # lamp::bulb = table ∘ top (0, 0, 0.7) ∘ (0.2, 0, 0.1), table yawed 0.5 rad about z.
    c, s = np.cos(0.5), np.sin(0.5)
    expected = (-1.0 + 0.2 * c, 0.5 + 0.2 * s, 0.8)
    bulb = links["lamp::bulb"]
    assert (bulb.x, bulb.y, bulb.z) == pytest.approx(expected, abs=1e-12), "nested link [m]"


def test_a_dropped_box_falls_at_the_files_gravity(world_file: Path) -> None:
    world = world_from_sdf(world_file)
    z0 = world.get_pose("crate").z
    steps = 500  # 1 s at the file's 2 ms step; ½·1.62·1² = 0.81 m, above the ground
    world.step(steps)
    t = steps * 0.002
    drop = z0 - world.get_pose("crate").z
    assert drop == pytest.approx(0.5 * MOON_G * t**2, rel=0.01), "½gt² at the file's g [m]"


def test_the_ground_plane_model_holds_a_box_at_rest(world_file: Path) -> None:
    world = world_from_sdf(world_file)
    world.step(1500)  # 3 s: the crate lands (1.85 m at 1.62 m/s² takes 1.5 s) and settles
    assert world.get_pose("crate").z == pytest.approx(0.15, abs=2e-3), "resting on the plane [m]"


def test_lesson_box_spawned_from_text_is_static_and_red() -> None:
    world = World()
    result = world.spawn(SpawnRequest(xml=LESSON_BOX), pose=Pose(2.0, 0.0, 0.25))
    assert result.name == "test_box", "the model's own name"
    world.step(500)
    assert world.get_pose("test_box") == Pose(2.0, 0.0, 0.25), "static: it never moves"
    model = world.model
    visual = model.geom("test_box/link_visual_0")
    assert visual.rgba[:3].tolist() == [1.0, 0.0, 0.0], "Gazebo/Red"


def test_a_pushed_robot_does_not_pass_through_the_sdf_box() -> None:
    """The collision check's physics against the lesson's box: 15 N/kg for 0.3 s towards it."""
    world = World()
    world.spawn(SpawnRequest(HUMANOID, on_ground=True), name="robot", pose=Pose(0.0, 0.0, 0.0))
    mujoco.mj_forward(world.model, world.data)
    front = max(
        world.data.geom_xpos[g][0] + world.model.geom_rbound[g]
        for g in range(world.model.ngeom)
        if world.model.geom(g).name.startswith("robot/")
    )
    near_face = front + 0.1
    world.spawn(SpawnRequest(xml=LESSON_BOX), pose=Pose(near_face + 0.25, 0.0, 0.25))
    mass = sum(world.model.body_mass[b] for b in range(world.model.nbody))
    world.push("robot", force=(15.0 * mass, 0.0, 0.0), duration=0.3)
    robot = [b for b in range(world.model.nbody) if world.model.body(b).name.startswith("robot/")]
    deepest = -np.inf
    for _ in range(100):  # 1 s in 10 ms samples: links level with the box stay in front of it
        world.step(10)
        com = world.data.xipos[robot]
        level = (np.abs(com[:, 1]) < 0.25) & (com[:, 2] < 0.5)
        if level.any():
            deepest = max(deepest, float(com[level, 0].max()) - near_face)
    assert deepest > -0.3, f"the push never brought the robot to the box ({deepest:.3f} m)"
    assert deepest < 0.05, f"a link COM went {deepest:.3f} m into the box (limit 0.05 m)"
    assert world.get_pose("test_box") == Pose(near_face + 0.25, 0.0, 0.25), "the box held"


def test_quaternion_and_rpy_poses_agree() -> None:
    world = World()
    world.spawn(SpawnRequest(xml=LESSON_BOX), name="a", pose=Pose(0, 0, 0.25, 0.0, 0.0, 0.7))
    quat = Pose(0, 0, 0.25, 0.0, 0.0, 0.7).quat()
    from_quat = Pose.from_quat(0.0, 0.0, 0.25, quat)
    assert from_quat.yaw == pytest.approx(0.7, abs=1e-12), "yaw from (w, x, y, z)"


SDF14_WORLD = """<?xml version="1.0"?>
<sdf version="1.4"><world name="moon">
<physics type="ode"><gravity>0 0 -1.62</gravity><max_step_size>0.001</max_step_size></physics>
<model name="plinth"><static>true</static><link name="l"><inertial><mass>80</mass>
<inertia><ixx>14.6</ixx><iyy>0</iyy><izz>14.6</izz></inertia></inertial>
<collision name="c"><geometry><box><size>1 1 1</size></box></geometry></collision></link></model>
</world></sdf>"""


def test_an_sdf_1_4_world_with_a_static_model_of_bad_inertia_loads(tmp_path: Path) -> None:
    # SDF 1.4 keeps gravity in <physics>; the AWS small house has static models whose
    # inertias are not physical, which Gazebo loads (a static model never moves).
    path = tmp_path / "moon.world"
    path.write_text(SDF14_WORLD)
    world = world_from_sdf(path)
    assert tuple(world.model.opt.gravity) == pytest.approx((0.0, 0.0, -1.62))
    world.step(200)
    body = world.model.body("plinth/l").id
    assert world.data.xpos[body] == pytest.approx([0.0, 0.0, 0.0], abs=1e-12), "static"
    assert any("repaired" in note and "inertia" in note for note in world.file_notes)


def test_what_a_world_file_holds_that_twin_does_not_simulate_is_said(tmp_path: Path) -> None:
    # A <population> or an unsupported <cone> vanished without a word.
    path = tmp_path / "w.world"
    path.write_text(
        '<sdf version="1.6"><world name="w"><population name="p"><model_count>3</model_count>'
        '</population><model name="cone"><link name="l"><collision name="c"><geometry><cone>'
        "<radius>0.1</radius><length>0.2</length></cone></geometry></collision></link></model>"
        "</world></sdf>"
    )
    notes = "\n".join(world_from_sdf(path).file_notes)
    assert "world <population>: not simulated" in notes, notes
    assert "<cone> geometry is not supported" in notes, notes


def test_a_served_worlds_models_are_found_with_package_paths(tmp_path: Path) -> None:
    # `twin serve WORLD --package NAME=PATH`: the fix the missing-model message names.
    from converters.errors import PackageNotFoundError
    from twin_cli.world.sdf_world import load_world

    model = tmp_path / "elsewhere" / "shelf"  # not above the world file: found only if given
    model.mkdir(parents=True)
    (model / "model.sdf").write_text(
        '<sdf version="1.6"><model name="shelf"><static>true</static><link name="l"><collision '
        'name="c"><geometry><box><size>1 1 1</size></box></geometry></collision></link></model>'
        "</sdf>"
    )
    path = tmp_path / "world" / "w.world"
    path.parent.mkdir()
    path.write_text(
        '<sdf version="1.6"><world name="w"><include><uri>model://shelf</uri>'
        "<pose>1 2 0.5 0 0 0</pose></include></world></sdf>"
    )
    with pytest.raises(PackageNotFoundError, match="--package shelf=PATH"):
        load_world(path)
    pose = load_world(path, package_paths={"shelf": str(model)}).get_pose("shelf")
    assert (pose.x, pose.y, pose.z) == pytest.approx((1.0, 2.0, 0.5))
