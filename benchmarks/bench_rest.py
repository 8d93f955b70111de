"""At rest means at rest, and servos hold: the figures a regression in contacts or servos moves.

- every corpus robot on flat ground, left alone after a 2 s settle: how far its base moves and
  turns over the next 60 s of sim time (target: < 1 mm and < 1 mrad; a robot whose passive
  limbs are still folding after 2 s moves more, and the row says it is passive);
- turtlebot3 after a 5 s drive (0.2 m/s, 0.5 rad/s) and a 2 s stop: the same 60 s figures, and
  how far its 5 s drive ends from the unicycle model (target < 2 % of the path);
- turtlebot3 never driven, on a 5° slope: how far it moves in 10 s (its plugin holds its wheels
  from load; they used to roll free, 16 m in 10 s);
- a 3.85 kg box on the rigid default contact: the spread of its normal force over m·g
  (target < 5 %);
- a wheel at 3 rad/s carrying half its effort limit (target within 1 %), and a 1 rad position
  move at a 1 rad/s limit (target: settled within 1 % in < 1.5 s, overshoot < 1 %).
Figures are sim-time physics, the same on any machine; the wall time is printed for the record.
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np
import tomllib

CORPUS = Path(__file__).resolve().parents[1].parent / "shared" / "corpus"
PACKAGES = CORPUS / "packages"
NON_PHYSICAL_INERTIA = ("abb_irb2400_12_155", "anymal_c", "hyq")
SETTLE_S, WATCH_S = 2.0, 60.0
TARGETS = {"moved_mm": 1.0, "turned_mrad": 1.0, "normal_force_spread": 0.05, "speed_error": 0.01}


def corpus_robots() -> dict[str, dict]:
    """robots.toml's entries by id (none without ../shared)."""
    if not (CORPUS / "robots.toml").is_file():
        return {}
    return {r["id"]: r for r in tomllib.loads((CORPUS / "robots.toml").read_text())["robot"]}


def corpus_request(robot: dict):  # noqa: ANN201 (SpawnRequest, imported lazily)
    """A corpus robot as `twin spawn --on-ground` takes it (the options its files need)."""
    from twin_cli.spawn_request import SpawnRequest

    packages = {p.name: str(p) for p in PACKAGES.iterdir()}
    return SpawnRequest(
        str(PACKAGES / robot["entry"]),
        package_paths=packages,
        args=robot["xacro_args"],
        repair_inertia=robot["id"] in NON_PHYSICAL_INERTIA,
        on_ground=True,
    )


def spawn_requests() -> dict:
    """Robot id → SpawnRequest: the corpus robots, then the bundled humanoid (the only robot
    without ../shared)."""
    from scenarios import HUMANOID
    from twin_cli.spawn_request import SpawnRequest

    requests = {rid: corpus_request(robot) for rid, robot in corpus_robots().items()}
    requests["humanoid"] = SpawnRequest(str(HUMANOID), on_ground=True)
    return requests


def _spawn(world, robot: dict, name: str) -> None:
    world.spawn(corpus_request(robot), name=name)


def _drift(world, name: str) -> dict:
    """Base motion over WATCH_S after the world has settled."""
    p0 = world.get_pose(name)
    world.step(round(WATCH_S / world.model.opt.timestep))
    p1 = world.get_pose(name)
    turned = max(
        abs(p1.roll - p0.roll),
        abs(p1.pitch - p0.pitch),
        abs(math.remainder(p1.yaw - p0.yaw, 2 * math.pi)),
    )
    moved = math.dist((p0.x, p0.y, p0.z), (p1.x, p1.y, p1.z))
    return {"moved_mm": round(moved * 1e3, 4), "turned_mrad": round(turned * 1e3, 4)}


def _corpus_rest() -> dict:
    from twin_cli.world import World

    rows = {}
    for rid, robot in corpus_robots().items():
        world = World()
        try:
            _spawn(world, robot, "r")
        except Exception as exc:  # a robot that needs options the bench does not give
            rows[rid] = {"skipped": f"{type(exc).__name__}: {exc}"[:160]}
            continue
        world.step(round(SETTLE_S / world.model.opt.timestep))
        row = _drift(world, "r")
        row["passive_limbs"] = not world.commands() and world.index_of("r").free_qpos >= 0
        row["at_rest"] = row["moved_mm"] < TARGETS["moved_mm"] and (
            row["turned_mrad"] < TARGETS["turned_mrad"]
        )
        rows[rid] = row
    return rows


def _turtlebot3_settled():
    """turtlebot3 spawned on the ground and settled for 0.3 s, or None without the corpus."""
    from twin_cli.world import World

    robot = corpus_robots().get("turtlebot3_burger")
    if robot is None:
        return None
    world = World()
    _spawn(world, robot, "tb3")
    world.step(300)
    return world


def _turtlebot_after_drive() -> dict:
    from twin_cli.control import controller_of, drive

    world = _turtlebot3_settled()
    if world is None:
        return {"skipped": "no corpus"}
    start = world.get_pose("tb3")
    v, w, t = 0.2, 0.5, 5.0
    drive(world, "tb3", v, w, t)
    plugin = controller_of(world, "tb3").plugin
    world.step(round((t + 1.0) / world.model.opt.timestep))
    end = world.get_pose("tb3")
    x, y, th, path = _unicycle(v, w, t, plugin, (start.x, start.y, start.yaw))
    error = math.hypot(end.x - x, end.y - y) / path
    world.step(round(SETTLE_S / world.model.opt.timestep))
    return {"unicycle_error": round(error, 4), **_drift(world, "tb3")}


def _turtlebot_on_a_slope() -> dict:
    """Never driven, then on a 5° slope (gravity tilted along its heading): how far it moves in
    10 s after 5 s there, its wheels held by its drive plugin from load."""
    world = _turtlebot3_settled()
    if world is None:
        return {"skipped": "no corpus"}
    slope = math.radians(5.0)
    world.set_gravity((9.81 * math.sin(slope), 0.0, -9.81 * math.cos(slope)))
    world.step(5000)
    p0 = world.get_pose("tb3")
    world.step(10000)
    p1 = world.get_pose("tb3")
    return {"moved_mm": round(math.dist((p0.x, p0.y, p0.z), (p1.x, p1.y, p1.z)) * 1e3, 4)}


def _unicycle(v: float, w: float, t: float, plugin, start: tuple) -> tuple:
    """The unicycle model driven by the plugin's rim-speed ramp, 0.1 ms Euler steps."""
    x, y, th = start
    half = plugin.wheel_separation / 2
    goals = (v - w * half, v + w * half)
    accel = plugin.max_wheel_acceleration or math.inf
    rims, path, dt, now = [0.0, 0.0], 0.0, 1e-4, 0.0
    while now < t + 1.0:
        for i, goal in enumerate(goals if now < t else (0.0, 0.0)):
            rims[i] += max(-accel * dt, min(accel * dt, goal - rims[i]))
        speed, turn = sum(rims) / 2, (rims[1] - rims[0]) / plugin.wheel_separation
        x, y, th = x + speed * math.cos(th) * dt, y + speed * math.sin(th) * dt, th + turn * dt
        path, now = path + abs(speed) * dt, now + dt
    return x, y, th, path


def _box_force() -> float:
    import mujoco

    from twin_cli.world import Pose, World

    mass = 3.85
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "box.urdf"
        i = mass * 0.2**2 / 6
        path.write_text(
            f'<robot name="box"><link name="box"><inertial><mass value="{mass}"/><inertia '
            f'ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial><collision>'
            '<geometry><box size="0.2 0.2 0.2"/></geometry></collision></link></robot>'
        )
        world = World()
        world.spawn(path, name="box", pose=Pose(z=0.1))
    world.step(2000)
    forces, wrench = [], np.zeros(6)
    for _ in range(1000):
        world.step(1)
        total = 0.0
        for c in range(world.data.ncon):
            mujoco.mj_contactForce(world.model, world.data, c, wrench)
            total += wrench[0]
        forces.append(total)
    return float(np.std(forces) / (mass * 9.81))


def _servos() -> dict:
    from twin_cli.world import Pose, World

    inertial = (
        '<inertial><mass value="{m}"/><inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" '
        'iyz="0"/></inertial>'
    )
    wheel = f"""<robot name="w"><link name="world"/>
<link name="base">{inertial.format(m=1, i=1)}</link>
<link name="disc">{inertial.format(m=0.2, i=1e-3)}</link>
<joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
<joint name="spin" type="continuous"><parent link="base"/><child link="disc"/>
  <axis xyz="0 0 1"/><limit effort="0.1" velocity="10"/></joint>
<joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
  <limit lower="-3" upper="3" effort="5" velocity="1"/></joint>
<link name="arm"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
  <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "rig.urdf"
        path.write_text(wheel)
        world = World()
        world.spawn(path, name="w", pose=Pose(z=1.0))
    world.command("w", "spin", mode="velocity", value=3.0)
    world.command("w", "j", mode="position", value=0.0)
    world.step(1000)
    world.push("w", torque=(0.0, 0.0, -0.05), link="disc", duration=1e3)
    world.command("w", "j", mode="position", value=1.0)
    q = []
    for _ in range(2000):
        world.step(1)
        q.append({s.name: s for s in world.joint_states("w")}["j"].position)
    speed = {s.name: s for s in world.joint_states("w")}["spin"].velocity
    q = np.array(q)
    outside = np.flatnonzero(np.abs(q - 1.0) > 0.01)
    return {
        "wheel_speed_error": round(abs(speed - 3.0) / 3.0, 5),
        "move_settle_s": round((outside[-1] + 2) * 1e-3 if len(outside) else 0.0, 3),
        "move_overshoot": round(float(max(q.max() - 1.0, 0.0)), 5),
    }


def run() -> dict:
    start = time.perf_counter()
    out = {
        "targets": TARGETS,
        "resting_box_normal_force_spread": round(_box_force(), 6),
        "servos": _servos(),
        "turtlebot3_after_drive": _turtlebot_after_drive(),
        "turtlebot3_never_driven_on_a_5_degree_slope": _turtlebot_on_a_slope(),
        "corpus_at_rest": _corpus_rest(),
    }
    out["wall_s"] = round(time.perf_counter() - start, 1)
    return out
