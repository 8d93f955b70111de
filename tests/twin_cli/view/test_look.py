"""The page's look (`twin_cli.view.look`): a software-rendered page is sent a copy of the world's
model without shadows or multisampling, and the world's own model is never changed.

On real models (the bundled humanoid in a World) and on a real server with its viewer; the
browser's side (a page in SwiftShader reports its renderer) is in test_view_pieces_browser.py.
"""

from __future__ import annotations

import json
import subprocess
import urllib.error
import urllib.parse
import urllib.request
from pathlib import Path

import numpy as np
import pytest
from view_helpers import twin_in

from twin_cli.view.look import PageLook, fast_copy, is_software

HUMANOID = Path(__file__).parents[3] / "scenarios" / "robots" / "humanoid.urdf.xacro"
# Renderer names as browsers report them (WEBGL_debug_renderer_info).
SOFTWARE_NAMES = (
    "ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device (Subzero) (0x0000C0DE)), SwiftShader driver)",
    "ANGLE (Mesa/X.org, llvmpipe (LLVM 15.0.6 256 bits), OpenGL ES 3.2)",
    "ANGLE (Microsoft, Microsoft Basic Render Driver Direct3D11 vs_5_0 ps_5_0, D3D11)",
)
GPU_NAMES = (
    "ANGLE (NVIDIA, NVIDIA GeForce RTX 3080 Direct3D11 vs_5_0 ps_5_0, D3D11)",
    "ANGLE (Intel, Mesa Intel(R) UHD Graphics 620 (KBL GT2), OpenGL 4.6)",
    "Apple M1",
)


@pytest.fixture(scope="module")
def world():
    from twin_cli.world import Pose, World, WorldSettings

    world = World(WorldSettings())
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    return world


def test_software_renderers_are_told_from_gpus():
    assert all(is_software(n) for n in SOFTWARE_NAMES)
    assert not any(is_software(n) for n in GPU_NAMES)


def test_the_fast_copy_has_no_shadows_or_multisampling_and_the_world_keeps_both(world):
    model = world.model
    assert model.light_castshadow.any() and model.vis.quality.offsamples > 0
    shown = fast_copy(model)
    assert not shown.light_castshadow.any() and shown.vis.quality.offsamples == 0
    assert model.light_castshadow.any() and model.vis.quality.offsamples > 0, "world changed"
    for name in ("geom_size", "geom_rgba", "mesh_vert", "body_pos", "light_dir"):
        assert np.array_equal(getattr(shown, name), getattr(model, name)), name


def test_auto_sends_the_world_model_until_a_software_page_reports(world):
    look = PageLook("auto")
    for name in GPU_NAMES:
        look.report(name)
    assert look.model_for(world.model) is world.model and not look.fast
    look.report(SOFTWARE_NAMES[0])
    shown = look.model_for(world.model)
    assert shown is not world.model and not shown.light_castshadow.any()
    assert look.model_for(world.model) is shown, "a new copy every sync: the page would reload"
    assert look.status() == {"quality": "auto", "fast": True, "software": SOFTWARE_NAMES[0]}
    look.report(GPU_NAMES[0])  # a GPU page opened later does not bring the shadows back
    assert look.fast
    look.quality = "full"
    assert look.model_for(world.model) is world.model
    assert PageLook("fast").model_for(world.model) is not world.model


def test_options_the_world_changes_in_place_reach_the_copy(world):
    look = PageLook("fast")
    shown = look.model_for(world.model)
    world.set_gravity((0.0, 0.0, -1.62))
    try:
        assert look.model_for(world.model) is shown
        assert list(shown.opt.gravity) == [0.0, 0.0, -1.62]
    finally:
        world.set_gravity((0.0, 0.0, -9.81))
    assert list(look.model_for(world.model).opt.gravity) == [0.0, 0.0, -9.81]


def test_a_unknown_quality_is_refused_and_every_layer_offers_the_same_ones():
    import typing
    import warnings

    from twin_cli.server.models import ViewBody

    with warnings.catch_warnings():  # typer's own import of click's deprecated names
        warnings.simplefilter("ignore", DeprecationWarning)
        from twin_cli.cli.commands.view import QUALITIES as CLI
    from twin_cli.view.look import QUALITIES

    with pytest.raises(ValueError, match="auto, full, fast"):
        PageLook("low")
    body = typing.get_args(ViewBody.model_fields["quality"].annotation)[0]
    assert CLI == QUALITIES == typing.get_args(body)


def twin(*args: str, world: str) -> subprocess.CompletedProcess:
    return twin_in(world, *args)


def viewer_get(url: str, path: str, headers: dict | None = None) -> bytes:
    """GET `path` on the viewer's port, as its own page would (Host: the page's address)."""
    request = urllib.request.Request(urllib.parse.urljoin(url, path), headers=headers or {})
    with urllib.request.urlopen(request, timeout=10) as reply:
        return reply.read()


def refused(url: str, path: str, headers: dict | None = None) -> int:
    """The HTTP status of a GET that the viewer must refuse."""
    try:
        viewer_get(url, path, headers)
    except urllib.error.HTTPError as exc:
        return exc.code
    pytest.fail(f"{path} with {headers} was answered")


def test_a_software_page_gets_the_fast_model_and_the_quality_switches_live(tmp_path, serve_world):
    with serve_world(tmp_path, "look"):
        bad = twin("view", "--quality", "low", world="look")
        assert bad.returncode == 2 and "--quality [low]" in bad.stderr, bad.stderr
        assert "auto, full, fast" in bad.stderr and "Traceback" not in bad.stderr
        started = twin("view", "--json", world="look")
        assert started.returncode == 0, started.stderr
        status = json.loads(started.stdout)
        assert status["look"] == {"quality": "auto", "fast": False, "software": None}
        url = status["url"]
        full_crc = wait_new_model(url, 0)
        name = urllib.parse.quote(SOFTWARE_NAMES[0])
        # Another site's page (an image pointing here: no Origin, but Sec-Fetch-Site) and a
        # name that is not printable text change nothing.
        assert refused(url, f"twin/renderer?name={name}", {"Sec-Fetch-Site": "cross-site"}) == 403
        assert refused(url, "twin/renderer?name=llvmpipe%1b%5b31m") == 400
        status = json.loads(twin("view", "--json", world="look").stdout)
        assert not status["look"]["fast"], status["look"]
        viewer_get(url, f"twin/renderer?name={name}", {"Sec-Fetch-Site": "same-origin"})
        status = json.loads(twin("view", "--json", world="look").stdout)
        assert status["look"]["fast"] and status["look"]["software"] == SOFTWARE_NAMES[0]
        fast_crc = wait_new_model(url, full_crc)
        # `--quality full` on the running viewer: the world's own model again, the page's
        # address unchanged.
        human = twin("view", "--quality", "fast", world="look")
        assert human.stdout.strip() == url and "fast look" in human.stderr, human.stderr
        full = json.loads(twin("view", "--quality", "full", "--json", world="look").stdout)
        assert full["look"]["quality"] == "full" and not full["look"]["fast"]
        assert full["url"] == url
        assert wait_new_model(url, fast_crc) == full_crc, "the full look is the world's model"
        assert twin("stop", world="look").returncode == 0


def wait_new_model(url: str, old: int, timeout: float = 30.0) -> int:
    """The crc32 of the model the viewer serves once it differs from `old`."""
    import time

    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        crc = int(viewer_get(url, "twin/current"))
        if crc not in (old, 0):
            return crc
        time.sleep(0.05)
    pytest.fail(f"the viewer still serves model {old} after {timeout:.0f} s")
