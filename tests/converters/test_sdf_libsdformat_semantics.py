"""What libsdformat loads, twin loads the same way: placement frames, names, include URIs, 1.6.

- `placement_frame` (1.8) on a `<model>` or an `<include>`, in a world or a model: `<pose>`
  places that frame (a link, joint, frame or nested model), and the model frame follows.
- A scheme-less include URI is looked up beside the file, then on GZ_SIM_RESOURCE_PATH,
  IGN_GAZEBO_RESOURCE_PATH, SDF_PATH, GAZEBO_MODEL_PATH and the `gazebo_model_path` exports of
  ROS packages; `gazebo_media_path` exports serve relative `file://` resources.
- A 1.4-1.6 world frame named like a model becomes `NAME_frame` (then `NAME_frame0`, ...).
Every expected pose is composed by hand from the files' numbers (`X`), every tolerance stated.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from sdf_frame_models import HALF_PI, TOL_M, X, assert_pose
from sdf_libsdformat_models import (
    FRAMES_CONFIG,
    FRAMES_MODEL,
    INERTIAL,
    PLACED,
    PLACEMENT_WORLD,
    STAND,
    model_dir,
    world_link_poses,
)

from converters import convert
from converters.errors import SDFError
from converters.report import Report
from converters.sdf import read_sdf_world
from twin_cli.world.sdf_world import world_from_sdf

PI = np.pi
inv = np.linalg.inv


def _world(tmp_path: Path, body: str, version: str = "1.9") -> Path:
    path = tmp_path / "world.sdf"
    path.write_text(f'<?xml version="1.0"?>\n<sdf version="{version}"><world name="w">\n{body}\n'
                    "</world></sdf>\n")  # fmt: skip
    return path


def _assert_links(poses: dict[str, np.ndarray], expected: dict[str, np.ndarray]) -> None:
    for name, T in expected.items():
        assert_pose(poses[name], T, f"link {name}")


# --- placement frames, hand-written files -------------------------------------------------
def test_world_models_and_includes_place_their_placement_frame(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("GZ_SIM_RESOURCE_PATH", str(model_dir(tmp_path / "models", "stand", STAND)))
    inner = (
        '<model name="arm" placement_frame="inner::tip"><pose>0 0 2 0 0 0</pose>'
        '<model name="inner" placement_frame="tip"><pose>0 0 0.5 0 0 0</pose>'
        f'<link name="tip"><pose>0.2 0 0 0 0 0</pose>{INERTIAL}</link></model></model>'
    )
    path = _world(
        tmp_path,
        f'<frame name="pad"><pose>2 0 0 0 0 {HALF_PI!r}</pose></frame>'
        '<model name="table" placement_frame="leg"><pose>0 0 1 0 0 0</pose>'
        f'<link name="top"><pose>0 0 0.5 0 0 0</pose>{INERTIAL}</link>'
        f'<link name="leg"><pose>0.3 0 -0.2 0 0 0</pose>{INERTIAL}</link>'
        '<joint name="j" type="fixed"><parent>top</parent><child>leg</child></joint></model>'
        '<model name="lamp" placement_frame="socket"><pose relative_to="pad">1 0 0 0 0 0</pose>'
        f'<link name="base">{INERTIAL}</link>'
        f'<frame name="socket"><pose>0 0 0.2 0 0 {HALF_PI!r}</pose></frame></model>'
        "<include><name>stand_a</name><uri>stand</uri><pose>5 0 0 0 0 0</pose>"
        "<placement_frame>foot</placement_frame></include>"
        '<include><name>stand_b</name><uri>stand</uri><pose relative_to="pad">0 0 1 0 0 0</pose>'
        "<placement_frame>mark</placement_frame></include>"
        f'<model name="shelf"><pose>0 5 0 0 0 0</pose><link name="board">{INERTIAL}</link>'
        "<include><name>s</name><uri>stand</uri><pose>1 0 0 0 0 0</pose>"
        f"<placement_frame>foot</placement_frame></include>{inner}</model>",
    )
    poses = world_link_poses(world_from_sdf(path))
    # table: leg (0.3, 0, -0.2) placed at (0, 0, 1): model frame (-0.3, 0, 1.2), top 0.5 above.
    # lamp: pad·(1, 0, 0) = (2, 1, 0) turned 90°; socket⁻¹ = (0, 0, -0.2) turned -90°, so the
    #   model frame (and base on it) is at (2, 1, -0.2), unturned.
    # stand_a: foot⁻¹ = (0.1, 0, 0) turned 180°: model frame (5.1, 0, 0) turned 180°; body 0.5
    #   above it; foot at (5, 0, 0), turned 360°.
    # stand_b: mark (0, 0, 0.8) rolled 90° placed at pad·(0, 0, 1) = (2, 0, 1) turned 90°:
    #   model frame (2, 0, 1) + Rz(90°)·(0, -0.8, 0) = (2.8, 0, 1), R = Rz(90°)·Rx(-90°);
    #   body = (2.8, 0, 1) + R·(0, 0, 0.5) = (2.3, 0, 1); foot = (2.8, 0, 1) + R·(0.1, 0, 0).
    R_b = X(0, 0, 0, 0, 0, HALF_PI) @ X(0, 0, 0, -HALF_PI, 0, 0)
    # shelf at (0, 5, 0): s as stand_a at (1, 0, 0); inner places tip (0.2, 0, 0) at (0, 0, 0.5)
    #   of arm, so arm's tip is at (0, 0, 0.5) and arm places it at (0, 0, 2): tip (0, 5, 2).
    _assert_links(
        poses,
        {
            "table/leg": X(0, 0, 1),
            "table/top": X(-0.3, 0, 1.7),
            "lamp/base": X(2, 1, -0.2),
            "stand_a/body": X(5.1, 0, 0.5, 0, 0, PI),
            "stand_a/foot": X(5, 0, 0),
            "stand_b/body": X(2.3, 0, 1) @ R_b,
            "stand_b/foot": X(2.8, 0.1, 1) @ R_b @ X(0, 0, 0, 0, 0, PI),
            "shelf/board": X(0, 5, 0),
            "shelf/s::body": X(1.1, 5, 0.5, 0, 0, PI),
            "shelf/s::foot": X(1, 5, 0),
            "shelf/arm::inner::tip": X(0, 5, 2),
        },
    )


def test_a_placement_frame_the_model_lacks_is_one_error_naming_its_frames(tmp_path) -> None:
    path = _world(
        tmp_path,
        '<model name="table" placement_frame="lge"><pose>0 0 1 0 0 0</pose>'
        f'<link name="top">{INERTIAL}</link><link name="leg">{INERTIAL}</link></model>',
    )
    with pytest.raises(SDFError, match=r"world\.sdf:3: <model name='table'>: frame 'lge' does "
                       r"not exist in this model; name one of: leg, top, __model__"):  # fmt: skip
        world_from_sdf(path)


@pytest.mark.parametrize(
    "request_pose", [(0, 0, 0, 0, 0, 0), (2, -1, 0.5, 0, 0, HALF_PI), (-3, 4, 1, 0.3, -0.2, 2.5)]
)
def test_a_spawned_model_file_puts_its_model_frame_at_the_request_pose(
    tmp_path, request_pose
) -> None:
    """gz-sim's create service sets a spawned model's pose to the request's, which replaces both
    the file's own `<pose>` and the pose its `placement_frame` would give (libsdformat applies
    that frame only where a world or model places the file: the include case above). `twin
    spawn` always sends a pose (0 by default), as ros_gz_sim's create does."""
    from twin_cli.spawn_request import SpawnRequest
    from twin_cli.world import Pose, World

    path = tmp_path / "stand.sdf"
    path.write_text(STAND.replace('<model name="stand">', '<model name="stand" '
                    'placement_frame="mark"><pose>7 0 3 0 0 1</pose>'))  # fmt: skip
    world = World()
    world.spawn(SpawnRequest(source=str(path)), name="s", pose=Pose(*request_pose))
    where = X(*request_pose)
    # body (0, 0, 0.5) and foot (0.1, 0, 0) turned 180° in the model frame, from STAND.
    _assert_links(
        world_link_poses(world),
        {"s/body": where @ X(0, 0, 0.5), "s/foot": where @ X(0.1, 0, 0, 0, 0, PI)},
    )


# --- placement frames, libsdformat's own test world ---------------------------------------
def _frames_model() -> dict[str, np.ndarray]:
    """Each frame of test_model_with_frames in its model frame, from the file's numbers."""
    F1 = X(0, 0, 0, 1.570796, 0, 0)
    L2 = F1 @ X(1, 0, 0)
    L3 = L2 @ X(0, 1, 0)
    M2 = F1 @ X(1, 0, 0)
    return {
        "__model__": np.eye(4),
        "F2": F1 @ X(0, 0, 0, 0, 0.785398, 0),
        "J2": L3 @ X(0, 0, 1),  # a joint's pose is relative to its child link by default
        "L1": F1,
        "L2": L2,
        "L3": L3,
        "L4": X(0, 0, 1),
        "M2::L5": M2 @ X(1, 0, 0),
    }


def test_libsdformats_placement_frame_world_places_every_frame_where_libsdformat_does(
    tmp_path, monkeypatch
) -> None:
    # libsdformat's expectation: every placement frame is at PLACED in the world (in the parent
    # model's frame, for the includes of parent_model_include, which is at the origin).
    models = tmp_path / "models" / "test_model_with_frames"
    models.mkdir(parents=True)
    (models / "model.sdf").write_text(FRAMES_MODEL)
    (models / "model.config").write_text(FRAMES_CONFIG)
    monkeypatch.setenv("SDF_PATH", str(models.parent))
    path = tmp_path / "placement_frame.sdf"
    path.write_text(PLACEMENT_WORLD)
    poses = world_link_poses(world_from_sdf(path))
    frames, placed = _frames_model(), X(*(float(v) for v in PLACED.split()))
    cases = {
        "no_placement_frame": "__model__",
        "placement_frame_using_link": "L4",
        "placement_frame_using_frame": "F2",
        "placement_frame_using_joint": "J2",
        "placement_frame_using_model": "__model__",
        "include_with_placement_frame_and_pose_relative_to": "L4",
    }
    nested = {f"parent_model_include/{k}::": v for k, v in cases.items() if k[0] == "p"}
    nested["parent_model_include/nested_include_with_placement_frame_and_pose_relative_to::"] = "L4"
    checked = 0
    for prefix, frame in {**{f"{k}/": v for k, v in cases.items()}, **nested}.items():
        X_W_M = placed @ inv(frames[frame])
        for link in ("L1", "L2", "L3", "L4", "M2::L5"):
            assert_pose(poses[prefix + link], X_W_M @ frames[link], f"{prefix}{link}")
            checked += 1
    # The <model placement_frame=...> cases hold copies of parts of the model: L1 at F1,
    # L2/L3 as above, L4 (0, 0, 1) and a nested_model at the model frame.
    own = {
        "model_with_link_placement_frame": ("L4", ["L4"]),
        "model_with_model_placement_frame": ("__model__", ["L4"]),
        "model_with_frame_placement_frame": ("F2", ["L1"]),
        "model_with_joint_placement_frame": ("J2", ["L1", "L2", "L3"]),
        "model_with_placement_frame_and_pose_relative_to": ("L4", ["L4"]),
        "model_with_nested_model_placement_frame": ("__model__", ["L4"]),
    }
    for model, (frame, links) in own.items():
        for link in links:
            expected = placed @ inv(frames[frame]) @ frames[link]
            assert_pose(poses[f"{model}/{link}"], expected, f"{model}/{link}")
            checked += 1
    assert_pose(
        poses["model_with_nested_model_placement_frame/nested_model::L4"],
        placed @ X(0, 0, 1),
        "nested_model::L4",
    )
    assert checked == 11 * 5 + 8, "every link of the 17 models (13 with a placement frame)"


# --- SDFormat 1.6: a world frame named like a model ----------------------------------------
def _box(name: str, pose: str, attributes: str = "") -> str:
    link = f'<link name="L">{INERTIAL}</link>'
    return f'<model name="{name}"><pose{attributes}>{pose}</pose>{link}</model>'


def test_a_1_6_world_frame_named_like_a_model_is_renamed_as_libsdformat_does(tmp_path) -> None:
    # libsdformat's world_model_frame_same_name_1_6.sdf: frame 'ground' becomes 'ground_frame'
    # (0, 0, 3); a second clash goes on to 'ground_frame0'. 'ground' alone means the model.
    path = _world(
        tmp_path,
        _box("base", "1 0 0 0 0 0")
        + _box("ground", "0 2 0 0 0 0")
        + '<frame name="ground"><pose>0 0 3 0 0 0</pose></frame>'
        + _box("lift", "0 4 0 0 0 0")
        + _box("lift_frame", "0 6 0 0 0 0")
        + '<frame name="lift"><pose>0 0 5 0 0 0</pose></frame>'
        + _box("on_frame", "1 0 0 0 0 0", ' frame="ground_frame"')
        + _box("on_model", "1 0 0 0 0 0", ' frame="ground"')
        + _box("on_frame0", "1 0 0 0 0 0", ' frame="lift_frame0"'),
        version="1.6",
    )
    world = world_from_sdf(path)
    poses = world_link_poses(world)
    _assert_links(
        poses,
        {
            "base/L": X(1, 0, 0),
            "ground/L": X(0, 2, 0),
            "lift/L": X(0, 4, 0),
            "lift_frame/L": X(0, 6, 0),
            "on_frame/L": X(1, 0, 3),
            "on_model/L": X(1, 2, 0),
            "on_frame0/L": X(1, 0, 5),
        },
    )
    report = Report(source=str(path))
    read_sdf_world(path.read_text(), str(path), tmp_path, report=report)
    renamed = {e.subject: e.detail for e in report.entries if "renamed" in e.detail}
    assert renamed.keys() == {"world frame 'ground'", "world frame 'lift'"}, report.entries
    assert "'ground_frame'" in renamed["world frame 'ground'"], renamed
    assert "'lift_frame0'" in renamed["world frame 'lift'"], renamed
    masses = world.model.body_mass[[world.model.body(f"{m}/L").id for m in ("base", "ground")]]
    np.testing.assert_allclose(masses, [1.0, 1.0], rtol=0, atol=TOL_M, err_msg="mass [kg]")


def test_from_1_7_a_world_frame_named_like_a_model_stays_an_error(tmp_path) -> None:
    path = _world(
        tmp_path,
        _box("ground", "0 2 0 0 0 0") + '<frame name="ground"><pose>0 0 3 0 0 0</pose></frame>',
        version="1.7",
    )
    with pytest.raises(SDFError, match="the name 'ground' is taken in this world"):
        world_from_sdf(path)


def test_placement_frame_errors_libsdformat_also_refuses(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("GZ_SIM_RESOURCE_PATH", str(model_dir(tmp_path / "models", "stand", STAND)))
    no_pose = _world(
        tmp_path, "<include><uri>stand</uri><placement_frame>foot</placement_frame></include>"
    )
    with pytest.raises(SDFError, match=r"<include>: has <placement_frame>foot</placement_frame> "
                       r"but no <pose>; give the <pose>"):  # fmt: skip
        world_from_sdf(no_pose)
    model = tmp_path / "model.sdf"
    model.write_text(
        '<sdf version="1.8"><model name="m" placement_frame="link3">'
        f'<link name="link1">{INERTIAL}</link><link name="link2">{INERTIAL}</link></model></sdf>'
    )
    with pytest.raises(SDFError, match="frame 'link3' does not exist in this model; name one of: "
                       "link1, link2, __model__"):  # fmt: skip
        convert(model)


def test_a_1_6_model_frame_named_like_its_link_becomes_name_frame(tmp_path) -> None:
    # Inside a model the same rule holds: the later element is renamed, a link keeps its name.
    path = tmp_path / "m.sdf"
    path.write_text(
        '<sdf version="1.6"><model name="m">'
        f'<link name="ground"><pose>0 0 1 0 0 {HALF_PI!r}</pose>{INERTIAL}</link>'
        '<frame name="ground"><pose frame="ground">1 0 0 0 0 0</pose></frame>'
        '<frame name="ground_frame"><pose>0 0 2 0 0 0</pose></frame></model></sdf>'
    )
    model = convert(path)[0].compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    # 'ground' (1, 0, 0) in the link turned 90° at (0, 0, 1): (0, 1, 1); the second frame,
    # clashing with the first one's new name, becomes its own name + _frame: ground_frame_frame.
    for site, expected in (("ground_frame", (0, 1, 1)), ("ground_frame_frame", (0, 0, 2))):
        np.testing.assert_allclose(
            data.site_xpos[model.site(site).id], expected, rtol=0, atol=TOL_M, err_msg=site
        )


# --- names with a prefix: custom elements and gz-sim's undeclared `gz:` -------------------
CUSTOM_PARTS = (  # as gz-sim's example worlds write them, no xmlns declared for gz
    '<plugin filename="gz-sim-sensors-system" name="gz::sim::systems::Sensors">'
    "<gz::system_priority>10</gz::system_priority></plugin>"
    "<gz:policies><physics_engine_name>x</physics_engine_name></gz:policies>"
)


@pytest.mark.parametrize("declared", [False, True], ids=["undeclared_gz", "declared_gz"])
def test_custom_elements_load_as_libsdformat_loads_them_and_are_never_read(
    tmp_path, declared
) -> None:
    """tinyxml2 (libsdformat's parser) knows no namespaces: `<gz:policies>`, `gz:expressed_in=`
    and `<gz::system_priority>` are plain names, undeclared as gz-sim's examples leave them.
    libsdformat copies a prefixed (custom) element and never reads it, so `<gz:link>` inside a
    model adds no link, declared or not; the model's own link is where its pose says."""
    xmlns = ' xmlns:gz="http://gazebosim.org/schema"' if declared else ""
    path = _world(
        tmp_path,
        f'{CUSTOM_PARTS}<model name="m"{xmlns}><pose>1 2 0.5 0 0 0</pose>'
        f'<link name="body">{INERTIAL}<collision name="c"><geometry><box><size>0.2 0.2 0.2'
        "</size></box></geometry><surface><friction><ode><mu>0.7</mu>"
        '<fdir1 gz:expressed_in="body">1 0 0</fdir1></ode></friction></surface></collision>'
        f'</link><gz:link name="ghost">{INERTIAL}</gz:link></model>',
    )
    world = world_from_sdf(path)
    poses = world_link_poses(world)
    assert sorted(poses) == ["m/body"], sorted(poses)
    _assert_links(poses, {"m/body": X(1, 2, 0.5)})
    box = next(g for g in range(world.model.ngeom) if world.model.geom(g).name.startswith("m/"))
    assert world.model.geom_friction[box][0] == pytest.approx(0.7)


@pytest.mark.parametrize(
    ("text", "where"),
    [
        ('<model name="m"><link name="a"></model>', "mismatch"),
        (f"{CUSTOM_PARTS}<gz:open>", "mismatch"),
        ('<model name="m"><link name="a" name="b"/></model>', "redefined|duplicate"),
        (f'{CUSTOM_PARTS}</world></sdf><sdf version="1.9"><world name="x">', "junk after"),
    ],
    ids=["unclosed", "unclosed_custom", "repeated_attribute", "content_after_the_root"],
)
def test_xml_tinyxml2_refuses_too_stays_refused_beside_custom_names(tmp_path, text, where) -> None:
    from converters.errors import MalformedXMLError

    with pytest.raises(MalformedXMLError, match=where):
        world_from_sdf(_world(tmp_path, text))


def test_errors_after_blank_lines_and_custom_names_name_their_own_line(tmp_path) -> None:
    """Blank lines before the XML declaration (tinyxml2 takes them) keep every line's number:
    the repeated attribute is on line 8 of the file."""
    path = tmp_path / "world.sdf"
    path.write_text(
        '\n\n\n<?xml version="1.0"?>\n<sdf version="1.9">\n<world name="w">\n<gz:x/>\n'
        '<model name="a" name="b"/></world></sdf>\n'
    )
    from converters.errors import MalformedXMLError

    with pytest.raises(MalformedXMLError, match=r"world\.sdf:8:"):
        world_from_sdf(path)
