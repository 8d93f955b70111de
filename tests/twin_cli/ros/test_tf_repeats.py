"""`RepeatFilter`: each child frame's transform once per stamp, as tf2's buffer takes them."""

from __future__ import annotations

from twin_cli.record import messages as ros
from twin_cli.record.topics import CLOCK, TF, TF_STATIC, Message, transform_stamped
from twin_cli.ros.tf_repeats import RepeatFilter


def _tf(time: float, *children: str, topic: str = TF.name) -> Message:
    stamp = ros.stamp(time)
    transforms = [
        transform_stamped(stamp, "world", child, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0])
        for child in children
    ]
    return Message(topic, ros.TF, time, ros.types()[ros.TF](transforms=transforms))


def _children(message: Message | None) -> list[str] | None:
    return None if message is None else [t.child_frame_id for t in message.message.transforms]


def test_each_frame_goes_once_per_stamp_and_a_new_frame_goes_alone() -> None:
    repeats = RepeatFilter()
    assert _children(repeats.filter(_tf(1.0, "a/base", "a/arm"))) == ["a/base", "a/arm"]
    assert repeats.filter(_tf(1.0, "a/base", "a/arm")) is None, "a paused world's beat"
    # a spawn while paused: only the new entity's frames, and they decode as a TFMessage
    spawned = repeats.filter(_tf(1.0, "a/base", "a/arm", "b/base"))
    assert _children(spawned) == ["b/base"]
    assert spawned is not None
    decoded = ros.typestore().deserialize_cdr(spawned.cdr(), ros.TF)
    assert [t.child_frame_id for t in decoded.transforms] == ["b/base"], "its bytes"
    assert _children(repeats.filter(_tf(1.01, "a/base", "b/base"))) == ["a/base", "b/base"]
    assert _children(repeats.filter(_tf(0.0, "a/base"))) == ["a/base"], "a reset's stamp is new"


def test_other_topics_pass_as_they_are() -> None:
    clock = Message(CLOCK.name, ros.CLOCK, 1.0, ros.types()[ros.CLOCK](clock=ros.stamp(1.0)))
    repeats = RepeatFilter()
    assert repeats.filter(clock) is clock and repeats.filter(clock) is clock


def test_a_drive_tf_topic_goes_once_per_stamp_and_tf_static_as_it_is() -> None:
    """A gz-sim drive system's `/model/<entity>/tf` is a tf topic of its own: its transform once
    per stamp there, whatever `/tf` sent; `/tf_static` (latched, sent whole) always passes."""
    drive = "/model/vehicle_blue/tf"
    repeats = RepeatFilter()
    assert _children(repeats.filter(_tf(1.0, "vehicle_blue/chassis"))) == ["vehicle_blue/chassis"]
    first = repeats.filter(_tf(1.0, "vehicle_blue/chassis", topic=drive))
    assert _children(first) == ["vehicle_blue/chassis"], "its own topic's first"
    assert repeats.filter(_tf(1.0, "vehicle_blue/chassis", topic=drive)) is None, "a beat"
    assert _children(repeats.filter(_tf(1.01, "vehicle_blue/chassis", topic=drive))) is not None
    static = _tf(1.0, "vehicle_blue/wheel", topic=TF_STATIC.name)
    assert repeats.filter(static) is static and repeats.filter(static) is static
