"""`twin model NAME`: one live entity as `gz model -m NAME` shows it.

Client-side (no mujoco or numpy): the server reads the entity under the world's lock and
computes the world poses of its links and tf frames (`twin_cli.live.model`); this prints them,
with its joints (state, command mode, modes offered), drives, sensors and topics.
"""

from __future__ import annotations

from typing import Annotated, Any

import typer

from twin_cli.cli.options import JsonOpt, WorldOpt
from twin_cli.cli.output import Output

POSE_COLUMNS = ["x [m]", "y [m]", "z [m]", "roll", "pitch", "yaw"]


def model(
    name: Annotated[str, typer.Argument(help="The entity (`twin list` names them).")],
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Show a live entity: links and frames with world poses, joints and modes, drives, sensors."""
    from twin_cli.server.connection import connect
    from twin_cli.server.transport import path_segment

    with connect(world, start=False) as client:
        reply = client.request("GET", f"/entities/{path_segment(name)}/model")
    out = Output(json)
    if json:
        out.data(reply)
        return
    pose = " ".join(f"{reply['pose'][k]:.4f}" for k in ("x", "y", "z", "roll", "pitch", "yaw"))
    out.line(f"model [{name}] from {reply['source']} at t={reply['time']:.3f} s, pose {pose}")
    for title, columns, rows in _tables(reply):
        if rows:
            out.table(title, columns, rows)


def _tables(reply: dict[str, Any]) -> list[tuple[str, list[str], list[list[Any]]]]:
    links = {link["frame"] for link in reply["links"]}
    return [
        (
            "links (world poses)",
            ["link", "frame", *POSE_COLUMNS],
            [[link["name"], link["frame"], *_pose(link["pose"])] for link in reply["links"]],
        ),
        (
            "other frames (world poses)",
            ["frame", "parent", *POSE_COLUMNS],
            [
                [f["name"], f["parent"] or "-", *_pose(f["pose"])]
                for f in reply["frames"]
                if f["name"] not in links
            ],
        ),
        (
            "joints",
            ["joint", "type", "position", "velocity", "effort", "mode", "modes"],
            [_joint(j) for j in reply["joints"]],
        ),
        (
            "drives",
            ["drive", "kind", "where"],
            [[d.get("name", "-"), d["kind"], d.get("where", "-")] for d in reply["drives"]],
        ),
        (
            "sensors",
            ["sensor", "type", "link", "rate [Hz]", "topic", "frame"],
            [
                [
                    s["name"],
                    s["type"],
                    s["link"],
                    s["update_rate"],
                    s["ros_topic"] or "-",
                    s["tf_frame"] or "-",
                ]
                for s in reply["sensors"]
            ],  # fmt: skip
        ),
        (
            "topics",
            ["topic", "type", "rate"],
            [
                [t["name"], t["type"], "latched" if t["latched"] else f"{t['rate']:g} Hz"]
                for t in reply["topics"]
            ],
        ),
    ]


def _pose(pose: dict[str, float]) -> list[str]:
    return [f"{pose[k]:.4f}" for k in ("x", "y", "z", "roll", "pitch", "yaw")]


def _joint(joint: dict[str, Any]) -> list[Any]:
    mode = joint["mode"] or ("passive" if not joint["actuated"] else "-")
    return [
        joint["name"], joint["type"], joint["position"], joint["velocity"], joint["effort"],
        mode, ", ".join(joint["modes"]) or "-",
    ]  # fmt: skip


def register(app: typer.Typer) -> None:
    """Adds `model`."""
    app.command("model")(model)
