"""The world's topics as ROS 2's rmw maps them onto DDS: names, QoS, and DDS types built from
rosbags' definitions that read and write the very CDR bytes rosbags does (the oracle)."""

from __future__ import annotations

import pytest

from twin_cli.record import messages as ros
from twin_cli.record.sensor_kinds.imu import IMU
from twin_cli.record.sensor_kinds.ray import SCAN
from twin_cli.record.topics import CLOCK, TF, TF_STATIC, Topic
from twin_cli.ros.graph import (
    DEFAULT_QOS,
    FLOAT64_ARRAY,
    LATCHED_QOS,
    SENSOR_QOS,
    TWIST_STAMPED,
    dds_topic,
    dds_type,
    qos_of,
    user_data,
)


def test_names_are_mapped_as_rmw_maps_them() -> None:
    assert dds_topic("/bot/cmd_vel") == "rt/bot/cmd_vel"
    assert dds_type("sensor_msgs/msg/JointState") == "sensor_msgs::msg::dds_::JointState_"


@pytest.mark.parametrize(
    ("topic", "qos"),
    [
        (CLOCK, DEFAULT_QOS),
        (TF, DEFAULT_QOS),
        (TF_STATIC, LATCHED_QOS),
        (Topic("/bot/robot_description", ros.STRING, latched=True), LATCHED_QOS),
        (Topic("/bot/joint_states", ros.JOINT_STATE), DEFAULT_QOS),
        (Topic("/bot/imu", IMU), SENSOR_QOS),
        (Topic("/bot/scan", SCAN), SENSOR_QOS),
    ],
)
def test_each_topic_has_the_qos_ros_publishers_offer(topic, qos) -> None:
    assert qos_of(topic) == qos
    assert (LATCHED_QOS.transient_local, LATCHED_QOS.depth) == (True, 1)
    assert (SENSOR_QOS.reliable, SENSOR_QOS.depth, DEFAULT_QOS.depth) == (False, 5, 10)


def test_user_data_carries_the_rihs01_type_hash() -> None:
    data = user_data(ros.CLOCK).decode()
    assert data == f"typehash={ros.definition(ros.CLOCK).rihs01};" and "RIHS01_" in data


@pytest.mark.parametrize(
    "name",
    [ros.CLOCK, ros.TF, ros.JOINT_STATE, ros.ODOMETRY, ros.STRING, IMU, SCAN, TWIST_STAMPED,
     FLOAT64_ARRAY, "sensor_msgs/msg/Image"],
)  # fmt: skip
def test_dds_types_read_and_write_rosbags_bytes(name) -> None:
    pytest.importorskip("cyclonedds", reason="cyclonedds is not installed (CI installs it)")
    from twin_cli.ros.graph import idl_type

    idl = idl_type(name)
    assert idl.__idl_typename__ == dds_type(name)
    store = ros.typestore()
    message = _example(store, name)
    cdr = ros.encode(message, name)
    decoded = idl.deserialize(cdr)
    again = decoded.serialize(use_version_2=False)
    padded = cdr.ljust((len(cdr) + 3) & ~3, b"\0")
    assert again[4:] == padded[4 : len(again)], f"{name}: IDL re-encoding differs from rosbags'"
    assert ros.encode(store.deserialize_cdr(again, name), name) == cdr, f"{name}: rosbags reads"


def _example(store, name):
    """A message of type `name` with every field filled (strings, arrays and nested types),
    made from rosbags' own field definitions."""
    import numpy as np

    def value(node, detail):
        if node == 1:
            kind = detail[0]
            return {"string": "frame_a", "bool": True}.get(
                kind, 0.25 if kind.startswith("float") else 3
            )
        if node == 2:
            return build(detail)
        (inner_node, inner), length = detail
        items = [value(inner_node, inner) for _ in range(length or 3)]
        if inner_node == 1 and inner[0] != "string":
            dtype = {"float64": np.float64, "float32": np.float32, "uint8": np.uint8}
            return np.array(items, dtype=dtype.get(inner[0], np.int64))
        return items

    def build(type_name):
        _, fields = store.fielddefs[type_name]
        return store.types[type_name](**{f: value(n, d) for f, (n, d) in fields})

    return build(name)
