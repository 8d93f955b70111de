"""A stock ROS 2 node on rmw_fastrtps_cpp (Fast DDS), run by a Python that has rclpy.

It is ROS's own code end to end (rclpy, rcl, rmw_fastrtps_cpp from the ros-jazzy-* wheels):
the variables it is started with configure it as they configure any Jazzy node. Humble's
`ROS_LOCALHOST_ONLY=1` (which Jazzy reads as its LOCALHOST range) is reproduced by a Fast DDS
profile the caller names in FASTRTPS_DEFAULT_PROFILES_FILE (test_discovery.py writes it):
rmw_fastrtps_shared_cpp's Humble participant.cpp replaces the built-in transports by a UDPv4
one whitelisting 127.0.0.1 and a shared-memory one, and changes nothing else.

Usage: python fastdds_peer.py session SECONDS ENTITY VX (as rmw_peer.py's session, plus
"nodes": the node names rclpy's graph holds, as `ros2 node list` prints them).
"""

import json
import sys
import time

import rclpy
from geometry_msgs.msg import Twist
from rosgraph_msgs.msg import Clock


def session(seconds: float, entity: str, vx: float) -> dict:
    rclpy.init()
    node = rclpy.create_node("fastdds_peer")
    received = []
    node.create_subscription(Clock, "/clock", received.append, 10)
    publisher = node.create_publisher(Twist, f"/{entity}/cmd_vel", 10)
    twist = Twist()
    twist.linear.x = vx
    sent, end, tick = 0, time.monotonic() + seconds, time.monotonic()
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.02)
        if time.monotonic() >= tick:
            publisher.publish(twist)
            sent, tick = sent + 1, tick + 0.1
    matched = publisher.get_subscription_count()
    nodes = sorted(f"{ns.rstrip('/')}/{name}" for name, ns in node.get_node_names_and_namespaces())
    node.destroy_node()
    rclpy.shutdown()
    return {"clock": len(received), "sent": sent, "matched": matched, "nodes": nodes}


if __name__ == "__main__":
    _, seconds, entity, vx = sys.argv[1:]
    json.dump(session(float(seconds), entity, float(vx)), sys.stdout)
