"""The topic and frame tags of gz-sim's drive systems (DiffDrive, AckermannSteering,
MecanumDrive), kept as written.

Each system builds its default names from its model's name when it loads (`/model/<model>/cmd_vel`,
`<model>/odom`), and a model takes the name it is spawned under, so the converter keeps only
what the file says; twin makes the names for each entity (`twin_cli.control.drive_names`).
"""

from __future__ import annotations

from dataclasses import dataclass

from converters.gazebo.plugin_params import Params


@dataclass(frozen=True)
class GzNames:
    """The tags a gz-sim drive system (DiffDrive, AckermannSteering, MecanumDrive) names its
    topics and frames with, as written ("" where left out: the system then builds the name from
    its model's name when it loads, `/model/<model>/cmd_vel`, `<model>/odom`, so the name is made
    where the model's name is known: twin names the model after its entity).

    Attributes:
        topic: `<topic>` (cmd_vel); sub_topic: AckermannSteering's `<sub_topic>` (cmd_vel at
        `/model/<model>/<sub_topic>`); odom_topic: `<odom_topic>`; tf_topic: `<tf_topic>`;
        frame_id, child_frame_id: the odometry's frames; canonical_link: the model's canonical
        link (the default child frame is `<model>/<canonical_link>`).
    """

    topic: str = ""
    sub_topic: str = ""
    odom_topic: str = ""
    tf_topic: str = ""
    frame_id: str = ""
    child_frame_id: str = ""
    canonical_link: str = ""


def gz_names(p: Params, canonical_link: str) -> GzNames:
    """A gz-sim drive system's topic and frame tags as written, with the model's canonical
    link (its tree's root link)."""
    return GzNames(
        topic=p.text("", "topic"),
        sub_topic=p.text("", "sub_topic"),
        odom_topic=p.text("", "odom_topic"),
        tf_topic=p.text("", "tf_topic"),
        frame_id=p.text("", "frame_id"),
        child_frame_id=p.text("", "child_frame_id"),
        canonical_link=canonical_link,
    )
