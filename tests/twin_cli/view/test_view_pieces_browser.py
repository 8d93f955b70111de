"""Spawns with the viewer page open, in headless chromium on a real world server: the page takes
each new model as pieces keyed by content (`twin_cli.view.piece_routes`).

One page, one test, one robot the test writes itself (`tests.big_meshes.write_mesh_arm`: eight
links drawn with about 136,000 triangles of OBJ meshes, as many as franka_panda's visual meshes
with its hand). Spawned with the page open, the arm is in the page's worker within `APPEAR_S`
of the spawn's reply (the server's sync and cut, the transfer: twin's part), and drawn within
`DRAWN_S` (the page renders in SwiftShader, so the server sends it the fast look: no shadows,
no multisampling); so is a second arm, and the page receives no byte of mesh data for it. A
miss of the 2 s is measured once more on a new arm and its copy, which must both make it.
Bytes are counted twice: by Chromium (the bodies of the responses the page receives, from its
network events) and by the page's own record of the pieces it fetched. A delete sends no mesh
bytes either.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from view_helpers import CHROMIUM, CHROMIUM_FLAGS, chromium_missing

from tests.big_meshes import write_mesh_arm
from twin_cli.view.look import is_software

pytestmark = pytest.mark.skipif(bool(chromium_missing()), reason=chromium_missing() or "")

WORLD = "pieces"
APPEAR_S = 2.0  # [s] from the spawn's reply to the new model in the page's worker
# [s] from the reply to the new model drawn: the page's main thread takes the bundle between two
# frames, MuJoCo's WASM parses it and builds its scene (0.2-0.3 s for this arm), SwiftShader
# uploads and draws 136,000 triangles (0.3-0.5 s a frame in the fast look the page gets).
# Measured on the 2-core VM at load 3-5: drawn 0.80-1.45 s after the reply.
DRAWN_S = 2.0
FIRST_LOAD_S = 120.0  # [s] the page's first load: WASM and WebGL in SwiftShader, ~12 s
TWIN_TIMEOUT_S = 120.0  # [s] a spawn converts the URDF and its meshes on a loaded machine
# Structure the second spawn changes: bodies, joints, names, their trees in the BVH arrays
# (measured: 48-70 KiB of a 16 MiB bundle); the mesh arrays are 2.1 MiB.
MAX_SECOND_BYTES = 256 * 1024  # [bytes]
MIN_FIRST_MESH_BYTES = 2 * 2**20  # [bytes] the arm's mesh rows (measured 2.1 MiB)


def twin(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", WORLD],
        capture_output=True,
        text=True,
        timeout=TWIN_TIMEOUT_S,
        env=os.environ.copy(),
    )


def spawn_arm(urdf: Path, name: str, x: float) -> tuple[float, float]:
    """Spawns the arm at (x, 0); returns the wall times [s since the epoch] of the request
    (a load the page parses after it is this spawn's) and of the reply (the times are from
    it)."""
    asked = time.time()
    spawned = twin("spawn", str(urdf), "--name", name, "-x", str(x))
    assert spawned.returncode == 0, spawned.stderr
    return asked, time.time()


def loads(tab) -> list[dict]:
    return tab.evaluate("window.twinPieces ? window.twinPieces.loads : []")


def received(tab, load: dict) -> dict | None:
    """The page's record of the bundle `load` parsed, as its worker fetched it."""
    got = [r for r in tab.evaluate("window.twinPieces.received") if r["crc"] == load["crc"]]
    return got[0] if got else None


def timeline(tab, load: dict, spawned_at: float) -> str:
    """When, after the spawn's reply [s], each step of showing the model happened."""
    got = received(tab, load)

    def at(ms: float | None) -> str:
        return f"{ms / 1e3 - spawned_at:.2f}" if ms else "-"

    steps = {
        "worker saw it": got and got["seen"],
        "worker had it": got and got["posted"],
        "page took it": got and got["at"],
        "parse began": load["started"],
        "parsed": load["parsed"],
        "next frame": load["shown"],
        "drawn": load["presented"],
    }
    return ", ".join(f"{what} {at(ms)} s" for what, ms in steps.items())


def frame_ms(tab) -> float:
    """[ms] between the page's frames, over one second."""
    script = """() => new Promise((done) => {
      const times = [];
      const tick = (t) => { times.push(t); if (t - times[0] < 1000) requestAnimationFrame(tick);
        else done((times[times.length - 1] - times[0]) / (times.length - 1)); };
      requestAnimationFrame(tick);
    })"""
    return float(tab.evaluate(script))


def shown_crc(tab) -> int:
    """The crc32 of the model the page drew last (0: none yet)."""
    drawn = [x["crc"] for x in loads(tab) if x["presented"]]
    return drawn[-1] if drawn else 0


def wait_shown(tab, after: float, timeout: float, old: int = 0) -> dict:
    """The first load of a model other than `old` (what the page showed before the spawn),
    parsed after `after` [s since the epoch], that the page has drawn and presented (the
    animation frame after the one that drew it has begun). The page parses the model it shows
    once more when the state stream names it after stale payloads: `old` keeps that out."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        drawn = [
            x
            for x in loads(tab)
            if x["presented"] and x["parsed"] / 1e3 > after and x["crc"] != old
        ]
        if drawn:
            return drawn[0]
        time.sleep(0.02)
    pytest.fail(f"no model drawn on the page within {timeout:.0f} s (loads: {loads(tab)})")


@pytest.fixture
def page(tmp_path_factory, serve_world):
    from playwright.sync_api import sync_playwright

    root = tmp_path_factory.mktemp("pieces")
    urdf = write_mesh_arm(root / "arm")
    with serve_world(root, WORLD):
        url = twin("view").stdout.strip()
        assert url.startswith("http://localhost:"), url
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            tab = browser.new_page(viewport={"width": 640, "height": 480})
            bodies: list[tuple[str, int]] = []  # (URL, body bytes) as Chromium got them
            tab.on("requestfinished", lambda r: bodies.append((r.url, _body_bytes(r))))
            errors: list[str] = []  # the page's uncaught errors (MuJoCo's WASM exits with one)
            tab.on("pageerror", lambda e: errors.append(str(e)))
            tab.goto(url)
            wait_shown(tab, 0.0, FIRST_LOAD_S)
            wait_fast_look(tab)
            yield tab, bodies, urdf, errors
            browser.close()


def wait_fast_look(tab) -> None:
    """Waits until the server sends this page (SwiftShader) the fast look and the page has
    drawn the model the server now serves, the same for a second: a spawn then measures its
    own model only."""
    deadline = time.monotonic() + FIRST_LOAD_S
    steady = None  # the crc drawn and served when first seen in the fast look
    while time.monotonic() < deadline:
        status = json.loads(twin("view", "--json").stdout)
        current = int(tab.evaluate("fetch('twin/current').then((r) => r.text())"))
        drawn = [x["crc"] for x in loads(tab) if x["presented"]]
        settled = status["look"]["fast"] and drawn and drawn[-1] == current
        if settled and steady == current:
            renderer = tab.evaluate("window.twinPieces.renderer")
            assert is_software(renderer), f"the test's page renders with {renderer}"
            assert status["look"]["software"] == renderer, status["look"]
            return
        steady = current if settled else None
        time.sleep(1.0 if settled else 0.1)
    pytest.fail(f"the page did not get the fast look (loads: {loads(tab)})")


def check_shown(tab, spawns: list[tuple[str, dict, float]]) -> list[float]:
    """Seconds from each spawn's reply to its model drawn; asserts twin's part (the server's
    sync and cut, the worker's fetch) within APPEAR_S and prints each timeline."""
    drawn = []
    for name, load, at in spawns:
        got = received(tab, load)
        times = timeline(tab, load, at)
        assert got is not None, f"{name} arm: the page's worker did not fetch it; {times}"
        had_s = got["posted"] / 1e3 - at
        assert had_s < APPEAR_S, f"{name} arm in the page's worker {had_s:.2f} s after; {times}"
        drawn.append(round(load["presented"] / 1e3 - at, 2))
        print(f"{name} arm drawn {drawn[-1]:.2f} s after the spawn's reply; {times}")
    return drawn


# A post on a hinge held by gz-sim's JointPositionController with its default integral gain.
HELD_ARM = """<robot name="held"><link name="world"/><link name="post"><inertial><mass value="1"/>
  <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><visual>
  <geometry><box size="0.1 0.1 0.4"/></geometry></visual></link>
  <joint name="hinge" type="revolute"><parent link="world"/><child link="post"/>
  <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="50" velocity="2"/>
  </joint><gazebo><plugin filename="gz-sim-joint-position-controller-system"
  name="gz::sim::systems::JointPositionController"><joint_name>hinge</joint_name>
  <p_gain>50</p_gain></plugin></gazebo></robot>"""


def _body_bytes(request) -> int:
    return int(request.sizes()["responseBodySize"])


def test_spawns_show_in_2_s_a_second_robot_sends_no_mesh_bytes_a_delete_none(page):
    tab, bodies, urdf, errors = page
    frame = frame_ms(tab)
    old = shown_crc(tab)
    asked, first_at = spawn_arm(urdf, "arm1", 0.0)
    first = wait_shown(tab, asked, FIRST_LOAD_S, old)
    record = tab.evaluate("window.twinPieces")
    assert record["assetBytes"] > MIN_FIRST_MESH_BYTES, (
        f"first arm: {record['assetBytes']} mesh bytes, expected > {MIN_FIRST_MESH_BYTES}"
    )

    before, asset_before, seen = record["bytes"], record["assetBytes"], len(bodies)
    asked, second_at = spawn_arm(urdf, "arm2", 1.0)
    second = wait_shown(tab, asked, 30.0, first["crc"])
    record = tab.evaluate("window.twinPieces")
    pieces = sum(n for url, n in bodies[seen:] if "/twin/pieces" in url)
    times = f"first: {timeline(tab, first, first_at)}; second: {timeline(tab, second, second_at)}"
    times += f"; the page's frames {frame:.0f} ms apart before the spawns"
    print(f"{times}; second: {pieces} bytes (Chromium), {record['bytes'] - before} (page)")
    assert record["assetBytes"] == asset_before, (
        f"second arm: {record['assetBytes'] - asset_before} mesh bytes sent again"
    )
    assert pieces == record["bytes"] - before, "Chromium and the page disagree on bytes"
    assert pieces < MAX_SECOND_BYTES, f"second arm: {pieces} bytes, > {MAX_SECOND_BYTES}"
    assert not any("/model" in url for url, _ in bodies), "the whole model was downloaded"
    drawn = check_shown(tab, [("first", first, first_at), ("second", second, second_at)])

    # A delete: the page holds every mesh the smaller model has.
    record = tab.evaluate("window.twinPieces")
    asset_before, loaded = record["assetBytes"], len(loads(tab))
    deleted = twin("delete", "arm2")
    assert deleted.returncode == 0, deleted.stderr
    deadline = time.monotonic() + 30.0
    while not [x for x in loads(tab)[loaded:] if x["crc"] != second["crc"] and x["presented"]]:
        assert time.monotonic() < deadline, f"the delete did not show (loads: {loads(tab)})"
        time.sleep(0.05)
    sent = tab.evaluate("window.twinPieces.assetBytes") - asset_before
    assert sent == 0, f"delete of arm2: {sent} mesh bytes sent"

    if max(drawn) >= DRAWN_S:
        # Measured once more on a miss (a machine busy for a moment), in the same world as the
        # first pair: an arm with new meshes where arm1 was, and its copy; both must make it.
        print(f"over {DRAWN_S} s: {drawn}; measured again with new meshes")
        asked, old = time.time(), shown_crc(tab)
        assert twin("delete", "arm1").returncode == 0
        empty = wait_shown(tab, asked, 30.0, old)
        other = write_mesh_arm(urdf.parent.parent / "arm_b")
        asked, third_at = spawn_arm(other, "arm3", 0.0)
        third = wait_shown(tab, asked, FIRST_LOAD_S, empty["crc"])
        asked, fourth_at = spawn_arm(other, "arm4", 1.0)
        fourth = wait_shown(tab, asked, 30.0, third["crc"])
        drawn = check_shown(tab, [("third", third, third_at), ("fourth", fourth, fourth_at)])
        times = (
            f"third: {timeline(tab, third, third_at)}; fourth: {timeline(tab, fourth, fourth_at)}"
        )
        assert max(drawn) < DRAWN_S, f"drawn {drawn} s after the replies; {times}"

    # A robot whose gz-sim PID runs on MuJoCo's `mujoco.pid` plugin, which the page's MuJoCo
    # lacks: the page is sent a copy without it (`twin_cli.world.page_model`) and draws it.
    held = urdf.parent.parent / "held.urdf"
    held.write_text(HELD_ARM)
    asked, old = time.time(), shown_crc(tab)
    assert twin("spawn", str(held), "--name", "held", "-x", "2").returncode == 0
    wait_shown(tab, asked, 30.0, old)
    assert not errors, f"the page failed: {errors}"
