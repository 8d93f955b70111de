"""SDF files as found in public Gazebo model repositories load as libsdformat reads them.

Each case is a small file written here in the shape the public one has: a plane visual on a
flying link (PX4's x500), `<include merge="true">`, a byte-order mark, `file://` meshes under
a Gazebo resource path, false flags, a static model without physical inertia. Expected poses
are composed by hand from the SDFormat specification's rules, stated beside each.
"""

from __future__ import annotations

import os
from pathlib import Path

import mujoco
import pytest

from converters import convert
from converters.errors import InertiaError, ResourceNotFoundError
from converters.formats import format_of
from converters.pipeline import convert_full
from converters.report import Outcome

TOL = 1e-9  # [m] and unit-vector components
HALF_PI = "1.5707963267948966"
INERTIAL = (
    "<inertial><mass>{m}</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz>"
    "</inertia></inertial>"
)
BOX = "<geometry><box><size>0.1 0.1 0.1</size></box></geometry>"


def _file(path: Path, body: str, version: str = "1.9") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f'<?xml version="1.0"?>\n<sdf version="{version}">\n{body}\n</sdf>\n')
    return path


def _positions(spec: mujoco.MjSpec) -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return model, data


def _details(report, outcome: Outcome) -> str:
    return "\n".join(f"{e.subject}: {e.detail}" for e in report.of(outcome))


# ------------------------------------------------------------------ visual-only geometry


def test_a_plane_visual_on_a_flying_link_is_drawn_not_refused(tmp_path: Path) -> None:
    # PX4's x500 carries a <plane> visual on its (non-static) base link; MuJoCo takes plane
    # geoms on static bodies only. A finite one is drawn as a thin box of its size (0.3 × 0.2 m
    # → half extents 0.15, 0.1); an infinite one (size 0 0) is left out, and said.
    path = _file(
        tmp_path / "m.sdf",
        f'<model name="m"><link name="base">{INERTIAL.format(m=1)}'
        '<visual name="logo"><geometry><plane><normal>0 0 1</normal><size>0.3 0.2</size>'
        '</plane></geometry></visual><visual name="sky"><geometry><plane><normal>0 0 1</normal>'
        '</plane></geometry></visual><visual name="terrain"><geometry><heightmap><uri>h.png</uri>'
        f'<size>1 1 1</size></heightmap></geometry></visual><collision name="c">{BOX}</collision>'
        "</link></model>",
    )
    spec, report = convert(path)
    model, _ = _positions(spec)
    logo = model.geom("base_visual_0")
    assert logo.type[0] == mujoco.mjtGeom.mjGEOM_BOX
    assert logo.size[:2] == pytest.approx([0.15, 0.1]), "half the plane's size [m]"
    assert logo.contype[0] == 0 and logo.conaffinity[0] == 0, "a visual never collides"
    ignored = _details(report, Outcome.IGNORED)
    assert "infinite plane" in ignored and "heightmap" in ignored, ignored


def test_a_plane_on_a_static_model_stays_a_plane(tmp_path: Path) -> None:
    path = _file(
        tmp_path / "m.sdf",
        '<model name="floor"><static>true</static><link name="l"><collision name="c"><geometry>'
        "<plane><normal>0 0 1</normal><size>10 10</size></plane></geometry></collision></link>"
        "</model>",
    )
    model, _ = _positions(convert(path)[0])
    assert model.geom("l_collision_0").type[0] == mujoco.mjtGeom.mjGEOM_PLANE


# ------------------------------------------------------------------ include merge="true"


def _x500(tmp_path: Path) -> Path:
    """PX4's x500 shape: a model that merges its base from model://x500_base."""
    _file(
        tmp_path / "models" / "x500_base" / "model.sdf",
        '<model name="x500_base"><pose>5 5 5 0 0 0</pose>'
        f'<link name="base_link">{INERTIAL.format(m=2)}<visual name="v"><geometry><plane>'
        "<normal>0 0 1</normal><size>0.3 0.3</size></plane></geometry></visual></link>"
        f'<link name="rotor_0"><pose>0.1 0 0.05 0 0 -{HALF_PI}</pose>{INERTIAL.format(m=0.1)}'
        "</link>"
        '<joint name="rotor_0_joint" type="revolute"><parent>base_link</parent>'
        '<child>rotor_0</child><axis><xyz expressed_in="__model__">1 0 0</xyz></axis></joint>'
        '<frame name="imu"><pose>0 0 0.01 0 0 0</pose></frame></model>',
    )
    return _file(
        tmp_path / "x500" / "model.sdf",
        '<model name="x500"><include merge="true"><uri>model://x500_base</uri>'
        f"<pose>0 0 0.5 0 0 {HALF_PI}</pose></include>"
        '<frame name="camera" attached_to="base_link"><pose relative_to="base_link">'
        "1 0 0 0 0 0</pose></frame>"
        '<plugin filename="gz-sim-multicopter-motor-model-system" name="motor">'
        "<jointName>rotor_0_joint</jointName></plugin></model>",
    )


def test_a_merged_include_splices_the_model_in_without_a_scope(tmp_path: Path) -> None:
    env = {"GAZEBO_MODEL_PATH": str(tmp_path / "models")}
    done = convert_full(_x500(tmp_path), env=env)
    robot = done.description
    assert [link.name for link in robot.links] == ["base_link", "rotor_0"], "names as written"
    assert [j.name for j in robot.joints] == ["rotor_0_joint"], "no x500_base:: prefix"
    assert "rotor_0_joint" in robot.gazebo.plugins[0].xml
    model, data = _positions(done.spec)
    # The include's pose (0 0 0.5, yaw 90°) replaces the model's own (5 5 5) and places the
    # proxy frame _merged__x500_base__model__ in x500's frame; base_link sits on it, and
    # rotor_0 at (0, 0, 0.5) + Rz(90°)·(0.1, 0, 0.05) = (0, 0.1, 0.55).
    proxy = data.site_xpos[model.site("_merged__x500_base__model__").id]
    assert proxy == pytest.approx([0.0, 0.0, 0.5], abs=TOL)
    assert data.xpos[model.body("base_link").id] == pytest.approx([0.0, 0.0, 0.5], abs=TOL)
    assert data.xpos[model.body("rotor_0").id] == pytest.approx([0.0, 0.1, 0.55], abs=TOL)
    # imu is attached to the merged model frame: (0, 0, 0.5 + 0.01); camera is 1 m along
    # base_link's x, which Rz(90°) turns to +y: (0, 1, 0.5).
    assert data.site_xpos[model.site("imu").id] == pytest.approx([0.0, 0.0, 0.51], abs=TOL)
    assert data.site_xpos[model.site("camera").id] == pytest.approx([0.0, 1.0, 0.5], abs=TOL)
    # rotor_0 turns back by -90°, so its frame is x500's; the axis was expressed in the merged
    # model's frame, so it is Rz(90°)·(1, 0, 0) = (0, 1, 0), not x500's (1, 0, 0).
    joint = model.joint("rotor_0_joint").id
    assert data.xaxis[joint] == pytest.approx([0.0, 1.0, 0.0], abs=TOL)


# ------------------------------------------------------------------ byte-order mark


def test_a_model_file_with_a_byte_order_mark_loads(tmp_path: Path) -> None:
    bom = "\ufeff"
    assert format_of(bom + '<?xml version="1.0"?><sdf version="1.6"/>') == "sdf"
    assert format_of(bom + '<robot name="r"/>') == "urdf"
    sdf = tmp_path / "bom.sdf"
    sdf.write_text(
        bom + f'<sdf version="1.6"><model name="b"><link name="l">{INERTIAL.format(m=1)}'
        "</link></model></sdf>",
        encoding="utf-8",
    )
    urdf = tmp_path / "bom.urdf"
    urdf.write_text(
        bom + '<?xml version="1.0"?><robot name="r"><link name="l"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        "</robot>",
        encoding="utf-8",
    )
    assert sdf.read_bytes()[:3] == b"\xef\xbb\xbf"
    for path in (sdf, urdf):
        model, _ = _positions(convert(path)[0])
        assert model.body("l").mass[0] == pytest.approx(1.0)


# ------------------------------------------------------------------ file:// resources

CUBE_OBJ = "\n".join(
    [f"v {x} {y} {z}" for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    + ["f 1 3 4 2", "f 5 6 8 7", "f 1 2 6 5", "f 3 7 8 4", "f 1 5 7 3", "f 2 4 8 6"]
)


def _mesh_model(tmp_path: Path, role: str = "collision") -> Path:
    return _file(
        tmp_path / "robot" / "model.sdf",
        f'<model name="m"><link name="l">{INERTIAL.format(m=1)}<{role} name="v"><geometry>'
        f"<mesh><uri>file://media/cube.obj</uri></mesh></geometry></{role}></link></model>",
        version="1.6",
    )


def test_a_file_uri_is_found_on_the_gazebo_resource_path(tmp_path: Path) -> None:
    # Not beside the model: under the second GAZEBO_RESOURCE_PATH entry.
    (tmp_path / "share" / "media").mkdir(parents=True)
    (tmp_path / "share" / "media" / "cube.obj").write_text(CUBE_OBJ)
    search = os.pathsep.join([str(tmp_path / "empty"), str(tmp_path / "share")])
    done = convert_full(_mesh_model(tmp_path), env={"GAZEBO_RESOURCE_PATH": search})
    mesh = done.description.links[0].collisions[0].geometry.mesh
    assert mesh == tmp_path / "share" / "media" / "cube.obj"


def test_a_file_uri_found_nowhere_lists_every_place_tried(tmp_path: Path) -> None:
    search = os.pathsep.join([str(tmp_path / "a"), str(tmp_path / "b")])
    with pytest.raises(ResourceNotFoundError) as caught:
        convert_full(_mesh_model(tmp_path), env={"GZ_SIM_RESOURCE_PATH": search})
    message = str(caught.value)
    for place in ("robot", "a", "b"):
        assert str(tmp_path / place / "media" / "cube.obj") in message, message
    assert "GAZEBO_RESOURCE_PATH" in message, "the fix names the variable"
    # A visual that is found nowhere is left out, as Gazebo draws nothing for it, and said
    # with the same list.
    env = {"GZ_SIM_RESOURCE_PATH": search}
    report = convert_full(_mesh_model(tmp_path, "visual"), env=env).report
    warnings = _details(report, Outcome.WARNING)
    assert "left out" in warnings and str(tmp_path / "b" / "media" / "cube.obj") in warnings


# ------------------------------------------------------------------ flags and inertia


def test_a_false_kinematic_flag_says_nothing_and_a_true_one_is_reported(tmp_path: Path) -> None:
    links = "".join(
        f'<link name="{name}"><pose>{i} 0 0 0 0 0</pose>{INERTIAL.format(m=1)}'
        f"<kinematic>{value}</kinematic><enable_wind>{value}</enable_wind></link>"
        for i, (name, value) in enumerate((("off", "0"), ("no", "false"), ("on", "true")))
    )
    _, report = convert(_file(tmp_path / "m.sdf", f'<model name="m">{links}</model>'))
    ignored = _details(report, Outcome.IGNORED)
    assert "link 'on' <kinematic>" in ignored and "link 'on' <enable_wind>" in ignored
    assert "'off'" not in ignored and "'no'" not in ignored, ignored


ZERO_INERTIA = (
    "<inertial><mass>1</mass><inertia><ixx>0</ixx><iyy>0</iyy><izz>0</izz></inertia></inertial>"
)


def test_a_static_model_without_physical_inertia_converts(tmp_path: Path) -> None:
    # Gazebo never moves a static model, so never reads its inertia: convert takes it as
    # `twin serve` does, and says so.
    body = f'<link name="l">{ZERO_INERTIA}<collision name="c">{BOX}</collision></link>'
    static = _file(tmp_path / "s.sdf", f'<model name="s"><static>true</static>{body}</model>')
    spec, report = convert(static)
    model, _ = _positions(spec)
    assert model.njnt == 0, "welded to the world"
    assert "unused in a static model" in _details(report, Outcome.REPAIRED)
    moving = _file(tmp_path / "d.sdf", f'<model name="d">{body}</model>')
    with pytest.raises(InertiaError):
        convert(moving)


def test_a_merged_include_with_a_placement_frame_places_that_frame(tmp_path: Path) -> None:
    # The include's pose places the model's `foot` link, 0.1 m below its model frame, at
    # (1, 0, 0) turned 90°: the model frame is then at (1, 0, 0) + Rz(90°)·(0, 0, 0.1) =
    # (1, 0, 0.1), and so is `body`, which sits on the model frame.
    _file(
        tmp_path / "models" / "stand" / "model.sdf",
        f'<model name="stand"><link name="body">{INERTIAL.format(m=1)}</link>'
        f'<link name="foot"><pose>0 0 -0.1 0 0 0</pose>{INERTIAL.format(m=1)}</link>'
        '<joint name="weld" type="fixed"><parent>body</parent><child>foot</child></joint></model>',
    )
    path = _file(
        tmp_path / "robot.sdf",
        '<model name="robot"><include merge="true"><uri>model://stand</uri>'
        f"<placement_frame>foot</placement_frame><pose>1 0 0 0 0 {HALF_PI}</pose></include>"
        "</model>",
    )
    done = convert_full(path, env={"GAZEBO_MODEL_PATH": str(tmp_path / "models")})
    model, data = _positions(done.spec)
    assert data.xpos[model.body("body").id] == pytest.approx([1.0, 0.0, 0.1], abs=TOL)
    proxy = data.site_xpos[model.site("_merged__stand__model__").id]
    assert proxy == pytest.approx([1.0, 0.0, 0.1], abs=TOL)


def test_a_heightmap_image_that_is_not_square_is_refused_at_its_line(tmp_path: Path) -> None:
    from PIL import Image

    from converters.errors import SDFError

    Image.new("L", (9, 5)).save(tmp_path / "h.png")
    path = _file(
        tmp_path / "t.sdf",
        '<model name="t"><static>true</static><link name="l"><collision name="c">\n'
        "<geometry><heightmap><uri>h.png</uri></heightmap></geometry></collision></link></model>",
    )
    with pytest.raises(SDFError, match=r"t\.sdf:4.*5×9 pixels, not square"):
        convert(path)


def test_a_visual_mesh_that_cannot_be_read_is_left_out_a_collision_one_refused(
    tmp_path: Path,
) -> None:
    from converters.errors import MeshError

    (tmp_path / "empty.stl").write_bytes(b"empty".ljust(80, b" ") + bytes(4))  # no triangles
    mesh = "<geometry><mesh><uri>empty.stl</uri></mesh></geometry>"
    link = f'<link name="l">{INERTIAL.format(m=1)}<visual name="v">{mesh}</visual>'
    spec, report = convert(_file(tmp_path / "v.sdf", f'<model name="v">{link}</link></model>'))
    assert spec.compile().ngeom == 0, "the visual is left out, nothing else to draw"
    assert "empty.stl" in _details(report, Outcome.WARNING)
    collision = f'<link name="l">{INERTIAL.format(m=1)}<collision name="c">{mesh}</collision>'
    with pytest.raises(MeshError, match="empty.stl"):
        convert(_file(tmp_path / "c.sdf", f'<model name="c">{collision}</link></model>'))


def test_a_heightmap_model_converts_on_its_own_to_a_height_field(tmp_path: Path) -> None:
    """`twin convert`/`twin spawn` of a terrain model, not only a served world: a 4 m × 4 m
    heightmap is a MuJoCo height field of half-extents 2 m × 2 m, centred on its <pos>."""
    import numpy as np
    from PIL import Image

    from converters.pipeline import convert_full

    image = np.zeros((9, 9), np.uint8)
    image[:, 5:] = 255
    Image.fromarray(image).save(tmp_path / "terrain.png")
    (tmp_path / "terrain.sdf").write_text(
        '<sdf version="1.6"><model name="terrain"><static>true</static><link name="l">'
        '<collision name="c"><geometry><heightmap><uri>terrain.png</uri><size>4 4 2</size>'
        "<pos>1 0 0.25</pos></heightmap></geometry></collision></link></model></sdf>"
    )
    model = convert_full(tmp_path / "terrain.sdf").spec.compile()
    assert model.nhfield == 1, "one height field"
    assert model.hfield_size[0][:2] == pytest.approx([2.0, 2.0]), "half-extents [m]"
    import mujoco

    (geom,) = [g for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_HFIELD]
    assert model.geom_pos[geom][:2] == pytest.approx([1.0, 0.0]), "centred on <pos> x, y [m]"


@pytest.mark.parametrize("fixed_base", [False, True])
def test_a_heightmap_on_a_root_welded_by_fixed_base_is_kept(
    tmp_path: Path, fixed_base: bool
) -> None:
    """A heightmap on a model that is not `<static>` rides a moving link and is left out
    (MuJoCo's height fields are static); `--fixed-base` welds that link to the world, so the
    terrain is kept, with no warning about a moving link."""
    import numpy as np
    from PIL import Image

    from converters.mjcf.builder import ConvertOptions

    Image.fromarray(np.zeros((9, 9), np.uint8)).save(tmp_path / "terrain.png")
    (tmp_path / "terrain.sdf").write_text(
        f'<sdf version="1.6"><model name="terrain"><link name="l">{INERTIAL.format(m=1)}'
        '<collision name="c"><geometry><heightmap><uri>terrain.png</uri><size>4 4 2</size>'
        "</heightmap></geometry></collision></link></model></sdf>"
    )
    done = convert_full(tmp_path / "terrain.sdf", options=ConvertOptions(fixed_base=fixed_base))
    model = done.spec.compile()
    fields = [g for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_HFIELD]
    assert len(fields) == int(fixed_base), "a height field only on the welded root"
    moving = "heightmap on a moving link" in _details(done.report, Outcome.WARNING)
    assert moving is not fixed_base, "the warning only where the link moves"
