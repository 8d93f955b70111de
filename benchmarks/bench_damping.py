"""Cost of Gazebo `dampingFactor`: a humanoid world with a damped box against the same undamped.

Two worlds hold the bundled humanoid on the ground and a 1 kg box beside it (sleeping off); in
one the box carries `dampingFactor` 0.01, which the converter writes as joint damping, so both
step in one `mj_step(m, d, n)` call. Throughput is compared in finely interleaved windows of the
stepping thread's CPU time (`paired.interleaved_ratio`; at load 8 on 2 cores one wall-time run
gave 0.96, three CPU-time runs 0.995-1.015), target ≥ 0.97 (the per-step Python loop it
replaced: 0.72).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from benchmarks.paired import interleaved_ratio
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World

ROOT = Path(__file__).parents[1]
HUMANOID = ROOT / "scenarios" / "robots" / "humanoid.urdf.xacro"
FRACTION = 0.01  # dampingFactor of the box
WINDOW_STEPS, PAIRS = 200, 100  # 1 ms steps per window; alternations
TARGETS = {"damped_vs_plain": 0.97}


def box_urdf(fraction: float | None) -> str:
    """A free 1 kg cube of 0.1 m, with `dampingFactor` when `fraction` is given."""
    tag = (
        ""
        if fraction is None
        else f'<gazebo reference="box"><dampingFactor>{fraction}</dampingFactor></gazebo>'
    )
    return f"""<robot name="box"><link name="box">
  <inertial><mass value="1"/>
    <inertia ixx="0.001667" iyy="0.001667" izz="0.001667" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>{tag}</robot>"""


def _world(directory: Path, fraction: float | None) -> World:
    path = directory / f"box_{fraction}.urdf"
    path.write_text(box_urdf(fraction))
    world = World()
    world.set_engine(sleep=False)  # a damped box must not buy its speed by sleeping sooner
    world.spawn(SpawnRequest(HUMANOID, on_ground=True), name="h")
    world.spawn(SpawnRequest(str(path), on_ground=True), name="box", pose=Pose(x=1.0))
    world.step(300)
    return world


def run() -> dict:
    """Steps per second of both worlds and their ratio over PAIRS interleaved windows."""
    with tempfile.TemporaryDirectory() as tmp:
        plain, damped = _world(Path(tmp), None), _world(Path(tmp), FRACTION)
    ratio = interleaved_ratio(
        lambda: plain.step(WINDOW_STEPS),
        lambda: damped.step(WINDOW_STEPS),
        pairs=PAIRS,
        clock=time.thread_time,
    )
    return {
        "window_steps": WINDOW_STEPS,
        "pairs": PAIRS,
        "damped_vs_plain": round(ratio, 4),
        "targets": TARGETS,
    }
