"""`twin delete`, `list`, `pose`, `joints`, `push`: one entity of a running world at a time."""

from __future__ import annotations

from twin_cli.cli.output import Output
from twin_cli.cli.params import JSON, NAME, POSE_KEYS, WORLD, Vec3
from twin_cli.cli.registry import Opt, command, flag
from twin_cli.cli.world_client import connect_world


def quat_of(pose: dict) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a reply's roll-pitch-yaw (R = Rz(yaw)·Ry(pitch)·Rx(roll))."""
    import math

    cr, sr = math.cos(pose["roll"] / 2), math.sin(pose["roll"] / 2)
    cp, sp = math.cos(pose["pitch"] / 2), math.sin(pose["pitch"] / 2)
    cy, sy = math.cos(pose["yaw"] / 2), math.sin(pose["yaw"] / 2)
    return (
        cy * cp * sr - sy * sp * cr,
        cy * sp * cr + sy * cp * sr,
        sy * cp * cr - cy * sp * sr,
        cy * cp * cr + sy * sp * sr,
    )


def _pose_text(pose: dict) -> str:
    """`x y z roll pitch yaw` as `gz model -p` prints it (rounding first: no `-0.000000`)."""
    return " ".join(f"{round(float(pose[k]), 6) + 0.0:.6f}" for k in POSE_KEYS)


@command("delete", NAME, WORLD, help="Delete an entity.")
def delete(*, name: str, world: str) -> None:
    with connect_world(world) as c:
        c.delete(name)


@command("list", WORLD, JSON, help="List the entities in the world.")
def list_(*, world: str, json: bool) -> None:
    with connect_world(world) as c:
        rows = c.entities()
    out = Output(json)
    if json:
        out.data(rows)
        return
    out.table(
        "entities",
        ["name", "x", "y", "z", "joints", "source", "hull stand-ins", "decomposition"],
        [
            [e["name"], *e["position"], e["n_joints"], e["source"], _stand_ins(e), _state(e)]
            for e in rows
        ],
    )
    for e in rows:
        for mesh in e.get("hull_stand_ins", []):
            out.line(f"{e['name']}: convex hull stands in for {mesh}")


def _stand_ins(entity: dict) -> str:
    """How many collision meshes of an entity are convex hulls standing in for their
    decomposition ("-" for none); an older server sends no such field."""
    count = len(entity.get("hull_stand_ins", []))
    return str(count) if count else "-"


DECOMPOSITION_STATES = {"pending": "pending", "done": "done", "failed": "failed (hull kept)"}


def _state(entity: dict) -> str:
    """Where the background decomposition of an entity's collision meshes is ("-": it had
    none, or an older server)."""
    return DECOMPOSITION_STATES.get(entity.get("decomposition") or "", "-")


@command(
    "pose",
    NAME,
    Opt(("--set",), "set_", "Move it: X Y Z (m) ROLL PITCH YAW (rad).", float, nargs=6),
    WORLD,
    JSON,
    flag("--quat", dest="quat", help="Print x y z qx qy qz qw (a quaternion)."),
    help="Print an entity's pose as `x y z roll pitch yaw` (or move it with --set).",
)
def pose(
    *, name: str, set_: tuple[float, ...] | None, world: str, json: bool, quat: bool = False
) -> None:
    """Print (or set) an entity's pose; `quat` prints `x y z qx qy qz qw` (geometry_msgs order)."""
    with connect_world(world) as c:
        if set_ is None:
            result = c.pose(name)
        else:
            result = c.set_pose(name, dict(zip(POSE_KEYS, set_, strict=True)))
    out = Output(json)
    if quat:
        result = {**result, "quat": list(quat_of(result))}
    if json:
        out.data(result)
    elif quat:
        values = [result[k] for k in POSE_KEYS[:3]] + result["quat"]
        out.line(" ".join(f"{round(float(v), 6) + 0.0:.6f}" for v in values))
    else:
        out.line(_pose_text(result))


@command(
    "joints",
    NAME,
    WORLD,
    JSON,
    help="Print an entity's joint positions, velocities and efforts.",
)
def joints(*, name: str, world: str, json: bool) -> None:
    with connect_world(world) as c:
        rows = c.joints(name)
        control = {j["name"]: j for j in c.joint_control(name)}
    # each actuated joint's active mode ("none": zero effort), target and offered modes
    for row in rows:
        extra = control.get(row["name"], {})
        row.update(mode=extra.get("mode"), target=extra.get("target"), modes=extra.get("modes"))
    out = Output(json)
    if json:
        out.data(rows)
        return
    out.table(
        f"joints of {name}",
        ["joint", "mode", "offers", "target", "position", "velocity", "effort"],
        [
            [j["name"], j["mode"] or "-", ",".join(j["modes"] or []) or "-", j["target"]]
            + [j["position"], j["velocity"], j["effort"]]
            for j in rows
        ],
    )


@command(
    "push",
    NAME,
    Opt(("--force",), "force", "Force FX FY FZ (N), world frame.", float, (0, 0, 0), 3),
    Opt(("--torque",), "torque", "Torque TX TY TZ (N m).", float, (0, 0, 0), 3),
    Opt(("--link",), "link", "Link to push (default: the root).", str),
    Opt(("--duration",), "duration", "How long (s) of sim time.", float, 0.1),
    WORLD,
    JSON,
    help="Apply a force and torque to an entity for a while.",
)
def push(
    *,
    name: str,
    force: Vec3,
    torque: Vec3,
    link: str | None,
    duration: float,
    world: str,
    json: bool = False,
) -> None:
    with connect_world(world) as c:
        result = c.push(name, force, torque, link=link, duration=duration)
    if json:
        Output(json).data(result)
