"""Gazebo's named OGRE materials (`Gazebo/<Name>`) as MuJoCo rgba colours."""

from __future__ import annotations

# Diffuse colours of Gazebo Classic's `media/materials/scripts/gazebo.material` (the same file
# gz-sim copies in `src/rendering/MaterialParser/gazebo.material`). Textured materials (Wood,
# checkerboards, ...) get a representative flat colour.
GAZEBO_MATERIALS: dict[str, tuple[float, float, float, float]] = {
    "Gazebo/Black": (0.0, 0.0, 0.0, 1.0),
    "Gazebo/FlatBlack": (0.1, 0.1, 0.1, 1.0),
    "Gazebo/DarkGrey": (0.175, 0.175, 0.175, 1.0),
    "Gazebo/Grey": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/Gray": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/LightGrey": (0.9, 0.9, 0.9, 1.0),
    "Gazebo/White": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/WhiteGlow": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/Red": (1.0, 0.0, 0.0, 1.0),
    "Gazebo/RedBright": (0.87, 0.26, 0.07, 1.0),
    "Gazebo/RedGlow": (1.0, 0.0, 0.0, 1.0),
    "Gazebo/Green": (0.0, 1.0, 0.0, 1.0),
    "Gazebo/GreenGlow": (0.0, 1.0, 0.0, 1.0),
    "Gazebo/Blue": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/BlueGlow": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/SkyBlue": (0.53, 0.81, 0.92, 1.0),
    "Gazebo/Yellow": (1.0, 1.0, 0.0, 1.0),
    "Gazebo/DarkYellow": (0.7, 0.7, 0.0, 1.0),
    "Gazebo/ZincYellow": (0.9725, 0.9529, 0.2078, 1.0),
    "Gazebo/Gold": (0.8, 0.65, 0.15, 1.0),
    "Gazebo/Orange": (1.0, 0.5088, 0.0468, 1.0),
    "Gazebo/Purple": (1.0, 0.0, 1.0, 1.0),
    "Gazebo/Turquoise": (0.0, 1.0, 1.0, 1.0),
    "Gazebo/Indigo": (0.33, 0.0, 0.5, 1.0),
    "Gazebo/Wood": (0.69, 0.5, 0.3, 1.0),
    "Gazebo/WoodFloor": (0.69, 0.5, 0.3, 1.0),
    "Gazebo/WoodPallet": (0.69, 0.5, 0.3, 1.0),
}


def gazebo_rgba(name: str) -> tuple[float, float, float, float] | None:
    """The rgba of a `Gazebo/<Name>` material, or None when twin does not know the name.

    Args:
        name: the `<material>` text of a `<gazebo reference>` block, e.g. "Gazebo/Grey".

    Returns:
        (r, g, b, a) in [0, 1], or None.
    """
    return GAZEBO_MATERIALS.get(name.strip())
