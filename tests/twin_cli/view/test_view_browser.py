"""The web viewer in a real browser (Debian's headless chromium) on a real world server.

One page (its first load takes ~12 s with WebGL in SwiftShader), checked in sequence by one
test: the humanoid shows, a spawned box appears without a page reload, the page still follows
the world's state after that model change (a box the world moves moves on the page), the page's
Pause pauses the world, the page's Reset puts entities back at their spawn poses. A second page,
whose requests for model pieces fail after the box appears, must still show the world's earlier
model again once the box is deleted.
"""

from __future__ import annotations

import contextlib
import io
import json
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from view_helpers import CHROMIUM, CHROMIUM_FLAGS, chromium_missing, red_box, twin_in

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
# The box is magenta, a colour nothing else on the page has, so its pixels are its own whatever
# the humanoid does meanwhile. The page's camera looks down at the humanoid (screen right is +x,
# up is +y, ~220 px/m): at (0.25, 0.6) the box is in view and clear of the fallen humanoid.
BOX_SIZE = 0.3  # [m]
BOX_PIXELS = 2000  # magenta pixels that count as the box shown (~6,000 when all of it shows)
SPAWN_X, SPAWN_Y, SPAWN_Z = 0.25, 0.6, 1.0  # [m]
MOVED_X = -0.25  # [m] where `twin pose --set` puts the box: ~110 px left of where it landed
MIN_SHIFT_PX = 50
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


def magenta(pixels: np.ndarray) -> np.ndarray:
    """Pixels lit from a (1, 0, 1) surface: red and blue alike, green under 15 % of them."""
    rgb = pixels[..., :3].astype(float)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return (r > 40) & (b > 0.7 * r) & (r > 0.7 * b) & (g < 0.15 * np.minimum(r, b))


def box_column(tab, name: str, out: Path) -> float | None:
    """Mean screen column [px] of the box's pixels, or None while fewer than BOX_PIXELS show."""
    rows_cols = np.nonzero(magenta(shot(tab, name, out)))
    return float(rows_cols[1].mean()) if len(rows_cols[1]) > BOX_PIXELS else None


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


@contextlib.contextmanager
def _served_page(tmp_path_factory, serve_world, pieces: dict[str, bool]):
    """A world with the humanoid and its page; the page's requests for model pieces fail
    while `pieces["fail"]` is true (its worker then reports an error)."""
    from playwright.sync_api import sync_playwright

    global SHOTS
    root = SHOTS = tmp_path_factory.mktemp("browser")
    with serve_world(root, WORLD):
        spawned = twin("spawn", str(HUMANOID), "--name", "h", "-z", "1.0")
        assert spawned.returncode == 0, spawned.stderr
        url = twin("view").stdout.strip()
        assert url.startswith("http://localhost:"), url
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            context = browser.new_context(viewport=VIEWPORT)
            context.route(
                lambda url: "/twin/pieces?" in url,
                lambda route: route.abort() if pieces["fail"] else route.continue_(),
            )
            tab = context.new_page()
            tab.set_default_timeout(SCREENSHOT_TIMEOUT_MS)
            tab.goto(url)
            tab.evaluate("window.twinLoaded = 'same page'")
            yield tab, root
            browser.close()


@pytest.fixture
def page(tmp_path_factory, serve_world):
    with _served_page(tmp_path_factory, serve_world, {"fail": False}) as served:
        yield served


def _the_page_shows_the_humanoid(page):
    tab, out = page
    wait_for(
        "the humanoid's trousers appear on the page",
        lambda: int(cloth_blue(shot(tab, "humanoid", out)).sum()) > MIN_PIXELS,
    )


def _a_spawned_box_appears_without_a_page_reload(page) -> float:
    tab, out = page
    assert box_column(tab, "before_box", out) is None, "magenta on the page before the spawn"
    urdf = out / "box.urdf"
    urdf.write_text(red_box(BOX_SIZE).replace('rgba="1 0 0 1"', 'rgba="1 0 1 1"'))
    at = ("-x", str(SPAWN_X), "-y", str(SPAWN_Y), "-z", str(SPAWN_Z))
    spawned = twin("spawn", str(urdf), "--name", "box", *at)
    assert spawned.returncode == 0, spawned.stderr
    column = wait_for("the box appears on the page", lambda: box_column(tab, "box", out))
    assert tab.evaluate("window.twinLoaded") == "same page", "the page was reloaded"
    return column


def _the_page_follows_the_world_after_the_spawn(page, landed_column: float):
    """A page that took the new model but stopped applying the world's state would keep
    drawing the box where it first showed it."""
    tab, out = page
    resting_z = str(BOX_SIZE / 2 + 1e-3)
    moved = twin("pose", "box", "--set", str(MOVED_X), str(SPAWN_Y), resting_z, "0", "0", "0")
    assert moved.returncode == 0, moved.stderr

    def shifted_left() -> bool:
        column = box_column(tab, "moved", out)
        return column is not None and landed_column - column > MIN_SHIFT_PX

    wait_for(f"the box drawn {MIN_SHIFT_PX}+ px left of {landed_column:.0f} px", shifted_left)


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
        spawn = (SPAWN_X, SPAWN_Y, SPAWN_Z)
        return all(abs(pose[k] - v) < 1e-9 for k, v in zip("xyz", spawn, strict=True))

    wait_for(f"`twin pose box` back at its spawn pose {(SPAWN_X, SPAWN_Y, SPAWN_Z)} m", back)
    stats = twin("stats", "-d", "0").stdout
    assert "SimTime[0.00]" in stats and "Paused[T]" in stats, stats


def test_the_viewer_shows_and_drives_the_world(page):
    """One test (one page: pytest-xdist must not split the steps over workers), in order."""
    _the_page_shows_the_humanoid(page)
    column = _a_spawned_box_appears_without_a_page_reload(page)
    _the_page_follows_the_world_after_the_spawn(page, column)
    _pause_in_the_page_pauses_the_world(page)
    _reset_in_the_page_puts_entities_back_at_their_spawn_pose(page)


def test_a_model_the_world_goes_back_to_shows_when_its_pieces_fail(tmp_path_factory, serve_world):
    """A spawn then a delete takes the world back to the model it had (same bytes, same crc32),
    which the page had set aside as superseded. When its worker cannot fetch that model's
    pieces, MuJoCo's own reload must still run: skipped, the page would keep drawing the box."""
    pieces = {"fail": False}
    with _served_page(tmp_path_factory, serve_world, pieces) as page:
        _the_page_shows_the_humanoid(page)
        _a_spawned_box_appears_without_a_page_reload(page)
        pieces["fail"] = True
        deleted = twin("delete", "box")
        assert deleted.returncode == 0, deleted.stderr
        tab, out = page
        wait_for("the box gone from the page", lambda: box_column(tab, "deleted", out) is None)
        assert tab.evaluate("window.twinLoaded") == "same page", "the page was reloaded"
