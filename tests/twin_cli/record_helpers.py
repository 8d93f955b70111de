"""Reading recordings back with readers that share no code with twin's writer.

`rosbags`' AnyReader parses the MCAP container and CDR itself; `mcap`'s reader checks CRCs and
the summary; `mcap_ros2`'s decoder is a second, independent CDR implementation.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np

from twin_cli.world import Pose


def read_bag(path: Path) -> dict[str, list[tuple[int, object]]]:
    """topic → [(log time [ns], message)] through rosbags' AnyReader (every message decoded)."""
    from rosbags.highlevel import AnyReader

    out: dict[str, list[tuple[int, object]]] = defaultdict(list)
    with AnyReader([path]) as reader:
        for connection, stamp, raw in reader.messages():
            out[connection.topic].append((stamp, reader.deserialize(raw, connection.msgtype)))
    return dict(out)


def seconds(stamp: object) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def compose_links(tf: object, tf_static: object) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """World pose (position, quaternion w,x,y,z) of every frame, composed from tf messages."""
    edges = {}
    for t in [*tf.transforms, *tf_static.transforms]:
        r, v = t.transform.rotation, t.transform.translation
        edges[t.child_frame_id] = (
            t.header.frame_id,
            np.array([v.x, v.y, v.z]),
            np.array([r.w, r.x, r.y, r.z]),
        )
    poses: dict[str, tuple[np.ndarray, np.ndarray]] = {
        "world": (np.zeros(3), np.array([1.0, 0, 0, 0]))
    }

    def resolve(frame: str) -> tuple[np.ndarray, np.ndarray]:
        if frame not in poses:
            parent, p, q = edges[frame]
            pp, pq = resolve(parent)
            poses[frame] = (pp + rotate(pq, p), multiply(pq, q))
        return poses[frame]

    for frame in edges:
        resolve(frame)
    return poses


def multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ]
    )


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    return multiply(multiply(q, np.array([0.0, *v])), q * np.array([1, -1, -1, -1]))[1:]


def pose_error(composed: tuple[np.ndarray, np.ndarray], pose: Pose) -> tuple[float, float]:
    """Position error [m] and quaternion error (sign-free) between a composed pose and a Pose."""
    p, q = composed
    ref_q = np.array(pose.quat())
    dq = min(np.abs(q - ref_q).max(), np.abs(q + ref_q).max())
    return float(np.abs(p - np.array(pose.position())).max()), float(dq)


def tf_edges(bag: dict) -> dict[str, tuple[str, bool]]:
    """child frame → (parent frame, whether on /tf_static), from the recording's first /tf and
    /tf_static messages (one layout); a frame with two parents fails here."""
    edges: dict[str, tuple[str, bool]] = {}
    for topic, static in (("/tf", False), ("/tf_static", True)):
        for t in bag[topic][0][1].transforms if topic in bag else ():
            assert t.child_frame_id not in edges, f"{t.child_frame_id} has two parents"
            edges[t.child_frame_id] = (t.header.frame_id, static)
    return edges


def tree_frames(edges: dict[str, tuple[str, bool]]) -> set[str]:
    """Every frame of a tf tree, after checking that each one reaches `world`."""
    for frame in edges:
        seen = {frame}
        while frame != "world":
            assert frame in edges, f"{frame} does not reach world"
            frame = edges[frame][0]
            assert frame not in seen, f"a cycle through {frame}"
            seen.add(frame)
    return {*edges, "world"}


def urdf_joints(text: str) -> list[dict[str, object]]:
    """A URDF's joints read with ElementTree: name, type, parent, child, origin xyz and rpy,
    mimic (joint, multiplier, offset) or None."""
    import xml.etree.ElementTree as ET

    out = []
    for joint in ET.fromstring(text).findall("joint"):
        origin, mimic = joint.find("origin"), joint.find("mimic")

        def values(key: str, origin: object = origin) -> list[float]:
            text = origin.get(key) if origin is not None else None
            return [float(v) for v in (text or "0 0 0").split()]

        out.append(
            {
                "name": joint.get("name"),
                "type": joint.get("type"),
                "parent": joint.find("parent").get("link"),
                "child": joint.find("child").get("link"),
                "xyz": values("xyz"),
                "rpy": values("rpy"),
                "mimic": None
                if mimic is None
                else (
                    mimic.get("joint"),
                    float(mimic.get("multiplier", "1")),
                    float(mimic.get("offset", "0")),
                ),
            }
        )
    return out
