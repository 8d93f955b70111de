"""Spawns with the viewer page open, in headless chromium on a real world server: the page takes
each new model as pieces keyed by content (`twin_cli.view.piece_routes`).

One page, one test: a turtlebot3 (meshes: 4.5 MiB of mesh arrays, 16 MiB of bundle with their
BVHs) spawned with the page open is in the page's renderer within `APPEAR_S` plus one of the
page's frames (its main thread takes the bundle between two), and drawn within `APPEAR_S` plus
what the browser's own frames cost (`DRAW_FRAMES`); so is a second turtlebot3, and the page
receives no byte of mesh data for it. Bytes are counted twice: by
Chromium (the bodies of the responses the page receives, from its network events) and by the
page's own record of the pieces it fetched.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest
from corpus_registry import CORPUS, needs_corpus, package_paths
from view_helpers import CHROMIUM, CHROMIUM_FLAGS, chromium_missing

pytestmark = [
    pytest.mark.skipif(bool(chromium_missing()), reason=chromium_missing() or ""),
    needs_corpus,
]

WORLD = "pieces"
ROBOT = "turtlebot3_burger"
APPEAR_S = 2.0  # [s] from the spawn's reply to the new model in the page (plus its frames)
# Frames (as long as the page's frames before the spawns) the browser may take to draw a new
# model on top of APPEAR_S: 0 when its frames are quick (measured 1.41 s to drawn, with frames
# 107 ms apart), ~1-2 s on a loaded machine where frames are 400-600 ms apart.
DRAW_FRAMES = 4
FIRST_LOAD_S = 120.0  # [s] the page's first load: WASM and WebGL in SwiftShader, ~12 s
TWIN_TIMEOUT_S = 120.0  # [s] a spawn converts the xacro and its meshes on a loaded machine
# Structure the second spawn changes: bodies, joints, names, their trees in the BVH arrays
# (measured: 26 KiB of a 16 MiB bundle); the mesh arrays are 4.5 MiB.
MAX_SECOND_BYTES = 256 * 1024  # [bytes]


def twin(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", WORLD],
        capture_output=True,
        text=True,
        timeout=TWIN_TIMEOUT_S,
        env=os.environ.copy(),
    )


def spawn_turtlebot(name: str, x: float) -> float:
    """Spawns a turtlebot3 at (x, 0); returns the wall time [s since the epoch] of the reply."""
    robot = CORPUS[ROBOT]
    root = package_paths(robot)
    entry = root[robot["entry"].split("/")[0]].parent / robot["entry"]
    packages = [f"--package={n}={p}" for n, p in root.items()]
    spawned = twin("spawn", str(entry), *packages, "--name", name, "-x", str(x))
    assert spawned.returncode == 0, spawned.stderr
    return time.time()


def loads(tab) -> list[dict]:
    return tab.evaluate("window.twinPieces ? window.twinPieces.loads : []")


def timeline(tab, load: dict, spawned_at: float) -> str:
    """When, after the spawn's reply, the page's worker had the model, parsed it, drew it."""
    got = [r for r in tab.evaluate("window.twinPieces.received") if r["crc"] == load["crc"]]
    had = f"{got[0]['at'] / 1e3 - spawned_at:.2f}" if got else "-"
    parsed, shown = load["parsed"] / 1e3 - spawned_at, load["shown"] / 1e3 - spawned_at
    presented = f"{load['presented'] / 1e3 - spawned_at:.2f}" if load["presented"] else "-"
    return (
        f"worker had it at {had} s, parsed at {parsed:.2f} s, next frame at {shown:.2f} s, "
        f"drawn at {presented} s"
    )


def frame_ms(tab) -> float:
    """[ms] between the page's frames, over one second."""
    script = """() => new Promise((done) => {
      const times = [];
      const tick = (t) => { times.push(t); if (t - times[0] < 1000) requestAnimationFrame(tick);
        else done((times[times.length - 1] - times[0]) / (times.length - 1)); };
      requestAnimationFrame(tick);
    })"""
    return float(tab.evaluate(script))


def wait_shown(tab, after: float, timeout: float) -> dict:
    """The first model load after `after` [s since the epoch] that the page has drawn and
    presented (the animation frame after the one that drew it has begun)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        drawn = [x for x in loads(tab) if x["presented"] and x["parsed"] / 1e3 > after]
        if drawn:
            return drawn[0]
        time.sleep(0.02)
    pytest.fail(f"no model drawn on the page within {timeout:.0f} s (loads: {loads(tab)})")


@pytest.fixture
def page(tmp_path_factory, serve_world):
    from playwright.sync_api import sync_playwright

    root = tmp_path_factory.mktemp("pieces")
    with serve_world(root, WORLD):
        url = twin("view").stdout.strip()
        assert url.startswith("http://localhost:"), url
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            tab = browser.new_page(viewport={"width": 640, "height": 480})
            received: list[tuple[str, int]] = []  # (URL, body bytes) as Chromium got them
            tab.on("requestfinished", lambda r: received.append((r.url, _body_bytes(r))))
            tab.goto(url)
            wait_shown(tab, 0.0, FIRST_LOAD_S)
            yield tab, received
            browser.close()


def _body_bytes(request) -> int:
    return int(request.sizes()["responseBodySize"])


def test_spawns_show_in_2_s_a_second_robot_sends_no_mesh_bytes_a_delete_none(page):
    tab, received = page
    frame = frame_ms(tab)
    first_at = spawn_turtlebot("tb1", 0.0)
    first = wait_shown(tab, first_at - 1.0, FIRST_LOAD_S)
    first_s = first["presented"] / 1e3 - first_at
    record = tab.evaluate("window.twinPieces")
    # 3.0 MiB: the face-normal rows equal the face rows, the same pieces, fetched once.
    assert record["assetBytes"] > 2 * 2**20, f"first turtlebot: {record['assetBytes']} mesh bytes"

    before, asset_before, seen = record["bytes"], record["assetBytes"], len(received)
    second_at = spawn_turtlebot("tb2", 1.0)
    second = wait_shown(tab, second_at - 1.0, 30.0)
    second_s = second["presented"] / 1e3 - second_at
    record = tab.evaluate("window.twinPieces")
    pieces = sum(n for url, n in received[seen:] if "/twin/pieces" in url)
    times = f"first: {timeline(tab, first, first_at)}; second: {timeline(tab, second, second_at)}"
    times += f"; the page's frames {frame:.0f} ms apart before the spawns"
    print(f"{times}; second: {pieces} bytes (Chromium), {record['bytes'] - before} (page)")
    assert record["assetBytes"] == asset_before, (
        f"second turtlebot: {record['assetBytes'] - asset_before} mesh bytes sent again"
    )
    assert pieces == record["bytes"] - before, "Chromium and the page disagree on bytes"
    assert pieces < MAX_SECOND_BYTES, f"second turtlebot: {pieces} bytes, > {MAX_SECOND_BYTES}"
    assert not any("/model" in url for url, _ in received), "the whole model was downloaded"
    for name, load, at, drawn_s in (
        ("first", first, first_at, first_s),
        ("second", second, second_at, second_s),
    ):
        # The page's main thread takes the bundle between two frames: up to one frame's wait.
        parsed_s = load["parsed"] / 1e3 - at
        budget = APPEAR_S + frame / 1e3
        assert parsed_s < budget, f"{name} turtlebot in the page {parsed_s:.2f} s after; {times}"
        # Drawing the new model is the browser's own cost: on a loaded machine SwiftShader's
        # frames slow down, and the frame that uploads the new meshes takes several of them.
        budget = APPEAR_S + DRAW_FRAMES * frame / 1e3
        assert drawn_s < budget, f"{name} turtlebot drawn {drawn_s:.2f} s after; {times}"

    # A delete: the page holds every mesh the smaller model has.
    record = tab.evaluate("window.twinPieces")
    asset_before, loaded = record["assetBytes"], len(loads(tab))
    deleted = twin("delete", "tb2")
    assert deleted.returncode == 0, deleted.stderr
    deadline = time.monotonic() + 30.0
    while not [x for x in loads(tab)[loaded:] if x["crc"] != second["crc"] and x["presented"]]:
        assert time.monotonic() < deadline, f"the delete did not show (loads: {loads(tab)})"
        time.sleep(0.05)
    sent = tab.evaluate("window.twinPieces.assetBytes") - asset_before
    assert sent == 0, f"delete of tb2: {sent} mesh bytes sent"
