"""Robot descriptions (xacro, URDF with Gazebo tags) → MuJoCo MjSpec with Gazebo's physics."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from converters.errors import ConversionError
from converters.report import Outcome, Report

if TYPE_CHECKING:
    from converters.mjcf.builder import ConvertOptions
    from converters.mjcf.writer import write_model
    from converters.pipeline import Conversion, convert, convert_full

__all__ = [
    "Conversion",
    "ConversionError",
    "ConvertOptions",
    "Outcome",
    "Report",
    "convert",
    "convert_full",
    "write_model",
]

# Heavy modules (numpy, mujoco via build) load on first use, so `import converters` stays cheap.
_LAZY = {
    "ConvertOptions": "converters.mjcf.builder",
    "Conversion": "converters.pipeline",
    "convert": "converters.pipeline",
    "convert_full": "converters.pipeline",
    "write_model": "converters.mjcf.writer",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'converters' has no attribute {name!r}")
