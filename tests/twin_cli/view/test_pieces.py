"""Models as pieces keyed by content (`twin_cli.view.pieces`, `piece_routes`), without a browser:
the cuts, a second robot of the same description in a world, and the viewer port's routes on a
real server."""

from __future__ import annotations

import hashlib
import json
import os
import random
import subprocess
import time
import urllib.error
import urllib.request
import zlib

import pytest
from corpus_registry import CORPUS, needs_corpus, package_paths
from mesh_models import write_mesh_package
from view_helpers import twin_in

from twin_cli.view.pieces import MAX_PIECE, array_ranges, split_bundle

WORLD = "pieceroutes"


def manifest_of(model):
    from mujoco.studio.web import state_payload

    bundle = state_payload.serialize_model_bundle(model)
    return bundle, split_bundle(bundle, zlib.crc32(bundle), array_ranges(bundle, model))


def test_content_cuts_survive_bytes_inserted_before_them():
    """4 MiB of random bytes, then 100 bytes put in front: the cuts follow the content, so all
    but the pieces around the insertion keep their keys (at least 90 % of the bytes)."""
    data = random.Random(7).randbytes(4 * 2**20)
    before = split_bundle(data, 1, [])
    after = split_bundle(b"x" * 100 + data, 2, [])
    kept = {p.key for p in before.pieces}
    reused = sum(p.size for p in after.pieces if p.key in kept)
    assert reused > 0.9 * len(data), f"reused {reused} of {len(data)} bytes"
    assert max(p.size for p in after.pieces) <= MAX_PIECE, "a piece over MAX_PIECE"


def test_pieces_put_back_the_bundle_and_are_named_by_the_hash_of_their_bytes(tmp_path):
    from twin_cli.spawn_request import SpawnRequest
    from twin_cli.world.engine import World

    urdf = write_mesh_package(tmp_path)
    world = World()
    package = urdf.parent.parent
    world.spawn(SpawnRequest(source=str(urdf), package_paths={package.name: str(package)}))
    bundle, manifest = manifest_of(world.model)
    assert b"".join(bundle[p.start : p.start + p.size] for p in manifest.pieces) == bundle
    for p in manifest.pieces:
        digest = hashlib.blake2b(bundle[p.start : p.start + p.size], digest_size=16).hexdigest()
        assert p.key == digest, f"piece at {p.start}: key is not the hash of its bytes"


@needs_corpus
def test_a_second_robot_of_the_same_description_adds_no_mesh_piece():
    """Two turtlebot3 in a world: every mesh piece of the second model is one of the first's,
    and what is new (bodies, joints, names, their BVH trees) is under 256 KiB of the 16 MiB
    (measured: 26 KiB)."""
    from twin_cli.spawn_request import SpawnRequest
    from twin_cli.world.engine import World

    robot = CORPUS["turtlebot3_burger"]
    paths = {n: str(p) for n, p in package_paths(robot).items()}
    entry = os.path.join(paths[robot["entry"].split("/")[0]], *robot["entry"].split("/")[1:])
    request = SpawnRequest(source=entry, package_paths=paths)
    world = World()
    world.spawn(request, name="tb1")
    _, first = manifest_of(world.model)
    world.spawn(request, name="tb2")
    bundle, second = manifest_of(world.model)
    assert first.asset_bytes > 4 * 2**20, f"the turtlebot's meshes: {first.asset_bytes} bytes"
    had = {p.key for p in first.pieces}
    new = [p for p in second.pieces if p.key not in had]
    assert not [p for p in new if p.asset], "mesh pieces new in the second model"
    new_bytes = sum(p.size for p in new)
    assert new_bytes < 256 * 1024, f"second turtlebot: {new_bytes} new bytes of {len(bundle)}"


def twin(*args: str) -> subprocess.CompletedProcess:
    return twin_in(WORLD, *args)


def get(url: str) -> bytes:
    with urllib.request.urlopen(url, timeout=30) as reply:
        return reply.read()


def test_the_viewer_port_serves_the_model_as_pieces_that_put_back_its_bundle(tmp_path, serve_world):
    urdf = write_mesh_package(tmp_path)
    with serve_world(tmp_path / "run", WORLD):
        package = f"--package={urdf.parent.parent.name}={urdf.parent.parent}"
        assert twin("spawn", str(urdf), package).returncode == 0
        url = twin("view").stdout.strip()
        manifest = json.loads(get(url + "twin/manifest"))
        assert int(get(url + "twin/current")) == manifest["crc32"]
        keys = [row[0] for row in manifest["pieces"]]
        body = get(url + "twin/pieces?keys=" + ",".join(keys))
        whole = get(url + "model")
        assert body == whole, f"pieces: {len(body)} bytes; /model: {len(whole)} bytes"
        assert zlib.crc32(whole) == manifest["crc32"], "the manifest names another model"
        assert b"twin/pieces.js" in get(url), "the page does not load twin's script"
        with pytest.raises(urllib.error.HTTPError) as gone:
            get(url + "twin/pieces?keys=" + "0" * 32)
        assert gone.value.code == 404

        # A load replaces the world: the viewer serves its model as pieces too.
        saved = tmp_path / "world.twin"
        assert twin("save", str(saved)).returncode == 0
        assert twin("delete", "mesh_robot").returncode == 0
        assert wait_for_model(url, manifest["crc32"], differ=True)
        loaded = twin("load", str(saved))
        assert loaded.returncode == 0, loaded.stderr
        assert wait_for_model(url, manifest["crc32"], differ=False), "the load did not show"


def wait_for_model(url: str, crc32: int, *, differ: bool, timeout: float = 30.0) -> bool:
    """Waits until the viewer serves, as pieces that put back /model, a model whose crc32 is
    (`differ`: is not) `crc32`."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        manifest = json.loads(get(url + "twin/manifest"))
        if (manifest["crc32"] != crc32) == differ:
            keys = ",".join(row[0] for row in manifest["pieces"])
            body = get(url + "twin/pieces?keys=" + keys)
            return zlib.crc32(body) == manifest["crc32"]
        time.sleep(0.1)
    return False
