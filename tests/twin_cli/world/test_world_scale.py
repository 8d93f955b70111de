"""Many robots in one world, in process: batch spawn, the conversion cache, the engine thread
pool and sleeping. Oracles: the world's own spec before a refused request (unchanged), the files
a conversion read (an edited include must convert again), the same trajectory stepped without
the pool (bit-equal), and a push on a resting box in a world without sleeping."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from models import block, two_wheel_bot

import scenarios
from twin_cli.errors import EntityExistsError, InvalidRequestError
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World
from twin_cli.world.conversion_cache import CACHE, cache_key

LESSON = [(0, 0), (1, 1), (2, 0), (1, 2), (0, 2)]  # [m] the spawning lesson's five poses
POOL_TOL = 1e-12  # [m or rad] the pool reorders no arithmetic: MuJoCo's threaded step is exact
PUSH_TOL = 0.002  # [m] a woken box slides as one that never slept (0.3 mm apart measured)
SLEEP_TOL = 0.02  # [m/s] above the 2-3 mm/s a box on Gazebo's stiff contact still creeps at


def test_batch_spawns_at_every_pose_in_one_recompile():
    world = World()
    results = world.spawn_batch(
        scenarios.HUMANOID, base="r", poses=[Pose(x=x, y=y, z=1.3) for x, y in LESSON]
    )
    assert [r.name for r in results] == [f"r_{i}" for i in range(5)]
    got = {e.name: e.position for e in world.entities()}
    for i, (x, y) in enumerate(LESSON):
        assert got[f"r_{i}"] == pytest.approx((x, y, 1.3), abs=1e-9), got
    world.step(300)  # each instance falls on its own: all five end at the same height
    heights = [world.get_pose(f"r_{i}").z for i in range(5)]
    assert max(heights) - min(heights) < 1e-6, heights


def test_a_refused_batch_leaves_the_world_as_it_was():
    world = World()
    world.spawn(scenarios.HUMANOID, name="r_1", pose=Pose(z=1.3))
    before = world._state.spec.to_xml()
    with pytest.raises(EntityExistsError, match=r"r_1"):
        world.spawn_batch(scenarios.HUMANOID, names=["a", "r_1"], poses=[Pose(), Pose(x=1)])
    with pytest.raises(InvalidRequestError, match=r"pose 1 of entity \[b\]"):
        world.spawn_batch(
            scenarios.HUMANOID, names=["a", "b"], poses=[Pose(), Pose(x=float("nan"))]
        )
    assert [e.name for e in world.entities()] == ["r_1"]
    assert world._state.spec.to_xml() == before


def test_second_spawn_skips_conversion_until_an_included_file_changes(tmp_path):
    include = tmp_path / "parts.xacro"
    include.write_text(_parts(0.2))
    main = tmp_path / "robot.urdf.xacro"
    main.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:include filename="parts.xacro"/><xacro:part/></robot>'
    )
    world = World()
    first = world.spawn(main, name="a")
    second = world.spawn(main, name="b", pose=Pose(x=1))
    assert (first.cached, second.cached) == (False, True)
    assert str(include) in CACHE.files_of(cache_key(main.resolve(), SpawnRequest(main), None))
    include.write_text(_parts(0.4))  # same file names, new content
    third = world.spawn(main, name="c", pose=Pose(x=2))
    assert third.cached is False
    sizes = [world.model.geom_size[world.model.geom(f"{n}/part_collision_0").id][0] for n in "ac"]
    assert sizes == pytest.approx([0.1, 0.2]), sizes


def _parts(edge: float) -> str:
    return (
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:macro name="part">'
        f'<link name="part"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
        f'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>'
        f'<box size="{edge} {edge} {edge}"/></geometry></collision></link>'
        "</xacro:macro></robot>"
    )


def _eight_humanoids(threads: int) -> World:
    world = World()
    world.set_engine(threads=threads)
    poses = [Pose(x=(i % 4) * 0.45, y=(i // 4) * 0.8, z=1.3) for i in range(8)]  # they collide
    world.spawn_batch(scenarios.HUMANOID, base="r", poses=poses)
    return world


def test_the_thread_pool_leaves_the_trajectory_unchanged():
    single, pooled = _eight_humanoids(1), _eight_humanoids(2)
    assert (single.pool_threads, pooled.pool_threads) == (0, 2)
    single.step(1500)
    pooled.step(1500)
    assert single.data.ncon > 8  # the robots touch the ground and each other
    assert np.abs(single.data.qpos - pooled.data.qpos).max() <= POOL_TOL
    pooled.delete("r_0")  # a recompile keeps the pool
    assert pooled.pool_threads == 2 and pooled.data.threadpool


def test_a_pushed_sleeping_box_wakes_and_slides_as_an_awake_one(tmp_path):
    (tmp_path / "box.urdf").write_text(block(size=0.2, name="box"))
    moved = []
    for sleep in (False, True):
        world = World()
        world.set_engine(sleep=sleep, sleep_tolerance=SLEEP_TOL)
        world.spawn(
            SpawnRequest(tmp_path / "box.urdf", on_ground=True), name="box", pose=Pose(z=0.1)
        )
        world.step(300)
        assert world.data.ntree_awake == (0 if sleep else 1)
        x0 = world.get_pose("box").x
        world.push("box", (20.0, 0.0, 0.0), duration=0.2)
        world.step(100)
        assert world.data.ntree_awake == 1, "the push woke it"
        world.step(400)
        moved.append(world.get_pose("box").x - x0)
    assert moved[0] > 0.3 and moved[1] == pytest.approx(moved[0], abs=PUSH_TOL), moved


def _tetra_stl(path) -> None:
    """A binary STL tetrahedron (0.1 m edges along the axes)."""
    v = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]], dtype="<f4")
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    rec = np.zeros(4, dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = [v[list(f)] for f in faces]
    path.write_bytes(b"\0" * 80 + np.uint32(4).tobytes() + rec.tobytes())


def test_instances_of_a_robot_share_its_meshes_in_the_world(tmp_path):
    _tetra_stl(tmp_path / "part.stl")
    (tmp_path / "r.urdf").write_text(
        '<robot name="r"><link name="base"><inertial><mass value="1"/><inertia ixx="0.01" '
        'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
        '<visual><geometry><mesh filename="part.stl"/></geometry></visual>'
        '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link></robot>'
    )
    world = World()
    world.spawn(tmp_path / "r.urdf", name="a", pose=Pose(z=0.5))
    one = world.model.nmesh
    world.spawn_batch(tmp_path / "r.urdf", base="b", poses=[Pose(x=k, z=0.5) for k in (1, 2)])
    assert one >= 1 and world.model.nmesh == one  # three instances, one copy of each mesh
    world.delete("a")  # the instance that brought the meshes goes; the others keep them
    world.step(10)
    mesh_geoms = world.model.geom_dataid[world.model.geom_type == mujoco.mjtGeom.mjGEOM_MESH]
    assert world.model.nmesh == one and len(mesh_geoms) == 2 and (mesh_geoms >= 0).all()
    world.delete("b_0")
    world.delete("b_1")
    assert world.model.nmesh == 0 and len(world._state.spec.meshes) == 0  # none left behind


DIFF_DRIVE_BOT = two_wheel_bot(
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>lj</left_joint>'
    "<right_joint>rj</right_joint><wheel_separation>0.2</wheel_separation>"
    "<wheel_diameter>0.1</wheel_diameter></plugin>"
)
SCENE = """<mujoco model="scene"><worldbody><light pos="0 0 3"/>
  <geom name="floor" type="plane" size="2 2 0.1"/>
  <body name="ball"><freejoint/><geom type="sphere" size="0.1" mass="1"/></body>
</worldbody></mujoco>"""


def test_batch_instances_keep_their_drive_plugin_and_the_sources_notes(tmp_path):
    """A batch spawn gives each instance what a single spawn gives it (plugins, notes)."""
    from twin_cli.control import controller_of, drive

    bot, scene = tmp_path / "bot.urdf", tmp_path / "scene.xml"
    bot.write_text(DIFF_DRIVE_BOT)
    scene.write_text(SCENE)
    world = World()
    world.spawn_batch(str(bot), base="d", poses=[Pose(x=0.0, z=0.1), Pose(x=1.0, z=0.1)])
    for name in ("d_0", "d_1"):
        drive(world, name, 0.1, 0.0, 0.5)  # refused for an entity without a drive plugin
        assert controller_of(world, name) is not None, f"{name} lost its diff drive"
    balls = world.spawn_batch(str(scene), base="s", poses=[Pose(x=3.0, z=1.0)])
    assert any("is a scene" in w for w in balls[0].warnings), balls[0].warnings
