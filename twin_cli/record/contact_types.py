"""gazebo_msgs' contact message types, registered in rosbags' typestore, which lacks them.

rosbags ships no gazebo_msgs (Gazebo classic's package is not part of any ROS 2 distribution it
carries), so ContactState and ContactsState are registered from their definitions below (the
interface of gazebo_ros_bumper); the bag stores the definitions with the messages, so every
reader decodes them. The typestore (`messages`) registers them when it is built and the sensor
messages (`sensor_messages`) build them: both import this module, not each other.
"""

from __future__ import annotations

from typing import Any

CONTACTS = "gazebo_msgs/msg/ContactsState"
CONTACT_DEFINITIONS = {
    "gazebo_msgs/msg/ContactState": """string info
string collision1_name
string collision2_name
geometry_msgs/Wrench[] wrenches
geometry_msgs/Wrench total_wrench
geometry_msgs/Vector3[] contact_positions
geometry_msgs/Vector3[] contact_normals
float64[] depths
""",
    CONTACTS: """std_msgs/Header header
gazebo_msgs/ContactState[] states
""",
}


def register_contact_types(store: Any) -> None:
    """Adds gazebo_msgs' ContactState and ContactsState to a rosbags typestore (idempotent)."""
    if CONTACTS in store.types:
        return
    from rosbags.typesys import get_types_from_msg

    types: dict = {}
    for name, text in CONTACT_DEFINITIONS.items():
        types.update(get_types_from_msg(text, name))
    store.register(types)
