"""The SDF reader: Gazebo's shapes, surfaces, materials, includes, worlds and its error messages."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from converters import convert
from converters.errors import ConversionError, PackageNotFoundError, SDFError
from converters.gazebo.contact import SOFT_IMPEDANCE, friction_priority
from converters.gazebo.materials import gazebo_rgba
from converters.sdf import read_sdf_world

# The collision lesson's obstacle, as gazebo_ros users spawn it.
LESSON_BOX = """<sdf version="1.6"><model name="test_box"><static>true</static><link name="link">
  <collision name="collision"><geometry><box><size>0.5 0.5 0.5</size></box></geometry></collision>
  <visual name="visual"><geometry><box><size>0.5 0.5 0.5</size></box></geometry>
    <material><script><uri>file://media/materials/scripts/gazebo.material</uri>
    <name>Gazebo/Red</name></script></material></visual></link></model></sdf>"""

INERTIAL = (
    "<inertial><mass>{m}</mass><inertia><ixx>0.01</ixx><iyy>0.02</iyy><izz>0.03</izz>"
    "</inertia></inertial>"
)


def _model(tmp_path: Path, body: str, version: str = "1.8", name: str = "m.sdf") -> Path:
    path = tmp_path / name
    path.write_text(f'<?xml version="1.0"?>\n<sdf version="{version}">\n{body}\n</sdf>\n')
    return path


def _compiled(path: Path) -> mujoco.MjModel:
    spec, _ = convert(path)
    return spec.compile()


def test_lesson_box_is_a_static_red_half_metre_box(tmp_path: Path) -> None:
    model = _compiled(_model(tmp_path, LESSON_BOX.split(">", 1)[1].rsplit("</sdf>", 1)[0]))
    assert model.njnt == 0, "a static model has no joint (welded to the world)"
    sizes = {model.geom(g).name: model.geom_size[g].tolist() for g in range(model.ngeom)}
    assert sizes["link_collision_0"] == pytest.approx([0.25, 0.25, 0.25]), "half extents [m]"
    visual = model.geom("link_visual_0")
    assert visual.rgba.tolist() == pytest.approx(list(gazebo_rgba("Gazebo/Red"))), "Gazebo/Red"
    assert gazebo_rgba("Gazebo/Red")[:3] == (1.0, 0.0, 0.0)


@pytest.mark.parametrize(
    ("shape", "mujoco_type", "size"),
    [
        ("<sphere><radius>0.2</radius></sphere>", mujoco.mjtGeom.mjGEOM_SPHERE, [0.2]),
        (
            "<cylinder><radius>0.1</radius><length>0.6</length></cylinder>",
            mujoco.mjtGeom.mjGEOM_CYLINDER,
            [0.1, 0.3],
        ),
        (
            "<capsule><radius>0.1</radius><length>0.6</length></capsule>",
            mujoco.mjtGeom.mjGEOM_CAPSULE,
            [0.1, 0.3],
        ),
        (
            "<ellipsoid><radii>0.1 0.2 0.3</radii></ellipsoid>",
            mujoco.mjtGeom.mjGEOM_ELLIPSOID,
            [0.1, 0.2, 0.3],
        ),
    ],
)
def test_primitive_shapes_keep_their_sizes(tmp_path: Path, shape, mujoco_type, size) -> None:
    body = (
        f'<model name="m"><link name="l">{INERTIAL.format(m=1)}'
        f'<collision name="c"><geometry>{shape}</geometry></collision></link></model>'
    )
    geom = _compiled(_model(tmp_path, body)).geom("l_collision_0")
    assert geom.type[0] == mujoco_type, "geom type"
    assert geom.size[: len(size)].tolist() == pytest.approx(size), "MuJoCo size [m]"


def test_surface_friction_and_contact_follow_gazebo_rules(tmp_path: Path) -> None:
    surface = (
        "<surface><friction><ode><mu>0.4</mu><mu2>0.3</mu2></ode></friction>"
        "<contact><ode><kp>1e5</kp><kd>50</kd></ode></contact></surface>"
    )
    body = (
        f'<model name="m"><link name="l">{INERTIAL.format(m=2)}<collision name="c">'
        f"<geometry><sphere><radius>0.1</radius></sphere></geometry>{surface}</collision>"
        '<collision name="plain"><geometry><box><size>0.1 0.1 0.1</size></box></geometry>'
        "</collision></link></model>"
    )
    model = _compiled(_model(tmp_path, body))
    tagged, plain = model.geom("l_collision_0"), model.geom("l_collision_1")
    assert tagged.friction[0] == pytest.approx(0.4), "μ1 (MuJoCo is isotropic: μ2 reported)"
    assert tagged.priority[0] == friction_priority(0.4), "min-μ priority"
    assert plain.friction[0] == pytest.approx(1.0) and plain.priority[0] == friction_priority(1.0)
    stiffness = -tagged.solref[0]
    assert stiffness == pytest.approx((1 - SOFT_IMPEDANCE) * 1e5 / 2.0, rel=1e-9), "S [1/s²]"


def test_model_include_resolves_through_model_config_and_overrides(tmp_path, monkeypatch):
    models = tmp_path / "models" / "crate"
    models.mkdir(parents=True)
    (models / "model.config").write_text(
        '<model><name>crate</name><sdf version="1.5">old.sdf</sdf>'
        '<sdf version="1.7">crate.sdf</sdf></model>'
    )
    (models / "crate.sdf").write_text(
        f'<sdf version="1.7"><model name="crate"><link name="body">{INERTIAL.format(m=3)}'
        '<collision name="c"><geometry><box><size>0.2 0.2 0.2</size></box></geometry>'
        "</collision></link></model></sdf>"
    )
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(tmp_path / "models"))
    world = _model(
        tmp_path,
        '<world name="w"><include><uri>model://crate</uri><name>box_a</name>'
        "<pose>1 2 3 0 0 0</pose></include><include><uri>model://ground_plane</uri></include>"
        "</world>",
        name="w.world",
    )
    description = read_sdf_world(world.read_text(), str(world), tmp_path)
    placed = {m.robot.name: m for m in description.models}
    assert sorted(placed) == ["box_a", "ground_plane"], "include <name> renames the model"
    assert placed["box_a"].pose[:3, 3].tolist() == [1.0, 2.0, 3.0], "include <pose> [m]"
    assert placed["box_a"].robot.links[0].inertial.mass == 3.0, "the newest version's file"
    ground = placed["ground_plane"].robot
    assert ground.gazebo.static, "twin's shipped ground_plane is static"
    assert ground.gazebo.surface_of("link", 0).mu1 == 100.0, "Gazebo's ground μ"
    assert ground.gazebo.surface_of("link", 0).mu2 == 50.0, "Gazebo's ground μ2"


def test_a_missing_model_lists_the_places_searched(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(tmp_path / "nowhere"))
    world = _model(
        tmp_path, '<world name="w"><include><uri>model://no_such</uri></include></world>'
    )
    with pytest.raises(PackageNotFoundError) as caught:
        read_sdf_world(world.read_text(), str(world), tmp_path)
    assert "no_such" in str(caught.value) and str(tmp_path / "nowhere") in str(caught.value)


def test_world_physics_gravity_and_models_are_read(tmp_path: Path) -> None:
    world = _model(
        tmp_path,
        '<world name="lab"><physics name="p" type="ode"><max_step_size>0.002</max_step_size>'
        "<real_time_update_rate>500</real_time_update_rate><ode><solver><iters>80</iters>"
        "</solver></ode></physics><gravity>0 0 -1.62</gravity>"
        '<include><uri>model://sun</uri></include><model name="a"><pose>1 0 0.5 0 0 0</pose>'
        f'<link name="l">{INERTIAL.format(m=1)}</link></model></world>',
    )
    description = read_sdf_world(world.read_text(), str(world), tmp_path)
    assert (description.timestep, description.rate, description.iterations) == (0.002, 500, 80)
    assert description.gravity == (0.0, 0.0, -1.62), "gravity [m/s²]"
    assert [m.robot.name for m in description.models] == ["a"], "the sun is a light, not a model"
    assert description.models[0].pose[:3, 3].tolist() == [1.0, 0.0, 0.5]


def test_a_link_without_inertial_gets_sdf_defaults(tmp_path: Path) -> None:
    body = '<model name="m"><link name="l"><collision name="c"><geometry><sphere><radius>0.1'
    model = _compiled(
        _model(tmp_path, body + "</radius></sphere></geometry></collision></link></model>")
    )
    assert model.body("l").mass[0] == pytest.approx(1.0), "SDF default mass [kg]"
    assert model.body("l").inertia.tolist() == pytest.approx([1.0, 1.0, 1.0]), "unit inertia"


def test_floating_model_starts_at_its_link_pose(tmp_path: Path) -> None:
    body = (
        f'<model name="m"><link name="l"><pose>0.1 0.2 0.3 0 0 1.5707963267948966</pose>'
        f"{INERTIAL.format(m=1)}</link></model>"
    )
    model = _compiled(_model(tmp_path, body))
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    assert data.xpos[model.body("l").id].tolist() == pytest.approx([0.1, 0.2, 0.3], abs=1e-12)
    assert model.joint("floating_base").type[0] == mujoco.mjtJoint.mjJNT_FREE
    expected = np.array([np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)])
    assert data.xquat[model.body("l").id] == pytest.approx(expected, abs=1e-12), "yaw 90°"


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        (
            '<model name="m"><link name="a"/><link name="b"/><joint name="j" type="hinge">'
            "<parent>a</parent><child>b</child></joint></model>",
            "type 'hinge'",
        ),
        (
            '<model name="m"><link name="a"/><joint name="j" type="fixed"><parent>a</parent>'
            "<child>ghost</child></joint></model>",
            "frame 'ghost' does not exist",
        ),
        ('<model name="m"><link name="a"><pose>0 0 x 0 0 0</pose></link></model>', "'x'"),
        ('<model name="m"><link name="a"><pose>0 0 1</pose></link></model>', "6 numbers"),
        ('<model name="m"/>', "has no <link>"),
        ('<world name="w"/>', "is a world"),
    ],
)
def test_bad_sdf_names_file_line_and_element(tmp_path: Path, body: str, needle: str) -> None:
    path = _model(tmp_path, body)
    with pytest.raises(ConversionError) as caught:
        convert(path)
    message = str(caught.value)
    assert needle in message, message
    assert f"{path}:" in message, f"file:line missing in {message!r}"


def test_an_unknown_version_is_refused_with_the_versions_twin_reads(tmp_path: Path) -> None:
    path = _model(tmp_path, '<model name="m"><link name="a"/></model>', version="2.0")
    with pytest.raises(SDFError, match=r"'2\.0'.*1\.4.*1\.11"):
        convert(path)


TINYXML_TOLERATES = """<!-- a leading note -->
<?xml version="1.0" ?>
<!--
  Spawn one with: gz service -s /world/w/create --reqtype gz.msgs.EntityFactory --timeout 300
  --req '"<?xml version=\\"1.0\\" ?><sdf version=\\"1.6\\">...'
-->
<sdf version="1.6"><world name="w"><gravity>0 0 -1.62</gravity></world></sdf>"""


def test_sdf_that_sdformats_tinyxml2_reads_is_read(tmp_path):
    # gz-sim's empty.sdf quotes a `gz service --reqtype` command in a comment ('--' is not
    # allowed there); gazebo-classic's cafe.world puts its XML declaration after a comment.
    world = read_sdf_world(TINYXML_TOLERATES, "w.world", tmp_path)
    assert world.gravity == pytest.approx((0.0, 0.0, -1.62))
    broken = TINYXML_TOLERATES.replace("</world>", "</wrold>")
    with pytest.raises(ConversionError, match=r"w\.world:7:.*malformed XML"):
        read_sdf_world(broken, "w.world", tmp_path)


def test_a_link_named_world_is_refused_at_its_line(tmp_path):
    # SDFormat reserves the name for the world frame, which poses and joints resolve against.
    path = tmp_path / "m.sdf"
    path.write_text(
        '<sdf version="1.7"><model name="m">\n<link name="world"/>\n<link name="a"/></model></sdf>'
    )
    with pytest.raises(
        SDFError, match=r"m\.sdf:2: <link name='world'>: .*reserves it\); rename it"
    ):
        convert(path)


def test_an_empty_quat_xyzw_pose_is_the_identity(tmp_path):
    path = tmp_path / "m.sdf"
    path.write_text(
        '<sdf version="1.9"><model name="m"><link name="l"><pose rotation_format="quat_xyzw"/>'
        "<inertial><mass>2</mass></inertial></link></model></sdf>"
    )
    spec, _ = convert(path)
    model = spec.compile()
    assert model.body("l").pos == pytest.approx([0.0, 0.0, 0.0])
    assert model.body("l").quat == pytest.approx([1.0, 0.0, 0.0, 0.0])


FUEL = "https://fuel.gazebosim.org/1.0/OpenRobotics/models"


def _fuel_world(*names: str) -> str:
    includes = "".join(f"<include><uri>{FUEL}/{n}</uri></include>" for n in names)
    return f'<sdf version="1.8"><world name="w">{includes}</world></sdf>'


def test_fuel_models_come_from_the_local_fuel_cache_or_twins_own(tmp_path, monkeypatch):
    # gz-sim's examples and the TurtleBot3 worlds include Fuel URIs; twin never downloads.
    cache = tmp_path / "fuel"
    monkeypatch.setenv("GZ_FUEL_CACHE_PATH", str(cache))
    crate = cache / "fuel.gazebosim.org" / "openrobotics" / "models" / "wooden crate" / "2"
    crate.mkdir(parents=True)
    (crate / "model.sdf").write_text(
        '<sdf version="1.6"><model name="crate"><static>true</static><link name="l">'
        "<collision name='c'><geometry><box><size>1 1 1</size></box></geometry></collision>"
        "</link></model></sdf>"
    )
    world = read_sdf_world(_fuel_world("Ground Plane", "Sun", "Wooden%20Crate"), "w", tmp_path)
    assert [m.robot.name for m in world.models] == ["ground_plane", "crate"]
    assert [light.name for light in world.lights] == ["sun"]
    with pytest.raises(SDFError, match=r"Cafe Table is a Gazebo Fuel model .*`gz fuel download"):
        read_sdf_world(_fuel_world("Cafe Table"), "w", tmp_path)


@pytest.mark.parametrize("version", ["1", "tip"])
def test_a_mesh_named_by_its_fuel_address_comes_from_the_local_fuel_cache(
    tmp_path, monkeypatch, version
):
    """gz-sim's examples name a Fuel model's mesh by its web address
    (`https://HOST/1.0/OWNER/models/NAME/VERSION/files/REL`); gz-sim keeps the download at
    `HOST/owner/models/name/VERSION/REL` in its cache, and twin reads it from there."""
    import trimesh

    cache = tmp_path / "fuel"
    monkeypatch.setenv("GZ_FUEL_CACHE_PATH", str(cache))
    meshes = cache / "fuel.gazebosim.org" / "openrobotics" / "models" / "pump" / "1" / "meshes"
    meshes.mkdir(parents=True)
    trimesh.creation.box(extents=(0.4, 0.2, 0.6)).export(meshes / "pump.stl")
    address = f"{FUEL}/Pump/{version}/files/meshes/pump.stl"
    text = (
        '<sdf version="1.8"><world name="w"><model name="pump"><static>true</static>'
        f"<link name='l'><collision name='c'><geometry><mesh><uri>{address}</uri></mesh>"
        "</geometry></collision></link></model></world></sdf>"
    )
    from twin_cli.world.sdf_world import world_from_sdf

    path = tmp_path / "w.sdf"
    path.write_text(text)
    model = world_from_sdf(path).model
    (geom,) = [g for g in range(model.ngeom) if model.geom(g).name.startswith("pump/")]
    mesh = model.geom_dataid[geom]
    start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
    vertices = model.mesh_vert[start : start + count]
    # MuJoCo turns a mesh onto its principal axes: the box's extents, in any order.
    extents = sorted(vertices.max(axis=0) - vertices.min(axis=0))
    assert extents == pytest.approx([0.2, 0.4, 0.6], abs=1e-6)
    with pytest.raises(Exception, match=r"(?s)is on the web and not in the local Fuel cache.*"
                       r"gz fuel download -u '.*/models/Other/1'"):  # fmt: skip
        path.write_text(text.replace("/Pump/" + version, "/Other/1"))
        world_from_sdf(path)


@pytest.mark.parametrize(
    "address",
    [
        f"{FUEL}/Pump/1/files/../../../../../secret.stl",
        f"{FUEL}/Pump/1/files/meshes%2F..%2F..%2F..%2Fsecret.stl",
        f"{FUEL}/../1/files/secret.stl",
    ],
    ids=["dotdot", "encoded_slash", "dotdot_name"],
)
def test_a_fuel_address_never_reads_outside_its_model_in_the_cache(tmp_path, monkeypatch, address):
    """A file planted next to the cache, where `..` in an address would lead, is not read: the
    address is refused as one not in the cache, naming it."""
    import trimesh

    cache = tmp_path / "fuel"
    monkeypatch.setenv("GZ_FUEL_CACHE_PATH", str(cache))
    (cache / "fuel.gazebosim.org" / "openrobotics" / "models" / "pump" / "1").mkdir(parents=True)
    for planted in (tmp_path, cache, cache / "fuel.gazebosim.org"):
        trimesh.creation.box().export(planted / "secret.stl")
    path = tmp_path / "w.sdf"
    path.write_text(
        '<sdf version="1.8"><world name="w"><model name="p"><static>true</static>'
        f"<link name='l'><collision name='c'><geometry><mesh><uri>{address}</uri></mesh>"
        "</geometry></collision></link></model></world></sdf>"
    )
    from twin_cli.world.sdf_world import world_from_sdf

    with pytest.raises(Exception, match=r"is on the web and not in the local Fuel cache"):
        world_from_sdf(path)
