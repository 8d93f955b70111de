"""URDF `<material>` (inline colour, named reference, texture) → an rgba for a visual geom."""

from __future__ import annotations

from dataclasses import dataclass

# Colour of a visual without any material: MuJoCo's default geom grey.
DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)


@dataclass(frozen=True)
class VisualColour:
    """The rgba [0-1] to paint a visual with, the material it came from, and its texture file."""

    rgba: tuple[float, float, float, float]
    material: str | None
    texture: str | None


def visual_colour(material: object | None, named: dict[str, object]) -> VisualColour:
    """Resolve a visual's material: its inline `<color>`, else the robot-level material it names.

    Args:
        material: yourdfpy `Material` of the `<visual>` (may carry only a name).
        named: robot-level materials by name.
    """
    if material is None:
        return VisualColour(DEFAULT_RGBA, None, None)
    name = getattr(material, "name", None)
    colour = getattr(material, "color", None)
    texture = getattr(material, "texture", None)
    if (colour is None or texture is None) and name in named:
        shared = named[name]
        colour = colour if colour is not None else getattr(shared, "color", None)
        texture = texture if texture is not None else getattr(shared, "texture", None)
    rgba = tuple(float(c) for c in colour.rgba) if colour is not None else DEFAULT_RGBA
    filename = getattr(texture, "filename", None) if texture is not None else None
    return VisualColour(rgba, name, filename)  # type: ignore[arg-type]


def robot_materials(model: object) -> dict[str, object]:
    """Robot-level `<material>` definitions by name (later definitions win, as in URDF parsers)."""
    return {m.name: m for m in getattr(model, "materials", []) if getattr(m, "name", None)}
