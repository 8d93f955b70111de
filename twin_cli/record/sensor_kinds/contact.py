"""A contact sensor's message: gazebo_msgs/ContactsState (gazebo_ros' bumper), one state per
contact; rosbags lacks the type, so `twin_cli.record.contact_types` registers it."""

from __future__ import annotations

from typing import Any

import numpy as np

from converters.description.sensors import ContactSpec
from twin_cli.record.contact_types import CONTACTS
from twin_cli.record.sensor_messages import ros_message, vector3
from twin_cli.sensors import ContactReading

ZERO = (0.0, 0.0, 0.0)  # [N m] a contact's torque about its own point


@ros_message(ContactSpec, ContactReading, CONTACTS)
def contacts_message(T: Any, header: Any, r: ContactReading) -> Any:
    states = []
    for c in r.states:
        wrench = T["geometry_msgs/msg/Wrench"](force=vector3(T, c.force), torque=vector3(T, ZERO))
        states.append(
            T["gazebo_msgs/msg/ContactState"](
                info=f"{c.collision1} touches {c.collision2}",
                collision1_name=c.collision1,
                collision2_name=c.collision2,
                wrenches=[wrench],
                total_wrench=wrench,
                contact_positions=[vector3(T, c.position)],
                contact_normals=[vector3(T, c.normal)],
                depths=np.array([c.depth]),
            )
        )
    return T[CONTACTS](header=header, states=states)
