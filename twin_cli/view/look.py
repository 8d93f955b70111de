"""What the page is sent to draw: the world's own model, or a copy with the fast look.

A browser without a GPU draws WebGL in software (Chromium's SwiftShader, Mesa's llvmpipe). There
MuJoCo's page spends most of a frame on the sun's shadow map (every mesh drawn a second time)
and on multisampling: measured at 640×480 with an arm of 136,000 triangles, a frame took
0.84-1.17 s with both, 0.55-0.85 s without shadows and 0.29-0.52 s without either, and a spawned
arm was drawn 0.80-1.34 s after the spawn's reply instead of 1.61-2.44 s. The fast look turns off
shadows and multisampling in a copy of the model sent to the page; the world's model (its
physics, `twin snapshot`, the exported scene) is never changed.

Qualities (`twin view --quality`): `full` (the world's look), `fast`, and `auto` (the default):
full until a page reports that it renders in software, fast from then on while the viewer runs.
"""

from __future__ import annotations

import copy
import re
from typing import Any

QUALITIES = ("auto", "full", "fast")
# WebGL renderer names (WEBGL_debug_renderer_info) of the software rasterisers browsers fall
# back to without a GPU: Chromium's SwiftShader, Mesa's llvmpipe, softpipe and lavapipe, and
# Windows' Microsoft Basic Render Driver.
SOFTWARE = re.compile(r"swiftshader|llvmpipe|softpipe|lavapipe|software|basic render", re.I)


def is_software(renderer: str) -> bool:
    """Whether a page's WebGL renderer name is a software rasteriser."""
    return bool(SOFTWARE.search(renderer))


def fast_copy(model: Any) -> Any:
    """A copy of `model` whose lights cast no shadows and whose scene is not multisampled."""
    shown = copy.copy(model)
    shown.light_castshadow[:] = 0
    shown.vis.quality.offsamples = 0
    return shown


class PageLook:
    """The quality asked for, the software renderer a page reported, and the model to send.

    `report` runs in the viewer's server thread, `prepare` and `model_for` in the sync thread
    (`model_for` with the world's lock held): each field is written by single assignments.
    """

    def __init__(self, quality: str = "auto") -> None:
        self.quality = check_quality(quality)
        self.software: str | None = None  # the first software renderer a page reported
        self._source: Any = None  # the world's model the copy was made from
        self._shown: Any = None

    @property
    def fast(self) -> bool:
        return self.quality == "fast" or (self.quality == "auto" and self.software is not None)

    def report(self, renderer: str) -> None:
        """A page's WebGL renderer; a software one turns `auto` fast (the viewer's life long)."""
        if is_software(renderer) and self.software is None:
            self.software = renderer[:200]

    def prepare(self, model: Any) -> None:
        """Makes the fast copy of the world's `model` if it will be needed, without the world's
        lock: a copy costs 4-27 ms for 24 MiB of meshes (three franka_panda), and the world
        replaces its model on a change rather than editing it (in place it changes only its
        options, copied by `model_for`, actuator gains and a turning skid steer's wheel contact
        impedance, none of which the page draws)."""
        if self.fast and model is not self._source:
            self._shown, self._source = fast_copy(model), model

    def model_for(self, model: Any) -> Any:
        """The model to send for the world's `model`: itself, or its fast copy (made here if
        `prepare` did not). The options the world changes in place (gravity, timestep, solver)
        are copied into it on every call, so the page shows them."""
        if not self.fast:
            self._source = self._shown = None
            return model
        self.prepare(model)
        self._shown.opt = model.opt  # 0.4 µs; comparing the two first costs ~80 µs
        return self._shown

    def status(self) -> dict:
        """`{quality, fast, software}` for `twin view --json`."""
        return {"quality": self.quality, "fast": self.fast, "software": self.software}


def check_quality(quality: str) -> str:
    if quality not in QUALITIES:
        raise ValueError(f"quality {quality!r}: give one of {', '.join(QUALITIES)}")
    return quality
