"""What the page is sent to draw: the world's own model, or a copy with the fast look.

A browser without a GPU draws WebGL in software (Chromium's SwiftShader, Mesa's llvmpipe). There
MuJoCo's page spends most of a frame on the sun's shadow map (every mesh drawn a second time)
and on multisampling: measured at 640×480 with an arm of 136,000 triangles, a frame took
0.7-1.2 s with both, 0.55-0.75 s without shadows and 0.3-0.5 s without either, and a spawned
arm was drawn 0.8-1.1 s after the spawn's reply instead of 1.6-2.4 s. The fast look turns off
shadows and multisampling in a copy of the model sent to the page; the world's model (its
physics, `twin snapshot`, the exported scene) is never changed.

Qualities (`twin view --quality`): `full` (the world's look), `fast`, and `auto` (the default):
full until a page reports that it renders in software, fast from then on while the viewer runs.
"""

from __future__ import annotations

import copy
import re
import threading
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

    `report` runs in the viewer's server thread, `model_for` in the sync thread (with the
    world's lock held): the fields each writes are single assignments.
    """

    def __init__(self, quality: str = "auto") -> None:
        self.quality = check_quality(quality)
        self.software: str | None = None  # the first software renderer a page reported
        self._source: Any = None  # the world's model the copy was made from
        self._shown: Any = None
        self._lock = threading.Lock()

    @property
    def fast(self) -> bool:
        return self.quality == "fast" or (self.quality == "auto" and self.software is not None)

    def report(self, renderer: str) -> None:
        """A page's WebGL renderer; a software one turns `auto` fast (the viewer's life long)."""
        if is_software(renderer) and self.software is None:
            self.software = renderer[:200]

    def model_for(self, model: Any) -> Any:
        """The model to send for the world's `model`: itself, or its fast copy. The copy is
        made once per world model; the options the world changes in place (gravity, timestep,
        solver) are copied into it on every call, so the page shows them."""
        if not self.fast:
            self._source = self._shown = None
            return model
        with self._lock:
            if model is not self._source or self._shown is None:
                self._shown, self._source = fast_copy(model), model
            if self._shown.opt != model.opt:
                self._shown.opt = model.opt
            return self._shown

    def status(self) -> dict:
        """`{quality, fast, software}` for `twin view --json`."""
        return {"quality": self.quality, "fast": self.fast, "software": self.software}


def check_quality(quality: str) -> str:
    if quality not in QUALITIES:
        raise ValueError(f"quality {quality!r}: give one of {', '.join(QUALITIES)}")
    return quality
