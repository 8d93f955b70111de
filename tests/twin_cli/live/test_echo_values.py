"""Echoed messages as JSON values and as `ros2 topic echo` text, on messages built as a recording
builds them (no world: the conversion and the printing are pure)."""

from __future__ import annotations

import math

import numpy as np

from twin_cli.cli.message_text import message_text
from twin_cli.live.echo import plain
from twin_cli.record import messages as ros
from twin_cli.record.topics import transform_stamped


def _scan(ranges: list[float]) -> object:
    T = ros.types()
    header = T["std_msgs/msg/Header"](stamp=ros.stamp(1.5), frame_id="post/scan")
    return T["sensor_msgs/msg/LaserScan"](
        header=header, angle_min=-1.0, angle_max=1.0, angle_increment=0.5, time_increment=0.0,
        scan_time=0.1, range_min=0.1, range_max=3.5,
        ranges=np.array(ranges, dtype=np.float32), intensities=np.zeros(0, dtype=np.float32),
    )  # fmt: skip


def test_plain_keeps_every_field_and_infinity():
    values = plain(_scan([1.0, math.inf, 2.5]))
    assert values["header"] == {
        "stamp": {"sec": 1, "nanosec": 500_000_000},
        "frame_id": "post/scan",
    }
    assert values["ranges"] == [1.0, math.inf, 2.5], "+inf (no return): the client prints .inf"
    assert values["intensities"] == [] and values["range_max"] == 3.5
    assert not any(key.startswith("__") for key in values), "rosbags' type tag is not a field"


def test_long_arrays_and_strings_are_cut_as_ros2_topic_echo_cuts_them():
    values = plain(_scan([1.0] * 200), truncate=128)
    assert len(values["ranges"]) == 129 and values["ranges"][-1] == "...", "128 items, then ..."
    assert len(plain(_scan([1.0] * 200), truncate=0)["ranges"]) == 200, "0: whole"
    text = ros.types()["std_msgs/msg/String"](data="x" * 300)
    assert plain(text, truncate=10) == {"data": "x" * 10 + "..."}


def test_text_is_ros2_topic_echos_yaml():
    stamp = ros.stamp(2.25)
    transform = transform_stamped(stamp, "world", "r/base", [1.0, 2.0, 3.0], [1.0, 0.0, 0.0, 0.0])
    tf = ros.types()[ros.TF](transforms=[transform])
    assert message_text(plain(tf)).splitlines() == [
        "transforms:",
        "- header:",
        "    stamp:",
        "      sec: 2",
        "      nanosec: 250000000",
        "    frame_id: world",
        "  child_frame_id: r/base",
        "  transform:",
        "    translation:",
        "      x: 1.0",
        "      y: 2.0",
        "      z: 3.0",
        "    rotation:",
        "      x: 0.0",
        "      y: 0.0",
        "      z: 0.0",
        "      w: 1.0",
    ]
    scan = message_text(plain(_scan([1.0, math.inf]))).splitlines()
    assert "  frame_id: post/scan" in scan and scan[scan.index("ranges:") + 2] == "- .inf"
    assert "intensities: []" in scan
