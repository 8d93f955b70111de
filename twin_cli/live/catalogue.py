"""The topics a running world offers (`twin topics`), named and typed as a recording names them.

A recording of the world holds exactly these topics (`twin_cli.record.topics`, and each sensor's
`twin_cli.record.sensor_messages.spec_topic`), so a topic listed live is the one a bag holds:
`/clock`, `/tf`, `/tf_static`, and per entity `joint_states` (anything that moves),
`robot_description` (URDF sources), `odom` (floating bases, under its drive's name for it:
gz-sim's `/model/<entity>/odometry`, with its `/model/<entity>/tf`) and one topic per
sensor. Rates are in Hz of sim time: the state topics are sampled at STATE_RATE (`twin
record`'s default, gazebo_ros' joint_state_publisher's too), a sensor at its `<update_rate>`
(0: every physics step), both capped at the step rate; latched topics have none (sent once, to
each new subscriber).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

from twin_cli.control.drive_names import tf_topic
from twin_cli.errors import TopicNotFoundError
from twin_cli.names import namespace
from twin_cli.record import messages as ros
from twin_cli.record.frames import odom_topic, unique_odom_topics
from twin_cli.record.sensor_messages import spec_topic
from twin_cli.record.topics import CLOCK, TF, TF_STATIC

if TYPE_CHECKING:
    from twin_cli.world.engine import World

STATE_RATE = 100.0  # [Hz] of sim time: joint states, tf, odometry and clock, as `twin record`


@dataclass(frozen=True)
class LiveTopic:
    """One stream of a running world.

    Attributes:
        name: the ROS topic name; type: its message type (`pkg/msg/Type`).
        rate: [Hz] of sim time at which messages come; 0 for a latched topic.
        latched: sent once, then only when it changes (transient local).
        entity: the entity it belongs to, or "" for world-wide topics.
        sensor: the sensor it carries, or "".
        command: a topic twin reads (`twin serve --ros` acts on what a node sends on it:
            `twin_cli.ros.commands`), not one it sends; its rate is 0.
    """

    name: str
    type: str
    rate: float
    latched: bool = False
    entity: str = ""
    sensor: str = ""
    command: bool = False

    def to_dict(self) -> dict:
        return asdict(self)


def live_topics(world: World) -> list[LiveTopic]:
    """Every topic of `world` now, world-wide ones first, then entity by entity (spawn order)."""
    with world.lock:  # a few attribute reads: names, sensors, the step
        step_rate = 1.0 / float(world.model.opt.timestep)
        entities = [(n, world.entity(n), world.index_of(n).free_qpos) for n in world.entity_names()]
        moving = {n: _has_joints(world, n) for n, _, _ in entities}
    state = min(STATE_RATE, step_rate)
    odom = unique_odom_topics(
        {n: odom_topic(n, record.plugins) for n, record, free in entities if free >= 0}
    )
    out = [
        LiveTopic(CLOCK.name, CLOCK.type, state),
        LiveTopic(TF.name, TF.type, state),
        LiveTopic(TF_STATIC.name, TF_STATIC.type, 0.0, latched=True),
    ]
    for name, record, free_qpos in entities:
        if moving[name]:
            topic = f"{namespace(name)}/joint_states"
            out.append(LiveTopic(topic, ros.JOINT_STATE, state, entity=name))
        if record.description:
            out.append(
                LiveTopic(f"{namespace(name)}/robot_description", ros.STRING, 0.0, True, name)
            )
        if free_qpos >= 0:
            out.append(LiveTopic(odom[name], ros.ODOMETRY, state, entity=name))
        drive_tf = tf_topic(name, record.plugins) if free_qpos >= 0 else ""
        if drive_tf and drive_tf != TF.name:
            out.append(LiveTopic(drive_tf, TF.type, state, entity=name))
        for spec in record.sensors:
            topic = spec_topic(name, spec)
            if topic is not None:
                rate = min(spec.update_rate or step_rate, step_rate)
                out.append(LiveTopic(topic.name, topic.type, rate, entity=name, sensor=spec.name))
    return out


def _has_joints(world: World, name: str) -> bool:
    """Whether anything of the entity moves: a joint (its free joint too). A static or welded
    model has none, and no joint_states; a free body's are empty, as joint_state_publisher's
    for a URDF without movable joints."""
    return len(world.index_of(name).joints) > 0


def find_topic(world: World, name: str) -> LiveTopic:
    """The topic called `name` (a missing leading '/' is added, as ros2 does).

    Raises:
        TopicNotFoundError: the world offers no such topic (the message lists those it does).
    """
    wanted = name if name.startswith("/") else f"/{name}"
    topics = live_topics(world)
    for topic in topics:
        if topic.name == wanted:
            return topic
    raise TopicNotFoundError(name, [t.name for t in topics])
