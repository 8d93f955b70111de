"""The web viewer in a real browser (Debian's headless chromium) on a real world server.

One page (its first load takes ~12 s with WebGL in SwiftShader), checked in sequence by one
test: the humanoid shows, a spawned red box appears without a page reload, the page's Pause
pauses the world, the page's Reset puts entities back at their spawn poses.
"""

from __future__ import annotations

import io
import json
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from view_helpers import CHROMIUM, CHROMIUM_FLAGS, chromium_missing, pure_red, red_box, twin_in

import scenarios

pytestmark = pytest.mark.skipif(bool(chromium_missing()), reason=chromium_missing() or "")

HUMANOID = Path(scenarios.HUMANOID)
WORLD = "browser"
VIEWPORT = {"width": 800, "height": 600}
# Where MuJoCo Studio's Options panel draws its buttons in an 800×600 page (its default layout).
PAUSE_BUTTON = (60, 122)
RESET_BUTTON = (48, 90)
WAIT_S = 90.0  # [s] for a picture to change: SwiftShader renders a frame in ~0.1-5 s under load
MIN_PIXELS = 150  # pixels of a colour that count as "shows"
BOX_PIXELS = 2000  # red pixels the 0.4 m box adds (~15,000 at the default camera distance)
SPAWN_Z = 1.0  # [m]
SCREENSHOT_TIMEOUT_MS = 120_000  # a screenshot waits for a rendered frame: slow on a loaded CPU


SHOTS: Path | None = None  # where the page's screenshots go (named in failure messages)


def twin(*args: str) -> subprocess.CompletedProcess:
    return twin_in(WORLD, *args)


def cloth_blue(pixels: np.ndarray) -> np.ndarray:
    """Pixels of the humanoid's trousers (0.2 0.3 0.6): blue well above red and green."""
    rgb = pixels[..., :3].astype(float)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return (b > 1.5 * r) & (b > 1.3 * g) & (b > 60)


def shot(page, name: str, out: Path) -> np.ndarray:
    from PIL import Image

    png = page.screenshot()
    (out / f"{name}.png").write_bytes(png)
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


def wait_for(what: str, test, timeout: float = WAIT_S):
    """Polls `test()` until it returns a truthy value; fails naming `what`."""
    deadline = time.monotonic() + timeout
    last = None
    while time.monotonic() < deadline:
        last = test()
        if last:
            return last
        time.sleep(0.5)
    pytest.fail(f"{what} within {timeout:.0f} s (last: {last}; screenshots in {SHOTS})")


@pytest.fixture
def page(tmp_path_factory, serve_world):
    from playwright.sync_api import sync_playwright

    global SHOTS
    root = SHOTS = tmp_path_factory.mktemp("browser")
    with serve_world(root, WORLD):
        spawned = twin("spawn", str(HUMANOID), "--name", "h", "-z", str(SPAWN_Z))
        assert spawned.returncode == 0, spawned.stderr
        url = twin("view").stdout.strip()
        assert url.startswith("http://localhost:"), url
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            tab = browser.new_page(viewport=VIEWPORT)
            tab.set_default_timeout(SCREENSHOT_TIMEOUT_MS)
            tab.goto(url)
            tab.evaluate("window.twinLoaded = 'same page'")
            yield tab, root
            browser.close()


def _the_page_shows_the_humanoid(page):
    tab, out = page
    wait_for(
        "the humanoid's trousers appear on the page",
        lambda: int(cloth_blue(shot(tab, "humanoid", out)).sum()) > MIN_PIXELS,
    )


def _a_spawned_red_box_appears_without_a_page_reload(page):
    tab, out = page
    # The humanoid's shirt (0.8 0.2 0.2) renders as red as the box: count the red it adds.
    before = int(pure_red(shot(tab, "before_box", out)).sum())
    urdf = out / "box.urdf"
    urdf.write_text(red_box(0.4))
    spawned = twin("spawn", str(urdf), "--name", "box", "-x", "0.6", "-z", str(SPAWN_Z))
    assert spawned.returncode == 0, spawned.stderr
    wait_for(
        "the red box appears on the page",
        lambda: int(pure_red(shot(tab, "box", out)).sum()) - before > BOX_PIXELS,
    )
    assert tab.evaluate("window.twinLoaded") == "same page", "the page was reloaded"


def _pause_in_the_page_pauses_the_world(page):
    tab, _ = page
    assert "Paused[F]" in twin("stats", "-d", "0").stdout
    tab.mouse.click(*PAUSE_BUTTON)
    wait_for(
        "`twin stats` prints Paused[T]", lambda: "Paused[T]" in twin("stats", "-d", "0").stdout
    )


def _reset_in_the_page_puts_entities_back_at_their_spawn_pose(page):
    tab, _ = page
    fallen = json.loads(twin("pose", "box", "--json").stdout)
    assert fallen["z"] < SPAWN_Z - 0.3, f"the box did not fall first: z {fallen['z']} m"
    tab.mouse.click(*RESET_BUTTON)

    def back() -> bool:
        pose = json.loads(twin("pose", "box", "--json").stdout)
        return abs(pose["z"] - SPAWN_Z) < 1e-9 and abs(pose["x"] - 0.6) < 1e-9

    wait_for("`twin pose box` back at its spawn pose (0.6, 0, 1.0) m", back)
    stats = twin("stats", "-d", "0").stdout
    assert "SimTime[0.00]" in stats and "Paused[T]" in stats, stats


def test_the_viewer_shows_and_drives_the_world(page):
    """One test (one page: pytest-xdist must not split the steps over workers), in order."""
    _the_page_shows_the_humanoid(page)
    _a_spawned_red_box_appears_without_a_page_reload(page)
    _pause_in_the_page_pauses_the_world(page)
    _reset_in_the_page_puts_entities_back_at_their_spawn_pose(page)
