"""Mutated world files for `twin load`: a world comes back, or one WorldFileError names the file.

Seeds are real saves (a robot holding position and velocity commands, a pushed ball); the
mutations are the ways a file breaks in a user's hands: a key removed, a value of the wrong type
or an absurd number, a list cut short or lengthened, the text truncated or spliced with junk.
The property is `savefile.load`'s contract: a World, or a WorldFileError (a TwinError the CLI
prints as one message, exit 2), never another exception.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from models import CONTROL_RIG, ball_on_plane, write_urdf

from twin_cli.errors import WorldFileError
from twin_cli.world import Pose, World
from twin_cli.world.savefile import load, save

EXAMPLES = int(os.environ.get("TWIN_FUZZ_EXAMPLES", "40"))
ODD_VALUES = (None, True, -1, 0, 1e309, -1e309, "x", "", [], {}, [1.0, "a"], 2**70, 1e-320)


@pytest.fixture(scope="module")
def seed(tmp_path_factory) -> tuple[Path, dict]:
    """A save of a rig with a velocity and a position command and a ball under a push."""
    folder = tmp_path_factory.mktemp("seed")
    world = World()
    world.spawn(write_urdf(folder, CONTROL_RIG, "rig.urdf"), name="rig", pose=Pose(z=1.0))
    world.spawn(write_urdf(folder, ball_on_plane(1.0), "ball.urdf"), name="ball", pose=Pose(x=2))
    world.command("rig", "spin", mode="velocity", value=2.0)
    world.command("rig", "slide", mode="position", value=0.1)
    world.push("ball", (5.0, 0.0, 0.0), duration=10.0)
    world.step(200)
    path = folder / "seed.json"
    save(world, path)
    return folder, json.loads(path.read_text())


def _paths(value, prefix=()) -> list[tuple]:
    """Every key path into a JSON value (dict keys and list indices)."""
    out = [prefix] if prefix else []
    if isinstance(value, dict):
        for key, item in value.items():
            out += _paths(item, (*prefix, key))
    elif isinstance(value, list):
        for i, item in enumerate(value[:4]):
            out += _paths(item, (*prefix, i))
    return out


def _parent(doc, path: tuple):
    for key in path[:-1]:
        doc = doc[key]
    return doc


@st.composite
def mutated(draw: st.DrawFn, doc: dict) -> str:
    """The seed document with one to three mutations, as text (sometimes truncated or spliced)."""
    doc = json.loads(json.dumps(doc))
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(doc)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent, key = _parent(doc, path), path[-1]
        action = draw(st.sampled_from(("delete", "odd", "shorten", "lengthen", "scale")))
        if action == "delete" and isinstance(parent, dict):
            del parent[key]
        elif action == "odd":
            parent[key] = draw(st.sampled_from(ODD_VALUES))
        elif action in ("shorten", "lengthen") and isinstance(parent[key], list):
            items = parent[key]
            parent[key] = items[:-1] if action == "shorten" else items + items[-1:]
        elif isinstance(parent[key], (int, float)) and not isinstance(parent[key], bool):
            parent[key] = parent[key] * draw(st.sampled_from((-1, 0, 1e12, 1e-12)))
    text = json.dumps(doc)
    tail = draw(st.sampled_from(("keep", "keep", "keep", "truncate", "junk")))
    if tail == "truncate":
        text = text[: draw(st.integers(0, len(text) - 1))]
    elif tail == "junk":
        at = draw(st.integers(0, len(text)))
        text = text[:at] + draw(st.binary(min_size=1, max_size=20)).decode("latin-1") + text[at:]
    return text


@settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_a_mutated_world_file_loads_or_names_the_file(seed, data) -> None:
    folder, doc = seed
    text = data.draw(mutated(doc))
    path = folder / "mutated.json"
    path.write_text(text, encoding="latin-1")
    try:
        world = load(path)
    except WorldFileError as exc:
        assert str(path) in str(exc) or path.name in str(exc), str(exc)
        return
    world.step(10)  # what loaded also steps


def test_the_seed_itself_loads_with_its_commands(seed) -> None:
    folder, _ = seed
    world = load(folder / "seed.json")
    modes = {j: c["mode"] for j, c in world.joint_commands("rig").items()}
    assert modes == {"spin": "velocity", "slide": "position"}, modes
