"""A visual's material (colour, named reference, texture) → the rgba to paint its geom with."""

from __future__ import annotations

from dataclasses import dataclass

from converters.description import Material

# Colour of a visual without any material: MuJoCo's default geom grey.
DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)


@dataclass(frozen=True)
class VisualColour:
    """The rgba [0-1] to paint a visual with, the material it came from, and its texture file."""

    rgba: tuple[float, float, float, float]
    material: str | None
    texture: str | None


def visual_colour(material: Material | None) -> VisualColour:
    """The colour of a visual: its material's rgba, else MuJoCo's default grey.

    Args:
        material: the visual's material, already resolved against named materials by the reader.
    """
    if material is None:
        return VisualColour(DEFAULT_RGBA, None, None)
    rgba = material.rgba if material.rgba is not None else DEFAULT_RGBA
    return VisualColour(rgba, material.name, material.texture)
