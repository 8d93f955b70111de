"""The MuJoCo side: a robot description → MjSpec (bodies, joints, geoms, actuators), and writing
it as an MJCF directory. Lumping, inertia and geometry planning are steps of the builder."""

from __future__ import annotations

from converters.mjcf.builder import ConvertOptions, build_spec
from converters.mjcf.writer import write_model

__all__ = ["ConvertOptions", "build_spec", "write_model"]
