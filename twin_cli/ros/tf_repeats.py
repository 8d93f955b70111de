"""`/tf` as tf2 takes it: a frame's transform is sent once per stamp.

tf2's buffer refuses a second transform of a child frame at a stamp it already holds, warning
TF_REPEATED_DATA each time (rclcpp's tf2_ros listeners, RViz, Nav2). A paused world's state is
published again every half second (late joiners of the other topics see it), with the paused
time as its stamp, so its `/tf` carries nothing tf2 would take. `RepeatFilter` leaves out every
transform whose child frame was already sent at that stamp: a paused world's `/tf` goes once,
and a spawn on a paused world sends only the new entity's frames. A stamp that goes back (a
reset, a load) is a new stamp: its transforms go, and tf2's listeners, which watch `/clock` go
back, clear their buffers.
"""

from __future__ import annotations

from typing import Any

from twin_cli.record import messages as ros
from twin_cli.record.topics import TF, TF_STATIC, Message


class RepeatFilter:
    """The `/tf` messages a sink should send: each child frame once per stamp (on `/tf` and on
    every other tf topic that is not latched: a gz-sim drive system's `/model/<entity>/tf`,
    which a user may remap onto `/tf`)."""

    def __init__(self) -> None:
        self._stamps: dict[tuple[str, str], tuple[int, int]] = {}  # (topic, child) → stamp sent

    def filter(self, message: Message) -> Message | None:
        """`message` itself, a tf message of its new transforms only, or None (nothing new).
        Messages of other types, and `/tf_static`, pass as they are."""
        if message.type != TF.type or message.topic == TF_STATIC.name:
            return message
        topic, transforms = message.topic, message.message.transforms
        fresh = [t for t in transforms if self._stamps.get((topic, t.child_frame_id)) != _stamp(t)]
        for transform in fresh:
            self._stamps[(topic, transform.child_frame_id)] = _stamp(transform)
        if len(fresh) == len(transforms):
            return message if fresh else None
        if not fresh:
            return None
        subset = ros.types()[ros.TF](transforms=fresh)
        return Message(message.topic, message.type, message.time, subset)


def _stamp(transform: Any) -> tuple[int, int]:
    """A TransformStamped's stamp as (sec, nanosec)."""
    stamp = transform.header.stamp
    return int(stamp.sec), int(stamp.nanosec)
