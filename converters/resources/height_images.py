"""Height map images (PNG, 8 or 16 bit, grey or colour) → a grid of brightness in [0, 1]."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def read_height_image(path: Path) -> np.ndarray:
    """The image's first channel as floats in [0, 1] (value / the pixel type's maximum), rows
    top to bottom as stored, as Gazebo reads a heightmap image.

    Raises:
        OSError: the file cannot be read as an image.
        ValueError: the image is not square (Gazebo refuses it too).
    """
    from PIL import Image

    with Image.open(path) as image:
        pixels = np.asarray(image)
    if pixels.ndim == 3:
        pixels = pixels[..., 0]
    if pixels.ndim != 2 or pixels.shape[0] != pixels.shape[1] or pixels.shape[0] < 2:
        raise ValueError(f"is {'×'.join(map(str, pixels.shape))} pixels, not square")
    if np.issubdtype(pixels.dtype, np.integer):
        top = 65535.0 if pixels.dtype.itemsize > 1 else 255.0
        return pixels.astype(float) / top
    return np.clip(pixels.astype(float), 0.0, 1.0)
