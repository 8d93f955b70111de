"""Gazebo worlds as public repositories write them load into a running world (`twin serve`).

A PX4-style world: an x500 that merges its base (with a plane visual on the flying base link)
from `model://`, posed relative to a world `<frame>`; a terrain from a heightmap image. Poses
are worked out by hand below.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from twin_cli.world.sdf_world import world_from_sdf

HALF_PI = "1.5707963267948966"
INERTIAL = (
    "<inertial><mass>{m}</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz>"
    "</inertia></inertial>"
)


def _write(path: Path, body: str, version: str = "1.9") -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f'<?xml version="1.0"?>\n<sdf version="{version}">{body}</sdf>\n')


@pytest.fixture
def px4_world(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    models = tmp_path / "models"
    _write(
        models / "x500_base" / "model.sdf",
        f'<model name="x500_base"><link name="base_link">{INERTIAL.format(m=2)}'
        '<visual name="logo"><geometry><plane><normal>0 0 1</normal><size>0.2 0.2</size>'
        '</plane></geometry></visual><collision name="c"><geometry><box><size>0.4 0.4 0.1</size>'
        "</box></geometry></collision></link>"
        f'<link name="rotor_0"><pose>0.2 0 0.06 0 0 0</pose>{INERTIAL.format(m=0.1)}</link>'
        '<joint name="rotor_0_joint" type="revolute"><parent>base_link</parent>'
        "<child>rotor_0</child><axis><xyz>0 0 1</xyz></axis></joint></model>",
    )
    _write(
        models / "x500" / "model.sdf",
        '<model name="x500"><include merge="true"><uri>model://x500_base</uri></include>'
        '<frame name="imu_frame" attached_to="base_link"/></model>',
    )
    world = tmp_path / "px4.sdf"
    _write(
        world,
        '<world name="default"><include><uri>model://ground_plane</uri></include>'
        f'<frame name="pad"><pose>3 0 0 0 0 {HALF_PI}</pose></frame>'
        '<include><uri>model://x500</uri><pose relative_to="pad">1 0 0.5 0 0 0</pose></include>'
        "</world>",
    )
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(models))
    return world


def test_a_px4_world_loads_its_merged_x500_on_the_pad(px4_world: Path) -> None:
    world = world_from_sdf(px4_world)
    assert set(world.entity_names()) == {"ground_plane", "x500"}
    # On the pad: (3, 0, 0) + Rz(90°)·(1, 0, 0.5) = (3, 1, 0.5).
    pose = world.get_pose("x500")
    assert (pose.x, pose.y, pose.z) == pytest.approx((3.0, 1.0, 0.5), abs=1e-9)
    assert pose.yaw == pytest.approx(float(HALF_PI), abs=1e-9)
    # Merged, not nested: the joint keeps its own name inside the entity.
    assert world.model.joint("x500/rotor_0_joint").id >= 0
    # rotor_0: (0.2, 0, 0.06) in the base frame, turned 90°: (3, 1.2, 0.56).
    rotor = world.link_poses("x500")["rotor_0"]
    assert (rotor.x, rotor.y, rotor.z) == pytest.approx((3.0, 1.2, 0.56), abs=1e-9)


def _box(name: str, x: float, y: float, z: float) -> str:
    return (
        f'<model name="{name}"><pose>{x} {y} {z} 0 0 0</pose><link name="l">'
        f'{INERTIAL.format(m=1)}<collision name="c"><geometry><box><size>0.2 0.2 0.2</size>'
        "</box></geometry></collision></link></model>"
    )


def test_boxes_dropped_on_a_heightmap_rest_at_the_images_heights(tmp_path: Path) -> None:
    # A 9×9 image over 4 × 4 m (a pixel every 0.5 m), z range 2 m, centre at (1, 0, 0.25).
    # Gazebo: height = value / brightest value × 2 m; the image's top rows lie at +y.
    # Left five columns 64: 64/255·2 = 0.50196 m; right four 255 (top rows) and 128 (bottom
    # rows): 2 m and 1.00392 m. A 0.2 m box rests 0.1 m above: z = 0.25 + height + 0.1.
    from PIL import Image

    image = np.zeros((9, 9), np.uint8)
    image[:, :5] = 64
    image[:4, 5:] = 255
    image[4:, 5:] = 128
    Image.fromarray(image).save(tmp_path / "terrain.png")
    world_file = tmp_path / "terrain.sdf"
    _write(
        world_file,
        '<world name="w"><model name="terrain"><static>true</static><link name="l">'
        '<collision name="c"><geometry><heightmap><uri>terrain.png</uri><size>4 4 2</size>'
        "<pos>1 0 0.25</pos></heightmap></geometry></collision></link></model>"
        + _box("low", -0.4, 0.0, 1.0)  # x -0.4 is over the left columns
        + _box("high", 2.5, 1.2, 2.5)  # x 2.5, y +1.2: right, top rows
        + _box("middle", 2.5, -1.2, 1.5)  # right, bottom rows
        + "</world>",
    )
    world = world_from_sdf(world_file)
    world.step(1500)  # 1.5 s: each box falls at most 0.2 m and settles
    expected = {"low": 0.85196, "high": 2.35, "middle": 1.35392}
    for name, z in expected.items():
        assert world.get_pose(name).z == pytest.approx(z, abs=0.01), name


def test_a_concave_static_mesh_in_a_world_holds_a_ball_inside_it(tmp_path: Path, monkeypatch):
    """A static cup (a concave mesh) in a world file is decomposed, not replaced by its hull:
    a ball dropped into it rests on its floor (floor + radius), well below its rim, where the
    hull would hold it at the rim."""
    import numpy as np
    import trimesh

    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path / "cache"))
    floor, rim, inner, outer, radius = 0.08, 0.6, 0.35, 0.42, 0.1  # [m]
    profile = np.array([[0, 0], [outer, 0], [outer, rim], [inner, rim], [inner, floor], [0, floor]])
    trimesh.creation.revolve(profile, sections=16).export(tmp_path / "cup.stl")
    ball = (
        '<model name="ball"><pose>0 0 1.5 0 0 0</pose><link name="b"><inertial><mass>1</mass>'
        "<inertia><ixx>0.004</ixx><iyy>0.004</iyy><izz>0.004</izz></inertia></inertial>"
        f'<collision name="c"><geometry><sphere><radius>{radius}</radius></sphere></geometry>'
        "</collision></link></model>"
    )
    world_file = tmp_path / "cup.world"
    _write(
        world_file,
        '<world name="w"><model name="cup"><static>true</static><link name="l">'
        '<collision name="c"><geometry><mesh><uri>cup.stl</uri></mesh></geometry></collision>'
        f"</link></model>{ball}</world>",
    )
    world = world_from_sdf(world_file)
    world.step(2000)
    z = world.get_pose("ball").z
    assert z == pytest.approx(floor + radius, abs=0.01), f"ball centre at {z:.3f} m"
    assert z < rim, "inside the cup, not on its hull"
