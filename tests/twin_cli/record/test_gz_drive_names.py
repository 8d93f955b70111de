"""A gz-sim drive system's ROS names are gz-sim's own, the names ros_gz_bridge bridges them under:
cmd_vel on `/model/<model>/cmd_vel`, odometry on `/model/<model>/odometry` and its transform on
`/model/<model>/tf`, or the topics `<topic>`, `<odom_topic>` and `<tf_topic>` give (a relative
name rooted at `/`, as gz-transport roots it); frames `<model>/odom` → `<model>/<canonical link>`
or `<frame_id>` → `<child_frame_id>` as written, never prefixed twice. The model is the entity:
gz-sim names a model as it is spawned. A static model (no joint, nothing moves) lists no
joint_states.

The robot is gz-sim's diff_drive example's shape (`vehicle_blue`: a chassis link, two wheels and
casters) at the drive tests' size; the bags are read back with rosbags (`record_helpers`).
"""

from __future__ import annotations

from pathlib import Path

import drive_models as dm
import numpy as np
import pytest
from record_helpers import read_bag

from twin_cli.live.catalogue import live_topics
from twin_cli.record.bag_recording import BagRecording
from twin_cli.ros.commands import entity_inputs, with_commands
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World

TWIST = "geometry_msgs/msg/Twist"
ODOMETRY = "nav_msgs/msg/Odometry"
TF = "tf2_msgs/msg/TFMessage"
POSE_TOL = 1e-12  # [m] the tf topic's transform and the odometry are one pose, one route


def _world(tmp_path: Path, tags: str = "", names: tuple[str, ...] = ("vehicle_blue",)) -> World:
    path, ground = tmp_path / "vehicle_blue.sdf", tmp_path / "ground.sdf"
    path.write_text(dm.gz_vehicle(tags))
    ground.write_text(dm.STATIC_GROUND)
    world = World()
    for k, name in enumerate(names):
        world.spawn(SpawnRequest(str(path), on_ground=True), name=name, pose=Pose(y=2.0 * k))
    world.spawn(SpawnRequest(str(ground)), name="ground_plane", pose=Pose(x=5.0))
    return world


def _record(world: World, path: Path, steps: int = 1000) -> dict:
    """A bag of `steps` steps (1 ms each), the first entity driven at 0.2 m/s, 0.5 rad/s."""
    from twin_cli.control import drive

    drive(world, world.entity_names()[0], 0.2, 0.5, None)
    recording = BagRecording(world, path, rate=100.0).start()
    world.step(steps)
    assert recording.stop().error is None
    return read_bag(path)


def _listed(world: World) -> dict[str, tuple[str, str, bool]]:
    """`twin topics`' listing: name → (type, entity, command)."""
    return {t.name: (t.type, t.entity, t.command) for t in with_commands(live_topics(world), world)}


def test_default_names_are_the_systems_under_the_entitys_name(tmp_path: Path) -> None:
    """Two robots from one file: each its own `/model/<entity>/...` and `<entity>/odom`."""
    world = _world(tmp_path, names=("vehicle_blue", "rover"))
    listed = _listed(world)
    for name in ("vehicle_blue", "rover"):
        assert listed[f"/model/{name}/cmd_vel"] == (TWIST, name, True)
        assert listed[f"/model/{name}/odometry"] == (ODOMETRY, name, False)
        assert listed[f"/model/{name}/tf"] == (TF, name, False)
        assert f"/{name}/odom" not in listed and f"/{name}/cmd_vel" not in listed
    assert {i.topic for i in entity_inputs(world)["rover"] if i.mode is None} == {
        "/model/rover/cmd_vel"
    }
    bag = _record(world, tmp_path / "gz.mcap")
    for name in ("vehicle_blue", "rover"):
        odometry = bag[f"/model/{name}/odometry"][-1][1]
        assert (odometry.header.frame_id, odometry.child_frame_id) == (
            f"{name}/odom",
            f"{name}/chassis",
        )
        transform = bag[f"/model/{name}/tf"][-1][1].transforms
        assert [(t.header.frame_id, t.child_frame_id) for t in transform] == [
            (f"{name}/odom", f"{name}/chassis")
        ]
        got = transform[0].transform.translation
        want = odometry.pose.pose.position
        assert np.allclose([got.x, got.y, got.z], [want.x, want.y, want.z], atol=POSE_TOL)
    _one_tree(bag, {"vehicle_blue/odom": "world", "vehicle_blue/chassis": "vehicle_blue/odom"})
    odometry = bag["/model/vehicle_blue/odometry"]
    assert len(odometry) >= 100 and odometry[-1][1].pose.pose.position.x > 0.1, "1 s at 0.2 m/s"


def _one_tree(bag: dict, expected: dict[str, str]) -> None:
    """Every `/tf` and `/tf_static` frame has one parent, `expected` among them, and no frame
    name holds a prefix twice."""
    parents: dict[str, str] = {}
    for topic in ("/tf", "/tf_static"):
        for t in bag[topic][-1][1].transforms:
            assert parents.setdefault(t.child_frame_id, t.header.frame_id) == t.header.frame_id
    for child, parent in expected.items():
        assert parents.get(child) == parent, (child, parents)
    for frame in {*parents, *parents.values()}:
        head = frame.split("/", 1)[0]
        assert not frame.startswith(f"{head}/{head}/"), f"doubled prefix: {frame}"


TAGS = (
    "<topic>cmd_vel</topic><odom_topic>odom</odom_topic><tf_topic>/vehicle/tf</tf_topic>"
    "<frame_id>odom</frame_id><child_frame_id>base_footprint</child_frame_id>"
)


@pytest.mark.parametrize(
    ("tags", "cmd_vel", "odom", "tf", "frames"),
    [
        (TAGS, "/cmd_vel", "/odom", "/vehicle/tf", ("odom", "base_footprint")),
        (
            "<topic>/robot/cmd vel/</topic><odom_topic>/robot//odometry</odom_topic>"
            "<tf_topic>/tf</tf_topic><frame_id>map</frame_id>",
            "/robot/cmd_vel",
            "/robot/odometry",
            "",
            ("map", "vehicle_blue/chassis"),
        ),
    ],
    ids=["relative", "absolute"],
)
def test_the_systems_tags_name_its_topics_and_frames(
    tmp_path: Path, tags: str, cmd_vel: str, odom: str, tf: str, frames: tuple[str, str]
) -> None:
    """A relative `<topic>` is rooted at `/`; a space becomes `_`, `//` and a trailing `/` go
    (gz-transport); `<tf_topic>/tf</tf_topic>` is the world's `/tf`, which carries the
    transform already. A `<child_frame_id>` that is no link's frame hangs from the odometry
    frame at the root link, the root link's frame fixed under it."""
    world = _world(tmp_path, tags)
    listed = _listed(world)
    assert listed[cmd_vel] == (TWIST, "vehicle_blue", True)
    assert listed[odom] == (ODOMETRY, "vehicle_blue", False)
    assert "/model/vehicle_blue/odometry" not in listed and "/model/vehicle_blue/tf" not in listed
    if tf:
        assert listed[tf] == (TF, "vehicle_blue", False)
    bag = _record(world, tmp_path / "tags.mcap")
    odometry = bag[odom][-1][1]
    assert (odometry.header.frame_id, odometry.child_frame_id) == frames
    tree = {frames[0]: "world", frames[1]: frames[0]}
    if frames[1] != "vehicle_blue/chassis":
        tree["vehicle_blue/chassis"] = frames[1]
    _one_tree(bag, tree)


def test_twin_odom_names_the_frames_for_the_entity(tmp_path: Path) -> None:
    """`twin odom` on a robot spawned as `rover` from the file of `vehicle_blue`."""
    from twin_cli.control import odometry

    world = _world(tmp_path, names=("rover",))
    reply = odometry(world, "rover")
    assert (reply["odometry_frame"], reply["robot_base_frame"]) == ("rover/odom", "rover/chassis")


def test_a_static_model_lists_no_joint_states(tmp_path: Path) -> None:
    """The static ground lists nothing of its own, and a bag holds no joint_states of it."""
    world = _world(tmp_path)
    listed = _listed(world)
    assert "/vehicle_blue/joint_states" in listed
    assert not [name for name, row in listed.items() if row[1] == "ground_plane"], listed
    bag = _record(world, tmp_path / "static.mcap", steps=20)
    assert "/ground_plane/joint_states" not in bag and "/vehicle_blue/joint_states" in bag


GZ_ACKERMANN = (
    '<plugin filename="gz-sim-ackermann-steering-system" '
    'name="gz::sim::systems::AckermannSteering"><left_joint>rear_left_joint</left_joint>'
    "<right_joint>rear_right_joint</right_joint><left_steering_joint>left_steering_joint"
    "</left_steering_joint><right_steering_joint>right_steering_joint</right_steering_joint>"
    f"<wheel_base>{dm.WHEEL_BASE}</wheel_base><wheel_separation>{dm.TRACK}</wheel_separation>"
    f"<wheel_radius>{dm.R}</wheel_radius><sub_topic>drive</sub_topic></plugin>"
)
GZ_MECANUM = (
    '<plugin filename="gz-sim-mecanum-drive-system" name="gz::sim::systems::MecanumDrive">'
    "<front_left_joint>left_front_joint</front_left_joint><front_right_joint>right_front_joint"
    "</front_right_joint><back_left_joint>left_rear_joint</back_left_joint><back_right_joint>"
    "right_rear_joint</back_right_joint><wheel_separation>0.3</wheel_separation><wheelbase>0.12"
    f"</wheelbase><wheel_radius>{dm.R}</wheel_radius></plugin>"
)


def test_ackermann_steering_and_mecanum_drive_are_named_as_diff_drive(tmp_path: Path) -> None:
    """AckermannSteering's `<sub_topic>` S takes cmd_vel on `/model/<model>/S`; MecanumDrive's
    names are DiffDrive's (a URDF robot: its root link is `base_link`)."""
    car, mover = tmp_path / "car.sdf", tmp_path / "mover.urdf"
    car.write_text(dm.sdf_ackermann(GZ_ACKERMANN))
    mover.write_text(dm.skid_steer_bot(GZ_MECANUM))
    world = World()
    world.spawn(SpawnRequest(str(car), on_ground=True), name="car")
    world.spawn(SpawnRequest(str(mover), on_ground=True), name="mecanum", pose=Pose(y=2.0))
    listed = _listed(world)
    assert listed["/model/car/drive"] == (TWIST, "car", True)
    assert listed["/model/mecanum/cmd_vel"] == (TWIST, "mecanum", True)
    bag = _record(world, tmp_path / "families.mcap", steps=100)
    for name in ("car", "mecanum"):
        odometry = bag[f"/model/{name}/odometry"][-1][1]
        frames = (odometry.header.frame_id, odometry.child_frame_id)
        assert frames == (f"{name}/odom", f"{name}/base_link")
        transform = bag[f"/model/{name}/tf"][-1][1].transforms[0]
        assert (transform.header.frame_id, transform.child_frame_id) == frames
