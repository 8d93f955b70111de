"""The model's `control` text, one JSON record per motor: written by the MJCF builder and by the
Gazebo plugin stage, so it lives outside both packages and neither imports the other for it."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import mujoco

CONTROL_TEXT = "control"
PID_OFFSET = "pid_offset"  # record key: the constant force [N m or N] a Gazebo PID adds
PID_INTEGRAL = "pid_integral"  # record key: a gz-sim PID's integral bound [N m or N], or None


def control_records(spec: mujoco.MjSpec) -> dict:
    """Each joint's record in the spec's `control` text ({} when it has none)."""
    text = spec.text(CONTROL_TEXT)
    return json.loads(text.data) if text is not None else {}


def set_control_record(spec: mujoco.MjSpec, joint: str, record: dict) -> None:
    """Writes `joint`'s record into the spec's `control` text (created on first use)."""
    records = control_records(spec)
    records[joint] = record
    text = spec.text(CONTROL_TEXT)
    if text is None:
        text = spec.add_text(name=CONTROL_TEXT, data="{}")
    text.data = json.dumps(records)
