"""Makes `docs/viewer.png`, the README's picture of MuJoCo's web viewer on a twin world.

    .venv/bin/python docs/viewer_picture.py      # needs Debian's chromium (as the browser tests)

A world of its own ("docs-picture"): the bundled humanoid standing at spawn height and a red box,
paused with `twin pause` so the robot stays upright; the page opens at 1280×800, where MuJoCo
Studio shows its Options and Inspector panels (the page's Pause lights up: it follows the world).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
WORLD = "docs-picture"
BOX = """<robot name="box"><link name="box">
  <inertial><mass value="1"/><inertia ixx="0.03" iyy="0.03" izz="0.03" ixy="0" ixz="0" iyz="0"/>
  </inertial><collision><geometry><box size="0.4 0.4 0.4"/></geometry></collision>
  <visual><geometry><box size="0.4 0.4 0.4"/></geometry>
  <material name="red"><color rgba="1 0 0 1"/></material></visual></link></robot>"""
RENDER_S = 20.0  # [s] for SwiftShader's first frames
ZOOM = 300  # mouse-wheel units toward the robot


def twin(*args: str) -> str:
    done = subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", WORLD],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    return done.stdout.strip()


def main() -> None:
    from PIL import Image
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as tmp:
        box = Path(tmp) / "box.urdf"
        box.write_text(BOX)
        twin("spawn", "scenarios/robots/humanoid.urdf.xacro", "--name", "h", "-z", "1.05")
        twin("pause")
        twin("spawn", str(box), "--name", "box", "-x", "0.8", "-y", "0.5", "-z", "0.2")
        url = twin("view")
        try:
            with sync_playwright() as p:
                browser = p.chromium.launch(
                    executable_path="/usr/bin/chromium",
                    args=["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run"],
                )
                page = browser.new_page(viewport={"width": 1280, "height": 800})
                page.goto(url)
                time.sleep(RENDER_S)
                page.mouse.move(610, 380)
                page.mouse.wheel(0, ZOOM)
                time.sleep(RENDER_S / 2)
                shot = Path(tmp) / "shot.png"
                page.screenshot(path=shot)
                browser.close()
        finally:
            twin("stop")
        picture = Image.open(shot).convert("RGB").quantize(256, dither=Image.Dither.FLOYDSTEINBERG)
        picture.save(ROOT / "docs" / "viewer.png", optimize=True)


if __name__ == "__main__":
    main()
