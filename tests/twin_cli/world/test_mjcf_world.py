"""An MJCF scene served as the world (`twin serve scene.xml`): its options, ground and bodies."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from twin_cli.errors import SpawnError
from twin_cli.world.sdf_world import load_world

MOON_G = 1.62  # [m/s²]
HALF = 0.1  # [m] the crate's half size
SCENE = f"""<mujoco model="moon_scene">
  <option timestep="0.002" gravity="0 0 -{MOON_G}" iterations="40" integrator="RK4"/>
  <worldbody>
    <light name="top" pos="0 0 3" dir="0 0 -1"/>
    <geom name="floor" type="plane" size="5 5 0.1" pos="0 0 0.5"/>
    <body name="crate" pos="0 0 2">
      <freejoint/>
      <geom type="box" size="{HALF} {HALF} {HALF}" mass="5"/>
    </body>
  </worldbody>
</mujoco>"""


@pytest.fixture
def scene(tmp_path: Path) -> Path:
    path = tmp_path / "moon_scene.xml"
    path.write_text(SCENE)
    return path


def test_the_scene_is_the_world(scene: Path) -> None:
    world = load_world(scene)
    physics = world.physics()
    assert (physics["timestep"], physics["rate"], physics["iterations"]) == (0.002, 500.0, 40)
    assert physics["integrator"] == "rk4", "the scene's integrator, not twin's default"
    assert world.gravity() == (0.0, 0.0, -MOON_G)
    assert [e.name for e in world.entities()] == ["moon_scene"]
    floors = [g for g in range(world.model.ngeom) if world.model.geom_type[g] == 0]
    assert len(floors) == 1, "the scene's own floor and no Gazebo ground beside it"


def test_a_crate_falls_at_the_scenes_gravity_and_rests_on_its_floor(scene: Path) -> None:
    world = load_world(scene)
    z0 = world.link_poses("moon_scene")["crate"].z
    world.step(500)  # 1 s at 2 ms: ½·1.62·1² = 0.81 m, still above the raised floor (0.5 m)
    drop = z0 - world.link_poses("moon_scene")["crate"].z
    assert drop == pytest.approx(0.5 * MOON_G * 1.0**2, rel=0.01), "½gt² at the scene's g [m]"
    world.step(1500)  # lands after 1.7 s and settles
    rest = world.link_poses("moon_scene")["crate"].z
    assert rest == pytest.approx(0.5 + HALF, abs=2e-3), "on the scene's floor at z 0.5 [m]"


def test_bad_mjcf_is_a_spawn_error_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "broken.xml"
    path.write_text("<mujoco><worldbody><body><geom type='box'/></body></worldbody></mujoco>")
    with pytest.raises(SpawnError, match="broken"):
        load_world(path)


def test_twin_serve_takes_a_scene(scene: Path, tmp_path: Path, serve_world) -> None:
    with serve_world(tmp_path, "mjcf_scene", str(scene), "--paused"):
        env = {**os.environ, "TWIN_RUNTIME_DIR": str(tmp_path)}
        env.pop("TWIN_WORLD", None)

        def twin(*args: str) -> dict | list:
            proc = subprocess.run(
                [sys.executable, "-m", "twin_cli", *args, "--world", "mjcf_scene", "--json"],
                env=env,
                capture_output=True,
                text=True,
                timeout=60,
            )
            assert proc.returncode == 0, proc.stderr
            return json.loads(proc.stdout)

        assert twin("physics")["timestep"] == 0.002
        assert twin("gravity")["gravity"] == [0.0, 0.0, -MOON_G]
        assert [e["name"] for e in twin("list")] == ["moon_scene"]


@pytest.mark.parametrize(
    ("attribute", "expected"),
    [("", "plain_box"), (' model="crate"', "crate"), (' model="a b"', "a b")],
)
def test_a_spawned_mjcf_is_named_by_its_own_model_name_else_its_file(
    tmp_path: Path, attribute: str, expected: str
) -> None:
    """MuJoCo calls a model without `model=` "MuJoCo Model": that is not the model's name, so
    the entity takes the file's (or, from text, "model")."""
    from twin_cli.spawn_request import SpawnRequest
    from twin_cli.world import World

    text = (
        f"<mujoco{attribute}><worldbody><body><freejoint/><geom type='box' size='.1 .1 .1'/>"
        "</body></worldbody></mujoco>"
    )
    path = tmp_path / "plain_box.xml"
    path.write_text(text)
    world = World()
    assert world.spawn(SpawnRequest(str(path))).name == expected
    named = world.spawn(SpawnRequest(xml=text)).name
    assert named == (expected + "_1" if attribute else "model"), named
