"""A world's conversion cache with bounded conversions (as a server runs them): the files the
child read key the cache, so a changed mesh or include converts again and an unchanged robot
does not."""

from __future__ import annotations

import pytest

from converters.isolated import bounded
from twin_cli.world import World
from twin_cli.world.pose import Pose

CUBE = "\n".join(
    [f"v {x} {y} {z}" for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    + ["f 1 3 2", "f 2 3 4", "f 5 6 7", "f 6 8 7", "f 1 2 5", "f 2 6 5"]
    + ["f 3 7 4", "f 4 7 8", "f 1 5 3", "f 3 5 7", "f 2 4 6", "f 4 8 6"]
)
PART = """<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:macro name="part">
  <link name="part"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><mesh filename="cube.obj" scale="{half} {half} {half}"/></geometry>
    </collision></link></xacro:macro></robot>"""
MAIN = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="part.xacro"/><xacro:part/></robot>"""


@pytest.fixture
def served():
    """Conversions bounded in children, as in a world server."""
    bounded.enable()
    yield
    bounded.disable()


def _half_width(world: World, name: str) -> float:
    """Half the longest extent [m] of entity `name`'s collision mesh, from the compiled model
    (MuJoCo turns a mesh to its principal axes, so the axis is not kept)."""
    model = world.model
    mesh = int(model.geom(f"{name}/part_collision_0").dataid[0])
    start = int(model.mesh_vertadr[mesh])
    vertices = model.mesh_vert[start : start + int(model.mesh_vertnum[mesh])]
    return float((vertices.max(axis=0) - vertices.min(axis=0)).max()) / 2


def test_a_served_conversion_is_cached_until_a_file_it_read_changes(served, tmp_path):
    (tmp_path / "cube.obj").write_text(CUBE)
    (tmp_path / "part.xacro").write_text(PART.format(half=0.1))
    main = tmp_path / "r.urdf.xacro"
    main.write_text(MAIN)
    world = World()
    results = [world.spawn(main, name="a"), world.spawn(main, name="b", pose=Pose(x=1))]
    assert [r.cached for r in results] == [False, True]
    (tmp_path / "part.xacro").write_text(PART.format(half=0.2))  # the include changes
    assert world.spawn(main, name="c", pose=Pose(x=2)).cached is False
    (tmp_path / "cube.obj").write_text(CUBE.replace("v 1", "v 3"))  # the mesh changes
    assert world.spawn(main, name="d", pose=Pose(x=3)).cached is False
    widths = [_half_width(world, n) for n in "abcd"]
    assert widths == pytest.approx([0.1, 0.1, 0.2, 0.4], abs=1e-6), widths
