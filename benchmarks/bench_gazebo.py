"""Gazebo-semantics figures: cost of the gazebo stage per corpus robot, and its physics fidelity.

Timing: `parse_gazebo` + `apply_gazebo` against the whole conversion of the same robot (ratio).
Fidelity: m·g/kp sinkage of a converted ball for two kp, and incline slide distances at 90 % and
110 % of the friction angle for both directions of the min-μ rule (oracle ½·a·t² above, 0 below).
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import mujoco
import tomllib

from converters.gazebo.apply import apply_gazebo
from converters.gazebo.blocks import parse_gazebo
from converters.gazebo.contact import add_gazebo_ground
from converters.pipeline import convert, convert_full
from converters.report import Report
from converters.urdf.xml_checks import parse_xml

REPO = Path(__file__).resolve().parents[1]
PACKAGES = REPO.parent / "shared" / "corpus" / "packages"
ROBOT_IDS = ("aliengo", "hyq", "robotiq_2f_85", "turtlebot3_burger")  # corpus robots with tags
G = 9.8


def _stage_timing(robot: dict) -> dict[str, float]:
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions

    options = ConvertOptions(repair_inertia=True, collision=CollisionSettings(mode="hull"))
    paths = {name: PACKAGES / name for name in robot["packages"]}
    start = time.perf_counter()
    done = convert_full(
        PACKAGES / robot["entry"], args=robot["xacro_args"], package_paths=paths, options=options
    )
    total = time.perf_counter() - start
    spec = done.spec.copy()
    for exclude in list(spec.excludes):
        spec.delete(exclude)
    start = time.perf_counter()
    ext = parse_gazebo(parse_xml(done.description.text, robot["entry"]), robot["entry"])
    apply_gazebo(spec, ext, done.provenance, Report())
    stage = time.perf_counter() - start
    return {"convert_s": round(total, 4), "gazebo_stage_s": round(stage, 4)}


def _world(directory: Path, text: str, z: float, gravity, extra=None):
    world = mujoco.MjSpec()
    world.option.timestep = 0.001
    world.option.gravity = list(gravity)
    add_gazebo_ground(world)
    parts = ([extra] if extra else []) + [(text, z)]
    for i, (urdf, height) in enumerate(parts):
        path = directory / f"p{i}.urdf"
        path.write_text(urdf)
        spec, _ = convert(path)
        world.attach(spec, frame=world.worldbody.add_frame(pos=[0, 0, height]), prefix=f"e{i}/")
    model = world.compile()
    return model, mujoco.MjData(model), f"e{len(parts) - 1}/"


def _fidelity(directory: Path) -> dict[str, float]:
    import sys

    sys.path.insert(0, str(REPO / "tests"))
    import models

    out: dict[str, float] = {}
    for kp in (1e4, 1e5):
        text = models.ball_on_plane(2.0, kp=kp, kd=2 * math.sqrt(kp * 2.0))
        model, data, prefix = _world(directory, text, 0.1, (0, 0, -G))
        mujoco.mj_step(model, data, nstep=1500)
        sink = 0.1 - data.xpos[model.body(f"{prefix}ball").id, 2]
        out[f"ball_sinkage_over_mg_kp_kp{kp:g}"] = round(sink / (2.0 * G / kp), 4)
    for label, block_mu, slab in (("ground", 0.3, None), ("slab", 1.0, 0.2)):
        mu = min(block_mu, slab or 100.0)
        for factor in (0.9, 1.1):
            theta = math.atan(mu * factor)
            gravity = (G * math.sin(theta), 0.0, -G * math.cos(theta))
            extra = (models.slab(slab), 0.0) if slab else None
            model, data, prefix = _world(
                directory, models.block(block_mu), 0.1 if slab else 0.05, gravity, extra
            )
            body = model.body(f"{prefix}block").id
            mujoco.mj_forward(model, data)
            x0 = data.xpos[body, 0]
            mujoco.mj_step(model, data, nstep=1000)
            accel = max(G * math.cos(theta) * (math.tan(theta) - mu), 0.0)
            out[f"incline_{label}_{factor}_slid_m"] = round(float(data.xpos[body, 0] - x0), 4)
            out[f"incline_{label}_{factor}_oracle_m"] = round(0.5 * accel, 4)
    return out


def run() -> dict:
    results: dict[str, object] = {}
    manifest = PACKAGES.parent / "robots.toml"
    corpus = {r["id"]: r for r in tomllib.loads(manifest.read_text())["robot"]}
    for robot_id in ROBOT_IDS:
        if robot_id in corpus:
            results[robot_id] = _stage_timing(corpus[robot_id])
    with tempfile.TemporaryDirectory() as tmp:
        results["fidelity"] = _fidelity(Path(tmp))
    return results


if __name__ == "__main__":
    import json

    print(json.dumps(run(), indent=2))
